"""The coupled cavity (reduced/coupled.py) against the paper's own route: a suction table built from
eqs (3)-(7) (F1 = dp pi r^2 - F0, V of eq 4, a uniform strip at eq 6's pressure) must give the
lifetimes of the paper's reduced model, to the table's interpolation error, which falls with the
grid, also with viscoelastic relaxation (reduced/coupled_relax.py). And the table's JSON round trip."""

import math
from dataclasses import replace

import numpy as np
import pytest

from reduced.coupled import CoupledCavity
from reduced.coupled_relax import load_strip
from reduced.critical_gap import illustrative_uc_table
from reduced.cup import cup_by_name
from reduced.force_balance import force_balance
from reduced.lifetime import largest_holdable_force, reference_model, solve_lifetime
from reduced.profile_leak import ContactProfile
from reduced.suction_table import SuctionTable
from reduced.viscoelastic import RelaxationModulus, default_relaxation, measurement_contact_time


def paper_table(model, nu: int, ndp: int) -> SuctionTable:
    """The paper's eqs (3)-(7) sampled on a (u, dp) grid (kappa = 1, no relaxation)."""
    cup, curve = model.cup, model.stiffness
    h1 = cup.h1_m
    u = np.linspace(0.0, 0.999 * h1, nu)
    dp = np.linspace(0.0, model.p_a_Pa, ndp)
    F1, V, rk, rcut = (np.empty((nu, ndp)) for _ in range(4))
    profiles = []
    for i, ui in enumerate(u):
        h = h1 - ui
        r, F0 = cup.radius(h), float(curve.force(h))
        l = cup.contact_width(r)
        row = []
        for j, d in enumerate(dp):
            F1[i, j] = d * math.pi * r**2 - F0
            V[i, j], rk[i, j], rcut[i, j] = cup.volume(r), r, r + l
            sigma = F0 / (2 * math.pi * r * l) + cup.beta * d
            row.append(ContactProfile(np.array([r, r + l]), np.array([sigma, sigma])))
        profiles.append(tuple(row))
    return SuctionTable(u, dp, F1, V, rk, rcut, tuple(profiles), E_Pa=model.E_Pa)


#: the coupled route as the paper's own table needs it: eq (6)'s strip geometry, fine quadrature
COUPLED = {"route": "coupled", "radial": "strip", "samples": 1601}


def on_table(model, n_u: int, n_dp: int, **fields):
    """`model` with its own eqs (3)-(7) as the suction table and the interface gas at p_b (eq 6):
    one model for the paper and the coupled route."""
    return replace(model, suction=paper_table(model, n_u, n_dp), interface="p_b", **fields)


@pytest.fixture(scope="module")
def model():
    return reference_model(cup_by_name("A"), illustrative_uc_table())


@pytest.fixture(scope="module")
def refined(model):
    """The model on three nested paper tables (21, 41, 81 points per axis)."""
    return [on_table(model, n, n) for n in (21, 41, 81)]


@pytest.mark.parametrize("F1", [5.0, 20.0, 60.0])
def test_paper_table_reproduces_the_paper_route(model, refined, F1):
    expected = solve_lifetime(model, F1, route="paper").lifetime_s
    errors = [abs(solve_lifetime(m, F1, **COUPLED).lifetime_s / expected - 1) for m in refined]
    assert errors[-1] < 5e-3
    assert errors[2] < errors[0] / 4                     # second order: 4x per halving, twice


def test_start_content_is_the_papers(model):
    cc = CoupledCavity(paper_table(model, 41, 41), model.u_c, model.gas, model.p_a_Pa, interface="p_b")
    dp, N0 = cc.start(model.cup.h1_m - model.cup.h_start_m)
    assert N0 == pytest.approx(force_balance(model).initial[1], rel=1e-3)


def test_over_force_detaches_at_once(model):
    res = solve_lifetime(on_table(model, 21, 21), 200.0, route="coupled")
    assert res.reason == "over_force" and res.lifetime_s == 0.0 and res.largest_force_N < 200.0


def test_suction_table_json_round_trip(model, tmp_path):
    table = paper_table(model, 5, 4)
    back = SuctionTable.from_json(table.to_json(tmp_path / "t.json"))
    for name in ("u_m", "dp_Pa", "F1_N", "V_m3", "seal_r_m", "cut_r_m"):
        assert np.allclose(getattr(back, name), getattr(table, name), rtol=1e-14, atol=0)
    assert np.allclose(back.profiles[2][3].p_Pa, table.profiles[2][3].p_Pa, rtol=1e-14)
    with pytest.raises(ValueError, match="lacks"):
        (tmp_path / "bad.json").write_text('{"u_mm": [0, 1]}')
        SuctionTable.from_json(tmp_path / "bad.json")


