"""The profile route's fast path against its direct one: the flow tables (`reduced.seal.PbTable`)
against the flow solved at every state, the batched series flow against the scalar one, the
sealed check against the flow's own u_c, and lifetimes by the integrator and by quadrature."""

import dataclasses
import math

import numpy as np
import pytest

from reduced.appendix_a import appendix_a_force
from reduced.critical_gap import UcTable
from reduced.cup import CUP_A
from reduced.force_balance import force_balance
from reduced.gas import AIR
from reduced.lifetime import lifetime_by_quadrature, reference_model, solve_lifetime
from reduced.profile_leak import ContactProfile, profile_leak_rate, profile_leak_rates
from reduced.seal import ProfileSeal
from reduced.stiffness_curve import StiffnessCurve
from reduced.viscoelastic import default_relaxation

P_A, E = 1e5, 4e6
FORCES_N = (5.0, 20.0, 40.0, 80.0)


@pytest.fixture(scope="module")
def pmma():
    """u_c of the main job's surface (Persson theory, with its patch length: 202 um)."""
    from reduced.roughness import preset, uc_table
    return uc_table(preset("pmma-1.89").spectrum(), 0.5)


def _curve(samples: int = 40) -> StiffnessCurve:
    """Cup A's Appendix A spring with the cone's r, l, V and, per sample, a contact pressure that
    rises across the strip to a rim peak (the FEM's shape: most load at the outer edge), carrying F0."""
    u = np.linspace(0.0, 0.8 * CUP_A.h1_m, samples)
    h = CUP_A.h1_m - u
    x = 1.0 + h / CUP_A.h0_m
    r, l = CUP_A.r0_m * x, CUP_A.l0_m + CUP_A.l_a_m * (1.0 - x)
    F0 = appendix_a_force(u, CUP_A.alpha_deg, E, 2e-3, CUP_A.r0_m, CUP_A.r1_m)
    profiles = [None]
    for ri, li, F in zip(r[1:], l[1:], F0[1:]):
        s = np.linspace(0.0, 1.0, 25)
        shape = 0.3 + s ** 3 + 2.0 * (s > 0.95)
        rr = np.concatenate([[ri - 0.2 * li], ri + li * s, [ri + 1.2 * li]])
        p = np.concatenate([[0.0], shape, [0.0]])
        p *= F / ContactProfile(rr, p).force_N
        profiles.append(ContactProfile(rr, p))
    return StiffnessCurve(u_m=u, F0_N=F0, h1_m=CUP_A.h1_m, r_c_m=r, l_m=l, V_m3=CUP_A.V0_m3 * (x ** 3 - 1),
                          profiles=profiles)


def _model(uc, **kw):
    return dataclasses.replace(reference_model(CUP_A, uc), stiffness=_curve(), **kw)


def _profile(model, exact: bool = False):
    """The profile route's force balance (the curve's laws, the profile seal)."""
    return force_balance(model, "curve", "profile", exact=exact)


def _sealing_table(at: float = 0.01) -> UcTable:
    """A power-law u_c sealed from p/E = at on (the ramp to 0 from the last open row)."""
    p = np.geomspace(1e-5, 0.9 * at, 40)
    return UcTable(np.append(p, at), np.append(0.7e-6 * (p / 0.025) ** -0.6, 0.0), patch_length_m=2e-4)


# ----------------------------------------------------------------- the batched series flow
def test_the_batched_series_flow_is_the_direct_one_state_by_state():
    rng = np.random.default_rng(7)
    r = np.sort(rng.uniform(15e-3, 17e-3, 31))
    pb = np.concatenate([[0.0, 1.0, P_A * (1 - 1e-9), P_A], rng.uniform(0.0, P_A, 40)])
    gaps = 10.0 ** rng.uniform(-8.3, -5.3, (30, pb.size))      # 5 nm (ballistic) .. 5 um (viscous)
    gaps[[3, 17]] = math.inf                                    # rings out of contact
    gaps[5, 6] = 0.0                                            # one state sealed
    q = profile_leak_rates(AIR, P_A, pb, r, gaps)
    direct = np.array([profile_leak_rate(AIR, P_A, b, r, g) for b, g in zip(pb, gaps.T)])
    assert q[6] == 0.0 and q[3] == 0.0 and direct[6] == 0.0
    assert np.all(q[direct > 0] > 0)
    np.testing.assert_allclose(q, direct, rtol=1e-11, atol=0.0)
    with pytest.raises(ValueError, match="p_b: cavity pressures must be in"):
        profile_leak_rates(AIR, P_A, np.array([-1.0]), r, gaps[:, :1])


