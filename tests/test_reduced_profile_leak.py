"""Leakage through a contact-pressure profile (issue 12, section 1) against the paper's strip
formulas, a series composition solved independently, and a refinement study; the patch-averaged
pressure (exactness, force, refinement, a point load) and the profile seal that uses it."""

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from reduced.critical_gap import UcTable
from reduced.gas import AIR, interpolated_leak_rate, liquid_volume_rate
from reduced.profile_leak import (ContactProfile, contact_segments, patch_average, patch_contact,
                                  profile_leak_rate, profile_liquid_rate, ring_gaps)
from reduced.seal import ProfileSeal
from reduced.stiffness_curve import StiffnessCurve

P_A, P_B = 1e5, 3e4
R0, L = 12e-3, 2e-3


@pytest.mark.parametrize("u_c", [5e-9, 0.2e-6, 20e-6])          # ballistic, mixed, diffusive
def test_a_uniform_strip_is_eq_19_with_the_papers_aspect_ratio(u_c):
    r = np.linspace(R0, R0 + L, 41)                               # 40 rings of the same gap
    strip = profile_leak_rate(AIR, P_A, P_B, r, np.full(40, u_c), radial="strip")
    assert strip == pytest.approx(interpolated_leak_rate(AIR, P_A, P_B, u_c, 2 * math.pi * R0 / L), rel=1e-12)
    annulus = profile_leak_rate(AIR, P_A, P_B, r, np.full(40, u_c))
    assert annulus == pytest.approx(interpolated_leak_rate(AIR, P_A, P_B, u_c, 2 * math.pi / math.log(1 + L / R0)),
                                    rel=1e-12)


def test_annulus_and_strip_differ_by_half_the_width_over_the_radius():
    """2 pi / ln(1 + l/r) = (2 pi r / l)(1 + l / 2r - l^2 / 12 r^2 + ...): the flat strip of eq (9)
    is the annulus to first order in l / r."""
    for x in (0.2, 0.05, 0.01):
        r = np.array([R0, R0 * (1 + x)])
        ratio = profile_leak_rate(AIR, P_A, P_B, r, [1e-7]) / profile_leak_rate(AIR, P_A, P_B, r, [1e-7], "strip")
        assert ratio - 1 == pytest.approx(x / 2 - x * x / 12, abs=x ** 3)


def test_two_steps_are_two_strips_in_series():
    """Inner ring (gap u1) and outer ring (u2): the flow through each, by the closed form eq (19)
    between the intermediate pressure P_m and its ends, is the same; P_m found independently."""
    r = np.array([R0, R0 + 0.7 * L, R0 + L])
    u1, u2 = 0.15e-6, 0.6e-6
    q = profile_leak_rate(AIR, P_A, P_B, r, [u1, u2])
    inner = lambda pm: interpolated_leak_rate(AIR, pm, P_B, u1, 2 * math.pi / math.log(r[1] / r[0]))  # noqa: E731
    outer = lambda pm: interpolated_leak_rate(AIR, P_A, pm, u2, 2 * math.pi / math.log(r[2] / r[1]))  # noqa: E731
    p_m = brentq(lambda pm: inner(pm) - outer(pm), P_B, P_A, xtol=1e-9)
    assert q == pytest.approx(inner(p_m), rel=1e-10)
    # and the narrow ring dominates: less flow than either ring alone would pass
    assert q < min(inner(P_A), outer(P_B))


def test_a_sealed_ring_stops_the_flow_and_an_open_ring_costs_nothing():
    r = np.array([R0, R0 + 1e-3, R0 + 2e-3, R0 + 3e-3])
    assert profile_leak_rate(AIR, P_A, P_B, r, [1e-7, 0.0, 1e-7]) == 0.0
    with_gap = profile_leak_rate(AIR, P_A, P_B, r, [1e-7, math.inf, 1e-7])
    direct = profile_leak_rate(AIR, P_A, P_B, r[[0, 1, 2, 3]], [1e-7, 1e3, 1e-7])   # a wide-open ring
    assert with_gap == pytest.approx(direct, rel=1e-9)
    assert profile_leak_rate(AIR, P_A, P_A, r, [1e-7, 1e-7, 1e-7]) == 0.0


