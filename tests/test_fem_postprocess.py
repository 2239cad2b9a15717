"""Post-processing (fem.postprocess) against closed forms: eq. (4), contact edges, strip widths."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from fem.geometry import cup_geometry
from fem.mesh import boundary_path, cup_mesh
from fem.postprocess import (contact_force, contact_zones, enclosed_volume, half_maximum_width,
                             median_force_width, quartile_width,
                             inner_contact_radius, pressure_weighted_width)

MM = 1e-3


# ------------------------------------------------------------------ volume
@pytest.mark.parametrize("cup", ["A", "B"])
def test_undeformed_cup_encloses_the_frustum(cup):
    g = cup_geometry(cup)
    mesh = cup_mesh(g, "coarse")
    r, z = mesh.doflocs[:, boundary_path(mesh, "cavity")]
    assert enclosed_volume(r, z) == pytest.approx(g.cavity_volume_m3(), rel=1e-13)


@pytest.mark.parametrize("h_over_h1", [1.0, 0.7, 0.3, 0.05])
def test_rigid_cone_pressed_flat_gives_eq_4(h_over_h1):
    # the paper's rigid-cone kinematics, eq. (3): the cone keeps its angle, the plate sits at h,
    # the surface meets z = 0 at r = r0 (1 + h/h0); the part beyond lies flat on the plane
    g = cup_geometry("A")
    h0 = g.r0_m * math.tan(g.alpha_rad)
    h = h_over_h1 * g.h1_m
    r_contact = g.r0_m * (1 + h / h0)
    cone_r = np.linspace(g.r0_m, r_contact, 7)
    flat_r = np.linspace(r_contact, g.r1_m, 5)[1:]
    r = np.concatenate([cone_r, flat_r])
    z = np.concatenate([h * (r_contact - cone_r) / (r_contact - g.r0_m), 0 * flat_r])
    v0 = math.pi * g.r0_m ** 2 * h0 / 3
    assert enclosed_volume(r, z) == pytest.approx(v0 * ((r_contact / g.r0_m) ** 3 - 1), rel=1e-13)


def test_curved_surface_volume_converges_at_second_order():
    # cavity under the paraboloid z = H (1 - r^2/R^2) for r0 < r < R, with a flat roof inside r0:
    # V = pi r0^2 z(r0) + 2 pi H [r^2/2 - r^4/(4 R^2)] from r0 to R; the polyline error is O(h^2)
    r0, R, H = 5 * MM, 19 * MM, 8 * MM
    exact = math.pi * r0 ** 2 * H * (1 - r0 ** 2 / R ** 2) \
        + 2 * math.pi * H * ((R ** 2 - r0 ** 2) / 2 - (R ** 4 - r0 ** 4) / (4 * R ** 2))
    errors = []
    for n in (8, 16, 32):
        r = np.linspace(r0, R, n + 1)
        errors.append(abs(enclosed_volume(r, H * (1 - r ** 2 / R ** 2)) - exact) / exact)
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert orders == pytest.approx([2.0, 2.0], abs=0.05)


def test_volume_stops_at_the_first_contact_and_closes_penetration():
    r = np.array([5.0, 10.0, 15.0, 19.0]) * MM
    z = np.array([4.0, 0.0, 1.0, 0.0]) * MM          # touches down at r = 10 mm, lifts, rim down
    inner = math.pi / 3 * 4 * MM * (25 + 50 + 100) * MM ** 2
    assert enclosed_volume(r, z) == pytest.approx(inner, rel=1e-14)
    z_pen = z.copy()
    z_pen[1] = -0.01 * MM                             # penetrating node: the drop back to z = 0
    mask = np.array([False, True, False, True])
    expected = math.pi / 3 * (4.01 * MM) * (25 + 50 + 100) * MM ** 2 - math.pi * (10 * MM) ** 2 * 0.01 * MM
    assert enclosed_volume(r, z_pen, in_contact=mask) == pytest.approx(expected, rel=1e-13)
    with pytest.raises(ValueError, match="not closed"):
        enclosed_volume(r, z + 1 * MM)


# ---------------------------------------------------------- contact edge
def test_square_root_edge_is_recovered_exactly():
    r = np.linspace(10, 12, 21) * MM
    r_c = 10.537 * MM
    p = 1e5 * np.sqrt(np.clip(r - r_c, 0, None) / MM)
    assert inner_contact_radius(r, p) == pytest.approx(r_c, rel=1e-13)


def test_hertz_edge_converges_at_second_order():
    # p = p0 sqrt(1 - x^2/a^2): p^2 is linear at the edge up to O(x^2), so the error is O(h^2)
    a, rm = 0.8 * MM, 12 * MM
    errors = []
    for n in (40, 80, 160):
        r = np.linspace(10, 14, n + 1) * MM + 0.3 * 4 * MM / n      # edge off the grid
        p = 2e5 * np.sqrt(np.clip(1 - ((r - rm) / a) ** 2, 0, None))
        errors.append(abs(inner_contact_radius(r, p) - (rm - a)))
    assert errors[-1] < 1e-3 * a
    assert np.all(np.log2(np.array(errors[:-1]) / np.array(errors[1:])) > 1.7)


def test_edge_of_a_uniform_or_decreasing_pressure_is_the_first_loaded_sample():
    r = np.linspace(5, 9, 9) * MM
    p = np.where(r > 6.2 * MM, 1e5, 0.0)
    assert inner_contact_radius(r, p) == r[np.argmax(p > 0)]
    assert inner_contact_radius(r, np.linspace(2, 1, 9)) == r[0]
    assert inner_contact_radius(r, np.where(r > 6.2 * MM, 1e5, 10.0), threshold_Pa=100) == r[3]
    with pytest.raises(ValueError, match="threshold"):
        inner_contact_radius(r, 0 * r)


# ------------------------------------------------------------ strip width
def _uniform(r_c, l, n=11):
    r = np.linspace(r_c, r_c + l, n)
    return r, np.full(n, 3e5)


def _triangle(r_c, l, n=11):
    r = np.linspace(r_c, r_c + l, n)
    return r, 3e5 * (1 - (r - r_c) / l)


@pytest.mark.parametrize("r_c,l", [(5 * MM, 4 * MM), (19 * MM, 0.8 * MM)])
def test_weighted_width_of_uniform_and_triangular_strips(r_c, l):
    # closed forms with dA = 2 pi r dr:
    #   uniform:  l (1 + l / (2 r_c));
    #   triangle: (r_c l/2 + l^2/6)^2 / (r_c (r_c l/3 + l^2/12)) -> 3 l / 4 for l << r_c
    assert pressure_weighted_width(*_uniform(r_c, l)) == pytest.approx(l * (1 + l / (2 * r_c)), rel=1e-13)
    tri = (r_c * l / 2 + l * l / 6) ** 2 / (r_c * (r_c * l / 3 + l * l / 12))
    assert pressure_weighted_width(*_triangle(r_c, l)) == pytest.approx(tri, rel=1e-13)
    assert pressure_weighted_width(*_triangle(100.0, l)) == pytest.approx(0.75 * l, rel=1e-4)


def test_weighted_width_of_a_hertz_strip_matches_quadrature():
    # elliptical pressure on [rm - a, rm + a]; reference by adaptive quadrature of the closed form
    a, rm = 1.0 * MM, 12 * MM
    ell = lambda x: math.sqrt(max(1 - ((x - rm) / a) ** 2, 0.0))
    first = quad(lambda x: ell(x) * x, rm - a, rm + a, epsabs=0, epsrel=1e-12)[0]
    second = quad(lambda x: ell(x) ** 2 * x, rm - a, rm + a, epsabs=0, epsrel=1e-12)[0]
    exact = first ** 2 / ((rm - a) * second)
    # thin-strip limit 3 pi^2/16 a (1D closed form), times rm/(rm - a) for dividing by r_c = rm - a
    assert exact == pytest.approx(3 * math.pi ** 2 / 16 * a * rm / (rm - a), rel=(a / rm) ** 2)
    r = np.linspace(rm - a, rm + a, 401)
    p = np.sqrt(np.clip(1 - ((r - rm) / a) ** 2, 0, None))
    # the sqrt edges limit the piecewise-linear integrals to O(h^1.5): 1e-3 at h = a/200
    assert pressure_weighted_width(r, p, r_c_m=rm - a) == pytest.approx(exact, rel=1e-3)


def test_half_maximum_widths():
    r_c, l = 10 * MM, 2 * MM
    assert half_maximum_width(*_uniform(r_c, l)) == pytest.approx(l, rel=1e-13)
    assert half_maximum_width(*_triangle(r_c, l)) == pytest.approx(l / 2, rel=1e-13)
    # the triangle with unloaded samples inside it: the zero sample does not widen the strip
    r, p = _triangle(r_c, l)
    r = np.concatenate([[r_c - 0.5 * MM], r])
    p = np.concatenate([[0.0], p])
    assert half_maximum_width(r, p) == pytest.approx(l / 2, rel=1e-13)
    a, rm = 1.0 * MM, 12 * MM
    errors = []
    for n in (100, 200, 400):
        r = np.linspace(10, 14, n + 1) * MM
        p = np.sqrt(np.clip(1 - ((r - rm) / a) ** 2, 0, None))
        errors.append(abs(half_maximum_width(r, p) / (math.sqrt(3) * a) - 1))
    # linear interpolation at p = 1/2 of a smooth profile (the sampled maximum is exact here)
    assert errors[-1] < 1e-4
    assert np.all(np.log2(np.array(errors[:-1]) / np.array(errors[1:])) > 1.8)


def test_contact_force_of_a_uniform_annulus():
    r, p = _uniform(10 * MM, 2 * MM)
    assert contact_force(r, p) == pytest.approx(3e5 * math.pi * ((12 * MM) ** 2 - (10 * MM) ** 2), rel=1e-13)


def test_bad_profiles():
    with pytest.raises(ValueError, match="increasing"):
        pressure_weighted_width(np.array([2.0, 1.0]), np.array([1.0, 1.0]))
    with pytest.raises(ValueError, match="no positive"):
        half_maximum_width(np.array([1.0, 2.0]), np.array([0.0, 0.0]))
    with pytest.raises(ValueError, match="NaN"):
        enclosed_volume(np.array([1.0, np.nan]), np.array([1.0, 0.0]))


# ------------------------------------------------------------ Richardson
def test_richardson_recovers_order_and_limit_of_a_power_law():
    from fem.postprocess import richardson
    h = np.array([0.4, 0.2, 0.1])
    for p, f_star, c in [(2.0, 3.0, 5.0), (3.0, -1.0, -2.0), (1.3, 10.0, 0.7)]:
        f = f_star + c * h ** p
        rich = richardson(*f)
        assert rich.order == pytest.approx(p, rel=1e-10)
        assert rich.extrapolated == pytest.approx(f_star, rel=1e-10)
        assert rich.fine_error == pytest.approx(abs(c) * 0.1 ** p, rel=1e-8)
    # oscillating (non-monotone) values, or an order so small that the extrapolation would
    # leave the data far behind: no order, the finest value, its last change as the error
    for f in ([1.0, 1.2, 1.1], [3.0 + 0.1 ** 0.2, 3.0 + 0.05 ** 0.2, 3.0 + 0.025 ** 0.2]):
        rich = richardson(*np.array(f)[:, None])
        assert np.isnan(rich.order[0]) and rich.extrapolated[0] == f[2]
        assert rich.fine_error[0] == pytest.approx(abs(f[2] - f[1]))


def test_median_force_width_uniform_strip_is_exact():
    # samples on the strip's edges: the trapezoid rule is exact
    r = np.array([10e-3, 10.5e-3, 10.5e-3 + 1e-12, 11.7e-3 - 1e-12, 11.7e-3, 12e-3])
    p = np.array([0.0, 0.0, 3e4, 3e4, 0.0, 0.0])
    assert median_force_width(r, p, r_c_m=10.5e-3) == pytest.approx(1.2e-3, rel=1e-6)


def test_median_force_width_triangle_closed_form():
    # p falls linearly from p0 at r_c to 0 at r_c + w: half the area within w (1 - 1/sqrt 2)
    r_c, w = 8e-3, 2e-3
    r = np.linspace(r_c, r_c + w, 9)          # trapezoid rule is exact for the linear profile
    p = 5e4 * (1 - (r - r_c) / w)
    assert median_force_width(r, p, r_c) == pytest.approx((2 - np.sqrt(2)) * w, rel=1e-12)


def test_median_force_width_is_bounded_by_a_concentrated_rim_force():
    # a uniform strip plus a spike at the far end that carries 10 % of the load: the median
    # moves by what the spike carries (a finite shift), it does not blow up as the spike narrows
    r_c, l = 10e-3, 1e-3
    for spike in (1e-4, 1e-5, 1e-6):
        r = np.concatenate([np.linspace(r_c, r_c + l, 201), [r_c + l + spike / 2, r_c + l + spike]])
        p = np.concatenate([np.full(201, 1.0), [0.1 * l / (spike / 2), 0.0]])
        # half of 1.1 l of load lies at 0.55 l from the edge: l_m -> 1.1 l as the spike narrows,
        # off by no more than the spike's own width (where its load sits), however high it is
        assert abs(median_force_width(r, p, r_c) - 1.1 * l) <= 1.5 * spike


def _two_strips(r_c, l, gap, l_out, p_in=3e4, p_out=5e4, eps=1e-12):
    """A uniform inner strip [r_c, r_c + l] and a uniform outer one beyond a gap, sampled on
    their edges (plus a zero just inside and one just outside each), so the trapezoid rule is exact."""
    r_out = r_c + l + gap
    r = np.array([r_c - 1e-4, r_c, r_c + eps, r_c + l - eps, r_c + l, r_c + l + gap / 2,
                  r_out, r_out + eps, r_out + l_out - eps, r_out + l_out, r_out + l_out + 1e-4])
    p = np.array([0, 0, p_in, p_in, 0, 0, 0, p_out, p_out, 0, 0], dtype=float)
    return r, p


def test_contact_zones_of_two_strips():
    r, p = _two_strips(r_c=10e-3, l=1e-3, gap=0.5e-3, l_out=0.2e-3)
    zones = contact_zones(r, p)
    assert len(zones) == 2
    assert zones[0] == pytest.approx((10e-3, 11e-3), abs=1e-11)
    assert zones[1] == pytest.approx((11.5e-3, 11.7e-3), abs=1e-11)
    assert contact_zones(r, np.where(r < 11.2e-3, p, 0.0)) == [zones[0]]


def test_median_and_quartile_widths_take_the_innermost_zone():
    # the paper's l is the sealing strip next to r_c: an outer (rim-corner) zone, however
    # loaded, does not change it; with innermost=False the closed form of both strips holds
    r_c, l, gap, l_out = 10e-3, 1e-3, 0.5e-3, 0.2e-3
    for p_out in (5e4, 5e5):
        r, p = _two_strips(r_c, l, gap, l_out, p_out=p_out)
        assert median_force_width(r, p, r_c) == pytest.approx(l, rel=1e-6)
        assert quartile_width(r, p) == pytest.approx(l, rel=1e-6)
    # all zones (p_out = 5e5 Pa): line forces 30 N/m inside and 100 N/m outside, so half of the
    # total lies (65 - 30) N/m / 5e5 Pa into the outer strip
    f_in, f_out = 3e4 * l, 5e5 * l_out
    r_half = r_c + l + gap + (0.5 * (f_in + f_out) - f_in) / 5e5
    assert median_force_width(r, p, r_c, innermost=False) == pytest.approx(2 * (r_half - r_c), rel=1e-6)


def test_quartile_width_closed_forms():
    # uniform strip: exactly l; triangle falling from p0 at the edge to 0 over w: the load
    # fraction within x is 1 - (1 - x/w)^2, quartiles at w (1 - sqrt(3)/2) and w / 2
    r = np.array([10e-3, 10.5e-3, 10.5e-3 + 1e-12, 11.7e-3 - 1e-12, 11.7e-3, 12e-3])
    p = np.array([0.0, 0.0, 3e4, 3e4, 0.0, 0.0])
    assert quartile_width(r, p) == pytest.approx(1.2e-3, rel=1e-6)
    r_c, w = 8e-3, 2e-3
    r = np.linspace(r_c, r_c + w, 9)        # the trapezoid rule is exact for the linear profile
    p = 5e4 * (1 - (r - r_c) / w)
    assert quartile_width(r, p) == pytest.approx((np.sqrt(3) - 1) * w, rel=1e-12)
    # it does not use the contact edge: zero samples further inside change nothing
    assert quartile_width(np.concatenate([[7e-3, 7.5e-3, r_c - 1e-12], r]),
                          np.concatenate([[0, 0, 0], p])) == pytest.approx((np.sqrt(3) - 1) * w, rel=1e-9)


def test_quartile_width_converges_for_an_edge_between_samples():
    # a triangle whose edge lies between the samples (the contact front between two nodes): the
    # sampled (piecewise-linear) profile smears the edge over one spacing h, so l_q converges to
    # the closed form at first order or better; the median width measured from the sampled edge
    # r_c = first loaded sample (a pressure falling from the edge) is off by up to 2 h
    r_c, w = 8.03e-3, 2e-3
    exact = (np.sqrt(3) - 1) * w
    errors = []
    for n in (20, 40, 80, 160):
        h = 4e-3 / n
        r = 7e-3 + h * np.arange(n + 1)
        p = np.where((r >= r_c) & (r <= r_c + w), 5e4 * (1 - (r - r_c) / w), 0.0)
        errors.append(abs(quartile_width(r, p) - exact))
        assert errors[-1] <= h
    assert errors[-1] < errors[0] / 4


def test_median_force_width_counts_no_load_inside_the_edge():
    # a uniform strip sampled on a grid whose node r_k is the edge: the piecewise-linear ramp
    # from the free node r_{k-1} to r_k lies inside r_c and must not count (it made l_m < 0 for
    # a contact zone of one loaded node); the width is then exactly l, and never negative
    h, r_c, l = 0.1e-3, 10.0e-3, 1.0e-3
    r = r_c + h * np.arange(-5, 16)
    r = np.sort(np.concatenate([r, [r_c + l + 1e-12]]))           # a sharp fall at r_c + l
    p = np.where((r >= r_c - 1e-15) & (r <= r_c + l + 1e-15), 2e4, 0.0)
    assert median_force_width(r, p, r_c) == pytest.approx(l, rel=1e-9)
    one = np.array([r_c - h, r_c, r_c + 1e-9, r_c + h])             # one loaded node, then free
    assert 0.0 <= median_force_width(one, np.array([0.0, 1e4, 0.0, 0.0]), r_c) < 1e-9


def test_smallest_stretch_of_closed_form_states():
    """Uniaxial compression, simple shear (stretches (sqrt(1 + k^2/4) -+ k/2)) and a hoop
    contraction: the smallest principal stretch in closed form, also for a rotated state."""
    from fem.postprocess import smallest_stretch
    lam, k, c = 0.6, 0.8, 0.3
    uniaxial = np.array([1.0 / np.sqrt(lam), 0.0, 0.0, lam, 1.0 / np.sqrt(lam)])
    shear = np.array([1.0, k, 0.0, 1.0, 1.0])
    hoop = np.array([1.1, 0.0, 0.0, 1.05, 0.7])
    R = np.array([[np.cos(c), -np.sin(c)], [np.sin(c), np.cos(c)]])
    F = R @ np.array([[1.0 / np.sqrt(lam), 0.0], [0.0, lam]])
    rotated = np.array([F[0, 0], F[0, 1], F[1, 0], F[1, 1], 1.0 / np.sqrt(lam)])
    f = np.stack([uniaxial, shear, hoop, rotated], axis=1)
    expected = [lam, np.sqrt(1 + k**2 / 4) - k / 2, 0.7, lam]
    np.testing.assert_allclose(smallest_stretch(f), expected, rtol=1e-14)
    # small strain: no cancellation (1 - 1e-9 resolved)
    assert smallest_stretch(np.array([1.0, 0.0, 0.0, 1.0 - 1e-9, 1.0]))[()] == pytest.approx(1 - 1e-9, rel=1e-15)


# ------------------------------------------------------------ outer contact edge
def test_outer_edge_of_a_hertz_profile_is_exact():
    """Hertz's p^2 = p0^2 (1 - r^2/a^2) is a quadratic in r: the fit recovers a to round-off,
    with the edge between samples and free samples (p = 0) beyond it."""
    from fem.postprocess import outer_contact_radius
    a = 0.1137 * MM
    r = np.linspace(0, 0.2, 41) * MM
    p = 3e7 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None))
    assert outer_contact_radius(r, p, band_m=0.3 * a) == pytest.approx(a, rel=1e-10)


def test_outer_edge_of_a_general_square_root_edge_converges_with_the_band():
    """p^2 = (a - r) exp((a - r) / a): a square-root edge whose p^2 is not a quadratic; the fit's
    model error is the cubic remainder, so the edge error falls like band^3 (densely sampled)."""
    from fem.postprocess import outer_contact_radius
    a = 1.0 * MM
    r = np.linspace(0, 1.5, 3001) * MM
    x = np.clip(a - r, 0, None)
    p = 1e5 * np.sqrt(x * np.exp(x / a))
    errors = [abs(outer_contact_radius(r, p, band_m=w * a) - a) for w in (0.4, 0.2, 0.1)]
    assert errors[0] < 1e-2 * a
    assert np.all(np.log2(np.array(errors[:-1]) / np.array(errors[1:])) > 2.5)


def test_outer_edge_needs_enough_loaded_samples():
    from fem.postprocess import outer_contact_radius
    r = np.linspace(0, 1, 11) * MM
    p = np.where(r < 0.45 * MM, 1e5, 0.0)
    with pytest.raises(ValueError, match="band_m"):
        outer_contact_radius(r, p, band_m=0.15 * MM)
    with pytest.raises(ValueError, match="no positive contact pressure"):
        outer_contact_radius(r, 0 * r, band_m=1 * MM)