def test_the_batched_march_stops_where_the_gas_pressure_would_fall_below_zero():
    """As `_march` (tests/test_reduced_profile_leak.py): a narrow outer ring after a wide inner
    one; the flow at p_b = 0 is the largest with P >= 0 all the way."""
    u = np.array([10e-6, 10e-9])
    r = np.array([10e-3, 10.5e-3, 10.6e-3])
    q = profile_leak_rates(AIR, P_A, np.array([0.0, 5e4]), r, u[:, None].repeat(2, axis=1))
    assert q == pytest.approx([profile_leak_rate(AIR, P_A, 0.0, r, u), profile_leak_rate(AIR, P_A, 5e4, r, u)],
                              rel=1e-11)


# ----------------------------------------------------------------- the flow tables
@pytest.mark.parametrize("fluid", ["air", "water"])
def test_the_flow_table_follows_the_direct_flow(pmma, fluid):
    """Every sample's table against the flow solved at p_b where the cup lives (0.1 .. 99 % of
    p_a): within 2e-6 (measured 1e-6 near the grid's high-p_b end, ~1e-7 elsewhere); outside the
    grid the direct flow is used."""
    model = _model(pmma, fluid=fluid)
    seal = _profile(model).seal
    assert seal.tabulate_at == (1.0, E) and seal.patch_length_m == pmma.patch_length_m
    pb = np.concatenate([np.geomspace(150.0, 0.99 * P_A, 25), P_A - np.geomspace(1.0, 1e3, 6)])
    worst = 0.0
    for k in range(1, len(seal.profiles), 3):
        direct = np.array([seal._at(k, b, 1.0, E)[0] for b in pb])
        table = np.array([seal._tabulated(k, b, 1.0, E) for b in pb])
        worst = max(worst, float(np.max(np.abs(table / direct - 1))))
        assert seal._tabulated(k, 10.0, 1.0, E) is None          # below the grid's p_b: direct
        assert seal._tabulated(k, 1e4, 1.0, 0.9 * E) is None     # another modulus: direct
    assert worst < 2e-6


def test_the_tabulated_flows_outputs_are_the_direct_ones(pmma):
    """Where the table gives Ndot, the peak pressure is the same and u_c (the narrowest gap, at the
    highest ring pressure since u_c falls with p) the same to round-off; the share follows u_c."""
    model = _model(pmma)
    fast, direct = _profile(model).seal, _profile(model, exact=True).seal
    for u in (0.7e-3, 2.5e-3, 4.1e-3, 6e-3):
        for pb in (3e3, 5e4, 9.5e4):
            a, b = fast.flow(0.0, 0.0, 0.0, pb, 1.0, E, u), direct.flow(0.0, 0.0, 0.0, pb, 1.0, E, u)
            assert a[0] == pytest.approx(b[0], rel=2e-6) and a[1] == b[1]
            assert a[2] == pytest.approx(b[2], rel=1e-12) and a[3] == pytest.approx(b[3], rel=1e-12)
            assert fast.rate(0.0, 0.0, 0.0, pb, 1.0, E, u) == a[0]


def test_the_rate_is_the_flows_first_entry_on_the_direct_path(pmma):
    seal = _profile(_model(pmma), exact=True).seal
    assert seal.tabulate_at is None
    for u in (1e-3, 2.5e-3, 4e-3):
        for pb in (0.0, 3e4, 9e4):
            assert seal.rate(0.0, 0.0, 0.0, pb, 1.0, E, u) == seal.flow(0.0, 0.0, 0.0, pb, 1.0, E, u)[0]


# ----------------------------------------------------------------- the sealed check
@pytest.mark.parametrize("patch", [None, 0.0])
@pytest.mark.parametrize("fluid", ["air", "water"])
def test_the_sealed_check_is_the_flows_u_c_at_every_state(patch, fluid):
    """seal.sealed (the highest ring pressure against the sealing p/E) is `flow`'s u_c <= 0 at
    every state, averaged (the table's patch) or raw (patch_length_m=0), between and at samples."""
    table = _sealing_table(0.03)         # between the samples' peak p/E with and without the suction
    curve = _curve(12)
    seal = ProfileSeal(curve, table, AIR, P_A, 0.8, 1e-3 if fluid == "water" else None, patch_length_m=patch)
    u = np.concatenate([curve.u_m[1:], 0.5 * (curve.u_m[1:-1] + curve.u_m[2:])])
    seen = set()
    for ui in u:
        for pb in (-2e4, 0.0, 2e4, 5e4, 8e4, 9.9e4, P_A) if fluid == "water" else (0.0, 2e4, 5e4, 8e4, 9.9e4, P_A):
            for kappa, modulus in ((1.0, E), (1.3, 3e6)):
                expect = seal.flow(0.0, 0.0, 0.0, pb, kappa, modulus, float(ui))[2] <= 0.0
                assert seal.sealed(0.0, 0.0, 0.0, pb, kappa, modulus, float(ui)) == expect, (ui, pb, kappa)
                seen.add(expect)
    assert seen == {True, False}