def test_liquid_rings_are_eq_24_in_series():
    r = np.array([R0, R0 + 0.5 * L, R0 + L])
    mu = 1.002e-3
    uniform = profile_liquid_rate(mu, P_A, P_B, r, [0.3e-6, 0.3e-6], radial="strip")
    assert uniform == pytest.approx(liquid_volume_rate(mu, P_A, P_B, 0.3e-6, 2 * math.pi * R0 / L), rel=1e-12)
    q = profile_liquid_rate(mu, P_A, P_B, r, [0.2e-6, 0.5e-6])
    # the same flow through each ring: the pressure drops add up to p_a - p_b
    drops = [q * 12 * mu * math.log(r[i + 1] / r[i]) / (2 * math.pi * u ** 3) for i, u in enumerate((0.2e-6, 0.5e-6))]
    assert sum(drops) == pytest.approx(P_A - P_B, rel=1e-12)


def _hertz_like(n: int) -> ContactProfile:
    """A smooth strip 2 mm wide peaking at 150 kPa, sampled at n + 1 radii."""
    r = np.linspace(R0, R0 + L, n + 1)
    return ContactProfile(r, 150e3 * np.sin(np.pi * (r - R0) / L) ** 0.5 + 1e3)


def test_the_flow_converges_with_the_radial_sampling_at_second_order():
    uc = UcTable(np.geomspace(1e-4, 1.0, 60), 0.68e-6 * (np.geomspace(1e-4, 1.0, 60) / 0.025) ** -0.8)
    q = []
    for n in (20, 40, 80, 160, 320):
        prof = _hertz_like(n)
        q.append(profile_leak_rate(AIR, P_A, P_B, prof.r_m, ring_gaps(prof, uc, 4e6)))
    d = np.abs(np.diff(q))
    orders = np.log2(d[:-1] / d[1:])
    assert np.all(orders > 1.7), orders          # measured 1.86-1.88 (the sqrt edge of the profile)
    assert d[-1] / q[-1] < 1e-3


def test_contact_profile_refuses_bad_input():
    with pytest.raises(ValueError, match="r_m: profile radii must be > 0 and strictly increasing"):
        ContactProfile([2e-3, 1e-3], [1.0, 2.0])
    with pytest.raises(ValueError, match="p_Pa: contact pressure must be >= 0"):
        ContactProfile([1e-3, 2e-3], [1.0, -2.0])
    assert ContactProfile([1.0, 2.0], [3.0, 3.0]).force_N == pytest.approx(math.pi * 3.0 * 3.0)


# ------------------------------------------------------------------ patch-averaged pressure
W = 1e-4                                                          # the patch width L [m]
UC = UcTable(np.geomspace(1e-4, 1.0, 60), 0.68e-6 * (np.geomspace(1e-4, 1.0, 60) / 0.025) ** -0.8)


def _averaged_flow(prof: ContactProfile, extra: float = 0.0, uc=UC) -> float:
    """Flow through the patch average of `prof`, eq (6)'s share `extra` on its nominal contact."""
    avg = patch_average(prof, W)
    share = np.where(patch_contact(prof, W, avg.r_m), extra, 0.0)
    return profile_leak_rate(AIR, P_A, P_B, avg.r_m, ring_gaps(avg, uc, 4e6, extra_Pa=share))


def test_a_uniform_pressure_is_unchanged_where_the_patch_lies_inside_it_and_the_force_is_kept():
    r = np.linspace(R0, R0 + L, 41)
    prof = ContactProfile(r, np.full(41, 50e3))
    avg = patch_average(prof, W)
    inside = (avg.r_m >= R0 + W / 2) & (avg.r_m <= R0 + L - W / 2)
    assert inside.sum() > 40
    np.testing.assert_allclose(avg.p_Pa[inside], 50e3, rtol=1e-12)
    assert avg.force_N == pytest.approx(prof.force_N, rel=1e-12)
    # the edges spread by L/2 each way, linearly in force: half the pressure at the old edge
    assert avg.r_m[0] == pytest.approx(R0 - W / 2, rel=1e-12) and avg.r_m[-1] == pytest.approx(R0 + L + W / 2, rel=1e-12)
    assert avg.p_Pa[np.argmin(np.abs(avg.r_m - R0))] == pytest.approx(25e3, rel=1e-2)
    # and the flow through the strip moves by the edges only, O(L / width)
    direct = profile_leak_rate(AIR, P_A, P_B, r, ring_gaps(prof, UC, 4e6))
    assert abs(_averaged_flow(prof) / direct - 1) < 2 * W / L