def test_kappa_is_the_papers_stiffness_factor(model):
    """kappa scales the table's response like the paper's kappa scales F0 (eqs 5, 6 with kappa F0,
    p/E at the same E): one model with kappa = 2 gives on the coupled route (the unscaled paper
    table) the paper route's lifetimes with F0 doubled (measured 1.3e-3 / 2.2e-4 off on 21x41 /
    41x81 grids), and the paper route's kappa is the curve scaled by it."""
    stiff = on_table(model, 41, 81, kappa=2.0)
    scaled = replace(model, stiffness=model.stiffness.scaled(2.0))
    for F1 in (10.0, 40.0):
        paper_s = solve_lifetime(stiff, F1, route="paper").lifetime_s
        assert paper_s == solve_lifetime(scaled, F1, route="paper").lifetime_s
        assert solve_lifetime(stiff, F1, **COUPLED).lifetime_s == pytest.approx(paper_s, rel=1e-3)
    assert largest_holdable_force(stiff, **COUPLED) == pytest.approx(largest_holdable_force(stiff), rel=1e-2)


def test_interface_gas_bounds_the_lifetime(model):
    """The interface gas beyond the seal at p_b (the table's pressure), rising linearly, or at p_a
    (dp taken off the zone): less solid pressure, wider gaps, more leak, so the lifetimes order
    p_a < linear < p_b."""
    base = on_table(model, 21, 21)
    life = {i: solve_lifetime(replace(base, interface=i), 10.0, route="coupled", radial="strip").lifetime_s
            for i in ("p_a", "linear", "p_b")}
    assert life["p_a"] < life["linear"] < life["p_b"]



# ----------------------------------------------------------------------------- relaxation
#: the coupled route on eq (6)'s strip geometry
STRIP = {"route": "coupled", "radial": "strip"}


def test_flat_relaxation_is_the_quadrature(model):
    """E_eff constant at the table's E: kappa = 1 and p/E as unrelaxed, so the time integration of
    (N, phi) must give the quadrature t = int dN / Ndot (converged: 6401 samples change it by
    < 1e-6 from 1601) to the ODE tolerance (rtol 1e-6; measured 5e-6 / 3.5e-5 / 6e-6 on 41 x 41,
    the kinks of the dp-linear surfaces cost the error control a factor ~30)."""
    flat = RelaxationModulus(np.array([1.0, 10.0]), np.array([4e6, 4e6]))
    quadrature = on_table(model, 41, 41)
    relaxed = replace(quadrature, relaxation=flat, phi0_s=1.0)
    for F1 in (5.0, 20.0, 60.0):
        r = solve_lifetime(relaxed, F1, **STRIP)
        assert r.reason == "table_edge" and np.allclose(r.trajectory["kappa"], 1.0, rtol=1e-12, atol=0)
        assert r.lifetime_s == pytest.approx(solve_lifetime(quadrature, F1, **STRIP, samples=6401).lifetime_s,
                                             rel=1e-4)


@pytest.fixture(scope="module")
def relaxed_refined(model):
    """The relaxed coupled model (default law, phi0 of cup A) on paper tables of 21 and 41 points."""
    phi0 = measurement_contact_time(model.cup)
    return [on_table(model, n, n, relaxation=default_relaxation(), phi0_s=phi0) for n in (21, 41)]


@pytest.mark.parametrize("F1", [5.0, 20.0, 60.0])
def test_relaxed_paper_table_reproduces_the_relaxed_paper_route(model, relaxed_refined, F1):
    """The paper table carries the paper's r (eq 3, the strip's inner edge) and l (eq 5, the
    uniform strip's force-quartile width), so eq 10, kappa(phi) and u_c(p / E_eff(phi)) are the
    paper route's; what remains is the interpolation of the table, second order in the grid as
    unrelaxed (measured 3.1e-3 / 1.9e-3 / 1.9e-3 on 21 x 21 and 7.1e-4 / 4.5e-4 / 3.3e-4 on
    41 x 41, the unrelaxed model's own errors on these grids being the same to 10 %)."""
    expected = solve_lifetime(relaxed_refined[0], F1, route="paper")
    runs = [solve_lifetime(m, F1, **COUPLED) for m in relaxed_refined]
    errors = [abs(r.lifetime_s / expected.lifetime_s - 1) for r in runs]
    assert errors[1] < 1.5e-3
    assert errors[1] < errors[0] / 3                      # second order: 4x per halving
    assert runs[1].trajectory["phi_s"][-1] == pytest.approx(expected.trajectory["phi_s"][-1], rel=5e-3)
    assert runs[1].trajectory["kappa"][0] == pytest.approx(default_relaxation()(0.0) / default_relaxation()(
        measurement_contact_time(model.cup)), rel=1e-12)