def test_cannot_seal_bounds_every_state(pmma):
    """With pmma-1.89 (sealing at p/E = 0.15) no ring of the curve reaches sealing even at p_b = 0;
    with a table sealing at 0.01 some do, and the bound says so."""
    curve = _curve(12)
    assert ProfileSeal(curve, pmma, AIR, P_A, 0.8, None).cannot_seal(1.0, E)
    low = ProfileSeal(curve, _sealing_table(), AIR, P_A, 0.8, None)
    assert not low.cannot_seal(1.0, E)
    assert any(low.sealed(0.0, 0.0, 0.0, 0.0, 1.0, E, float(u)) for u in curve.u_m[1:])
    high = ProfileSeal(curve, _sealing_table(0.5), AIR, P_A, 0.8, None)
    assert high.cannot_seal(1.0, E)
    assert not any(high.sealed(0.0, 0.0, 0.0, pb, 1.0, E, float(u)) for u in curve.u_m[1:] for pb in (0.0, 5e4))


# ----------------------------------------------------------------- lifetimes
@pytest.mark.parametrize("fluid", ["air", "water"])
def test_tabulated_lifetimes_agree_with_the_direct_path(pmma, fluid):
    """By quadrature (no time stepping, so no step sequence to perturb) the tables change the
    lifetime by < 1e-8 (measured ~1e-10); through the integrator by less than its own error at
    the default rtol (the step sizes follow the error estimate's cancellations, so a change of
    the rate at the 1e-12 level already moves a lifetime by ~1e-5): < 1e-3, the brief's bar."""
    model = _model(pmma, fluid=fluid)
    for F in FORCES_N:
        fast, direct = solve_lifetime(model, F, route="profile"), solve_lifetime(model, F, route="profile", exact=True)
        assert fast.reason == direct.reason == "reached_r1"
        assert fast.lifetime_s == pytest.approx(direct.lifetime_s, rel=1e-3)
        q_fast = lifetime_by_quadrature(model, F, route="profile", epsrel=1e-10)
        q_direct = lifetime_by_quadrature(model, F, route="profile", epsrel=1e-10, exact=True)
        assert q_fast == pytest.approx(q_direct, rel=1e-8)
        assert direct.lifetime_s == pytest.approx(q_direct, rel=1e-3)


def test_relaxation_keeps_the_direct_path(pmma):
    """With relaxation kappa and E change along the way: no table, the same lifetime to the bit."""
    model = _model(pmma, relaxation=default_relaxation())
    assert _profile(model).seal.tabulate_at is None
    a = solve_lifetime(model, 20.0, route="profile")
    assert a.lifetime_s == solve_lifetime(model, 20.0, route="profile", exact=True).lifetime_s


def test_the_exact_option_is_checked(pmma):
    with pytest.raises(ValueError, match="exact: expected True or False"):
        solve_lifetime(_model(pmma), 10.0, route="profile", exact="yes")
    with pytest.raises(ValueError, match="exact: not an option of route 'paper'"):
        solve_lifetime(reference_model(CUP_A, pmma), 10.0, route="paper", exact=True)


@pytest.mark.slow
def test_the_main_jobs_lifetimes_tabulated_against_direct():
    """The main job (scenes/main.toml: cup A, medium frictionless FEM, pmma-1.89, 16 forces), and
    its water-filled variant: tabulated against direct, < 1e-3 through the integrator (measured
    <= 1.0e-4, the integrator's own error at rtol 1e-6) and < 1e-8 by quadrature (measured 2e-10)."""
    from pathlib import Path

    from validation.bridge.products import Products, _model as study_model
    from validation.scenes.schema import load_scene

    study = load_scene(Path(__file__).resolve().parents[1] / "scenes" / "main.toml").study()
    products = Products(study)
    model = study_model(study, products.curve(), products.uc_table(), products.cup())
    for m, forces in ((model, study.loads.forces_N), (dataclasses.replace(model, fluid="water"), FORCES_N)):
        for F in forces:
            fast = solve_lifetime(m, F, route="profile", refine=2)
            direct = solve_lifetime(m, F, route="profile", refine=2, exact=True)
            assert fast.lifetime_s == pytest.approx(direct.lifetime_s, rel=1e-3), F
            assert lifetime_by_quadrature(m, F, route="profile", epsrel=1e-10) == pytest.approx(
                lifetime_by_quadrature(m, F, route="profile", epsrel=1e-10, exact=True), rel=1e-8), F