def test_the_patch_average_keeps_the_force_of_an_uneven_profile():
    """int pbar r dr = int p r dr holds exactly for the continuous average; sampled at its kinks it
    is exact for evenly spaced inputs (above) and to (h/L)^2 order otherwise."""
    rng = np.random.default_rng(0)
    r = np.sort(R0 + L * rng.random(60))
    p = 1e5 * rng.random(60)
    p[:3] = p[-2:] = 0.0
    prof = ContactProfile(r, p)
    avg = patch_average(prof, W)
    assert avg.force_N == pytest.approx(prof.force_N, rel=2e-3)      # measured 6.6e-4
    assert np.all(avg.p_Pa >= 0) and avg.p_Pa.max() < p.max()
    with pytest.raises(ValueError, match="length_m: the patch length must be finite and > 0"):
        patch_average(prof, 0.0)


def test_the_averaged_flow_does_not_depend_on_the_sampling_of_a_smooth_profile():
    """The same smooth p(r) at 40, 80, 160 and 320 rings: the flows agree to 0.5 % (measured: 0.39,
    0.10, 0.02 % from the 320-ring one), with or without eq (6)'s share."""
    for extra in (0.0, 40e3):
        q = [_averaged_flow(_hertz_like(n), extra) for n in (40, 80, 160, 320)]
        assert np.all(np.abs(np.array(q[:-1]) / q[-1] - 1) < 5e-3), q
        assert abs(q[1] / q[-1] - 1) < abs(q[0] / q[-1] - 1)


@pytest.mark.parametrize("extra", [0.0, 40e3])
def test_a_point_load_converges_to_a_strip_one_patch_wide(extra):
    """One loaded node (force F at radius R, free neighbours h away, lumped pressure F / (2 pi R h)):
    its raw gap closes as h -> 0 (this table seals above p/E = 0.5), while the patch average
    converges, at first order in h / L, to the strip [R - L/2, R + L/2] at F / (2 pi r L)."""
    uc = UcTable(np.array([1e-4, 1e-2, 0.3, 0.5]), np.array([5e-6, 0.7e-6, 0.1e-6, 0.0]))
    F, R = 0.3, 19e-3
    x = np.linspace(R - W / 2, R + W / 2, 2001)
    box = ContactProfile(x, F / (2 * np.pi * x * W))
    limit = profile_leak_rate(AIR, P_A, P_B, x, ring_gaps(box, uc, 4e6, extra_Pa=extra))
    errors, raw = [], []
    for h in (W / 8, W / 32, W / 128, W / 512):
        prof = ContactProfile([R - h, R, R + h], [0.0, F / (2 * np.pi * R * h), 0.0])
        assert prof.force_N == pytest.approx(F, rel=1e-9)
        errors.append(abs(_averaged_flow(prof, extra, uc) / limit - 1))
        raw.append(profile_leak_rate(AIR, P_A, P_B, prof.r_m, ring_gaps(prof, uc, 4e6, extra_Pa=extra)))
    # measured: 3.9, 0.93, 0.23, 0.056 % without the share, 5.4, 1.4, 0.36, 0.091 % with it
    assert np.all(np.diff(errors) < 0) and errors[-1] < 2e-3, errors
    assert errors[0] < 0.08
    assert raw[-1] == 0.0 and raw[0] > 0.0           # unaveraged: the corner seals the cup


def test_the_nominal_contact_is_the_contact_widened_by_half_a_patch():
    r = 1e-3 * np.array([10.0, 10.1, 10.2, 10.3, 10.5, 10.7, 10.8, 11.2, 11.21])
    p = np.array([0.0, 5.0, 6.0, 0.0, 0.0, 3.0, 0.0, 0.0, 2.0])
    a, b = contact_segments(ContactProfile(r, p))
    # edges half-way to the free neighbours; a loaded end sample ends its interval; a lone node
    np.testing.assert_allclose(a, 1e-3 * np.array([10.05, 10.6, 11.205]), rtol=1e-12)
    np.testing.assert_allclose(b, 1e-3 * np.array([10.25, 10.75, 11.21]), rtol=1e-12)
    grid = np.linspace(9.9e-3, 11.3e-3, 1401)
    on = patch_contact(ContactProfile(r, p), W, grid)
    mid = 0.5 * (grid[1:] + grid[:-1])
    expect = np.zeros(mid.size, bool)
    for lo, hi in zip(a, b):
        expect |= (mid >= lo - W / 2) & (mid <= hi + W / 2)
    assert np.array_equal(on, expect)
    assert not patch_contact(ContactProfile(r, 0 * p), W, grid).any()
    # the averaged profile's grid has the nominal contact's ends among its radii
    avg = patch_average(ContactProfile(r, p), W)
    for end in np.concatenate([a - W / 2, b + W / 2]):
        assert np.min(np.abs(avg.r_m - end)) < 1e-15