def test_softening_lengthens_the_lifetime(model):
    """A law with E_eff(phi0) = the table's E (phi0 = 1 s: kappa(0) = 1, the start is the
    unrelaxed one) that softens (4 -> 1.8 MPa over 3e4 s) lengthens the lifetime; its mirror image
    (4 -> 8.9 MPa) shortens it. The sign: at fixed gas the softer cup holds F1 at a smaller dp
    (kappa F1_tab(u, dp/kappa) = F1), so it settles deeper, away from the table's edge, and the leak's
    drive dp is smaller; the interface does not open, kappa p / E_eff(phi) staying what it was (the
    suction's share beta dp / E_eff even grows). The paper route shows the same sign (117 -> 152 s
    at 5 N with this law)."""
    soft = RelaxationModulus(np.array([1.0, 3e4]), np.array([4e6, 1.8e6]))
    stiff = RelaxationModulus(np.array([1.0, 3e4]), np.array([4e6, 4e6 * 4e6 / 1.8e6]))
    unrelaxed = on_table(model, 21, 21)
    for F1 in (5.0, 60.0):
        base = solve_lifetime(unrelaxed, F1, **STRIP)
        softer = solve_lifetime(replace(unrelaxed, relaxation=soft, phi0_s=1.0), F1, **STRIP)
        stiffer = solve_lifetime(replace(unrelaxed, relaxation=stiff, phi0_s=1.0), F1, **STRIP)
        assert softer.trajectory["kappa"][0] == stiffer.trajectory["kappa"][0] == 1.0
        assert stiffer.lifetime_s < base.lifetime_s < softer.lifetime_s
        assert softer.trajectory["kappa"][-1] < 1.0 < stiffer.trajectory["kappa"][-1]


def test_contact_time_starts_as_the_time(model):
    """phi(0) = 0 and dphi/dt = 1 - rdot phi / l -> 1 while phi is small (eq 10); kappa is
    E_eff(phi) / E_eff(phi0) along the trajectory (phi falls again near the end, where the strip
    moves fast: rdot phi / l > 1), and the CSV columns name both."""
    law = default_relaxation()
    r = solve_lifetime(on_table(model, 21, 21, relaxation=law, phi0_s=13.0), 20.0, **STRIP)
    phi, t = r.trajectory["phi_s"], r.trajectory["t_s"]
    assert phi[0] == 0.0 and phi[1] == pytest.approx(t[1], rel=1e-2)
    assert np.allclose(r.trajectory["kappa"], law(phi) / law(13.0), rtol=1e-12, atol=0)
    assert {"phi_s", "kappa"} <= set(r.trajectory_columns()) and r.summary()["phi_final_s"] > 0


@pytest.mark.parametrize("phi0, match", [(0.0, "phi0_s.*> 0"), (-3.0, "phi0_s.*> 0"),
                                          (math.nan, "phi0_s.*> 0"), (math.inf, "phi0_s.*> 0"),
                                          (None, "phi0_s.*measurement")])
def test_relaxation_bad_input(model, phi0, match):
    with pytest.raises(ValueError, match=match):
        CoupledCavity(paper_table(model, 5, 4), model.u_c, relaxation=default_relaxation(), phi0_s=phi0)


def test_phi0_without_relaxation_is_refused(model):
    with pytest.raises(ValueError, match="phi0_s.*relaxation"):
        CoupledCavity(paper_table(model, 5, 4), model.u_c, phi0_s=13.0)