def _point_load_curve(h: float, force_scale: float = 1.0) -> StiffnessCurve:
    """Three samples of one loaded node at R (neighbours h away) carrying force_scale F0."""
    u = np.array([0.0, 1e-3, 2e-3])
    F0 = np.array([0.0, 0.2, 0.4])
    R = 19e-3
    profiles = [None] + [ContactProfile([R - h, R, R + h], [0.0, force_scale * F / (2 * np.pi * R * h), 0.0])
                         for F in F0[1:]]
    return StiffnessCurve(u_m=u, F0_N=F0, h1_m=6e-3, r_c_m=np.full(3, R), l_m=np.zeros(3),
                          V_m3=np.array([1e-6, 0.9e-6, 0.8e-6]), profiles=profiles)


def test_the_profile_seal_averages_when_the_table_carries_a_patch_length():
    table = dataclasses.replace(UC, patch_length_m=W)
    for h in (W / 4, W / 64):
        plain = ProfileSeal(_point_load_curve(h), UC, AIR, P_A, 0.8, None)
        assert plain.patch_length_m is None
        seal = ProfileSeal(_point_load_curve(h, force_scale=1.25), table, AIR, P_A, 0.8, None)
        avg, contact = seal.averaged(1)
        # the averaged profile carries the curve's F0 (the lumped pressures' 25 % excess is removed)
        assert avg.force_N == pytest.approx(0.2, rel=1e-12)
        q, p, gap, _ = seal.flow(0.0, 19e-3, 0.0, P_B, 1.0, 4e6, 1e-3)
        share = np.where(contact, 0.8 * (P_A - P_B), 0.0)
        assert q == pytest.approx(profile_leak_rate(AIR, P_A, P_B, avg.r_m, ring_gaps(avg, table, 4e6, extra_Pa=share)),
                                  rel=1e-12)
        assert gap > 0 and p == pytest.approx(avg.p_Pa.max() + 0.8 * (P_A - P_B), rel=1e-12)
    # off by an explicit 0, and the flow converges with h only when averaged
    off = ProfileSeal(_point_load_curve(W / 64), table, AIR, P_A, 0.8, None, patch_length_m=0.0)
    assert off.patch_length_m is None
    q = [ProfileSeal(_point_load_curve(h), table, AIR, P_A, 0.8, None).flow(0.0, 19e-3, 0.0, P_B, 1.0, 4e6, 1e-3)[0]
         for h in (W / 16, W / 64, W / 256)]
    assert abs(q[2] / q[1] - 1) < abs(q[1] / q[0] - 1) < 0.03            # measured 0.63 %, 2.5 %
    with pytest.raises(ValueError, match="patch_length_m: must be finite and >= 0"):
        ProfileSeal(_point_load_curve(W), table, AIR, P_A, 0.8, None, patch_length_m=-1.0)


def test_eq10s_strip_under_a_lone_loaded_node_is_one_patch():
    """The contact time of eq (10) needs the width of the strip a point crosses: a lone loaded node
    (the FEM's l = 0) holds one patch of nominal contact, so the averaged seal's width is L there and
    the FEM's strip where that is wider; the raw seal keeps the FEM's 0 (the line where r' phi / l
    is singular)."""
    table = dataclasses.replace(UC, patch_length_m=W)
    seal = ProfileSeal(_point_load_curve(W / 16), table, AIR, P_A, 0.8, None)
    assert seal.width(0.0) == W and seal.width(3 * W) == 3 * W
    assert ProfileSeal(_point_load_curve(W / 16), UC, AIR, P_A, 0.8, None).width(0.0) == 0.0


def test_a_uc_table_carries_its_patch_length_through_a_csv(tmp_path):
    table = dataclasses.replace(UC, patch_length_m=1.2e-4, provenance="a test table\nsecond line")
    back = UcTable.from_csv(table.to_csv(tmp_path / "uc.csv"))
    assert back.patch_length_m == pytest.approx(1.2e-4, rel=1e-9)
    assert back.provenance == "a test table second line"
    assert UcTable.from_csv(UC.to_csv(tmp_path / "plain.csv")).patch_length_m is None
    with pytest.raises(ValueError, match="patch_length_m: must be finite and > 0"):
        dataclasses.replace(UC, patch_length_m=0.0)
    # the vectorised evaluation is the scalar one, sealed rows and extrapolation included
    sealing = UcTable(np.array([1e-4, 1e-2, 0.3, 0.5]), np.array([5e-6, 0.7e-6, 0.1e-6, 0.0]))
    x = np.geomspace(1e-7, 3.0, 500)
    for t in (UC, sealing):
        np.testing.assert_allclose(t.values(x), [t.scalar(v) for v in x], rtol=1e-13)


def test_a_spectrum_table_carries_the_patch_on_which_its_u_c_is_the_whole_spectrums():
    from reduced.roughness import critical_gap_table, preset, uc_table
    from reduced.roughness.persson import patch_length
    from reduced.roughness.spectrum import PowerSpectrum, self_affine

    spec = self_affine(H=0.8, q0_per_m=250.0, q1_per_m=1e7, qr_per_m=5e4, h_rms_m=1e-6)
    assert spec.rolloff_wavelength_m() == pytest.approx(2 * np.pi / 5e4, rel=3e-3)   # the grid's step
    L = patch_length(spec, 0.5)
    q, C = spec.q_per_m, spec.C_m4

    def u_c(q_cut):
        keep = q >= q_cut
        return critical_gap_table(PowerSpectrum(q[keep], C[keep]), 1e6, 0.5, [0.025]).u_c_m[0]

    full = u_c(0.0)
    assert u_c(2 * np.pi / L) / full >= 0.98                 # the patch keeps u_c to 2 %
    assert u_c(1.02 * 2 * np.pi / L) / full < 0.98           # a smaller one does not
    assert 1.0 < L * 5e4 / (2 * np.pi) < 3.0                  # beyond the roll-off, within a few
    params = preset("pmma-1.89").params
    pmma = patch_length(preset("pmma-1.89").spectrum(), 0.5)
    assert pmma == pytest.approx(202e-6, rel=0.02)            # the stored preset (docstrings)
    assert 1.5 < pmma * params["qr_per_m"] / (2 * np.pi) < 2.0
    assert patch_length(preset("pmma-1.89").spectrum(), 0.5, p_over_E=0.01) > pmma      # lower p: longer
    off = uc_table(spec, 0.5, p_over_E=np.geomspace(1e-3, 0.1, 5), with_patch_length=False)
    assert off.patch_length_m is None                                                     # opt-out
    table = uc_table(spec, 0.5, p_over_E=np.geomspace(1e-3, 0.1, 5))                     # the default
    assert table.patch_length_m == L


def test_the_march_stops_where_the_gas_pressure_would_fall_below_zero():
    """P_in(Q) through rings in series must fall monotonically with Q for the root search to find
    the one flow with P_in = p_b. A narrow outer ring (large b = a/u) can leave P below -b of a wide
    inner ring, whose formula then squares P back up: a gas has no negative pressure, so such a Q
    is too large (-inf), and P_in never rises with Q."""
    from reduced.gas import XI
    from reduced.profile_leak import _march

    u = np.array([10e-6, 10e-9])                  # inner ring wide open, outer ring narrow
    c = 12.0 * AIR.viscosity_Pa_s * AIR.kT_J * np.array([0.05, 0.01]) / (2.0 * np.pi)
    b = XI * AIR.n_lambda_per_m2 * AIR.kT_J / 2.0 / u
    u3 = u ** 3
    q_outer = u3[1] * ((P_A + b[1]) ** 2) / (2.0 * c[1])        # the outer ring's largest flow
    q = np.linspace(0.0, 0.999 * q_outer, 400)[1:]
    p_in = np.array([_march(P_A, u3, b, c, x)[0] for x in q])
    assert np.all(np.diff(p_in[np.isfinite(p_in)]) < 0)
    assert not np.isfinite(p_in[-1])              # P would pass below 0 after the narrow ring
    # and the flow at p_b = 0 is the largest with P >= 0 all the way
    Q = profile_leak_rate(AIR, P_A, 0.0, np.array([10e-3, 10.5e-3, 10.6e-3]), u)
    assert _march(P_A, u3, b, c, 1.001 * Q)[0] == -np.inf