def test_load_strip_is_the_fem_quartile_strip():
    """r, l of eq 10 against `fem.postprocess.quartile_width` (independent code): a uniform strip
    is itself, and on ramps, peaks and a second zone the widths agree."""
    from fem.postprocess import quartile_width
    strip = ContactProfile(np.array([0.010, 0.0124]), np.array([3e4, 3e4]))
    assert load_strip(strip) == pytest.approx((0.010, 0.0024), rel=1e-12)
    rng = np.random.default_rng(7)
    for _ in range(20):
        r = np.cumsum(rng.uniform(1e-4, 5e-4, 12)) + 0.01
        p = np.where(rng.uniform(size=12) < 0.25, 0.0, rng.uniform(1e3, 1e5, 12))
        p[0] = 0.0
        if not np.any(p > 0):
            continue
        assert load_strip(ContactProfile(r, p))[1] == pytest.approx(quartile_width(r, p), rel=1e-12)


def test_the_coupled_leak_through_a_lone_loaded_node_converges_with_its_spacing():
    """The FEM's lumped pressure at a rim corner grows as the mesh is refined (force over a
    tributary length h). With the u_c table's patch length L the coupled route reads u_c at the
    nominal pressure averaged over L, so the node conductance converges as h -> 0 (towards a
    strip L wide at F/(2 pi R L)); raw, the same force over ever smaller h seals."""
    from reduced.critical_gap import UcTable

    L, R, F = 1e-4, 15e-3, 0.5                               # patch [m], node radius [m], force [N]
    pe = np.geomspace(1e-4, 1.0, 60)
    uc = UcTable(pe, 0.68e-6 * (pe / 0.025) ** -0.8 * (pe < 0.5), patch_length_m=L)

    def conductance(h: float, table_uc) -> float:
        prof = ContactProfile(np.array([R - h, R, R + h]), np.array([0.0, F / (2 * math.pi * R * h), 0.0]))
        u, dp = np.array([1e-3, 2e-3]), np.array([0.0, 2e4])
        grid = np.ones((2, 2))
        table = SuctionTable(u, dp, grid, 1e-6 * grid, (R - h) * grid, (R + h) * grid,
                             ((prof, prof), (prof, prof)), E_Pa=4e6)
        return float(CoupledCavity(table, table_uc)._node_conductance[0, 1])

    q = [conductance(L / n, uc) for n in (16, 64, 256)]
    d1, d2 = abs(q[1] / q[0] - 1), abs(q[2] / q[1] - 1)
    # first order in h / L: the change falls ~4x per 4x refinement (measured 5.8 % then 1.5 %)
    assert d2 < 0.5 * d1 and d2 < 0.02
    raw = replace(uc, patch_length_m=None)
    assert conductance(L / 256, raw) == 0.0                 # the lumped peak seals


def test_unsealed_row_ends_the_branch_and_relaxation_reads_the_pressed_rows(model):
    """A row below the table whose states hold no seal (the rim off the plane): the branch that
    would read it ends there ("reached_r1", before the table without the row ends at its edge; a
    value there raises SealOpen, never a number), and the relaxed integration keeps to the rows
    above it (the same lifetime as without the row)."""
    from reduced.suction_table import SealOpen

    t = paper_table(model, 21, 21)
    n = t.dp_Pa.size
    grids = {k: np.vstack([np.full((1, n), np.nan), getattr(t, k)]) for k in ("F1_N", "V_m3", "seal_r_m", "cut_r_m")}
    sealed = np.vstack([np.zeros((1, n), bool), np.ones(t.F1_N.shape, bool)])
    raised = SuctionTable(u_m=np.concatenate([[t.u_m[0] - 1e-3], t.u_m]), dp_Pa=t.dp_Pa, **grids,
                          profiles=((None,) * n,) + t.profiles, E_Pa=t.E_Pa, provenance=t.provenance,
                          sealed=sealed)
    base = solve_lifetime(replace(model, suction=t), 10.0, route="coupled")
    opened = solve_lifetime(replace(model, suction=raised), 10.0, route="coupled")
    assert base.reason == "table_edge" and opened.reason == "reached_r1"
    assert opened.lifetime_s < base.lifetime_s
    cavity = CoupledCavity(raised, model.u_c)
    with pytest.raises(SealOpen):
        cavity.F1(float(raised.u_m[0]), float(raised.dp_Pa[5]))
    relax = dict(relaxation=default_relaxation(), phi0_s=measurement_contact_time(model.cup))
    assert solve_lifetime(replace(model, suction=raised, **relax), 10.0, route="coupled").lifetime_s == \
        solve_lifetime(replace(model, suction=t, **relax), 10.0, route="coupled").lifetime_s
