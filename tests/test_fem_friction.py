"""Coulomb friction at the plane (`fem.contact`, `fem.friction`): its limits, its law, its energy.

Independent checks: mu = 0 is the frictionless law and a large mu the sticking law (two other
solvers' paths), through the wall's landing and snap to 0.9 h1; Coulomb's F0 lies between the
frictionless and the sticking one on a monotone press; every converged state, also those reached
by damped motion across an instability (`fem.newton.relax_step`), is in global equilibrium (plate
force = sum of the contact reactions); a ring pressed and then sheared over the plane slides as a whole once the shear
reaches mu times the normal load, by global equilibrium (sum of the nodal friction forces =
-mu sum of the normal reactions, whatever the stress field); the work done equals the stored
energy plus what the slips dissipate, sum of mu lambda |Delta| per step, to the trapezoid's error,
which falls with the step.
"""

from __future__ import annotations

import numpy as np
import pytest
from skfem import MeshQuad, MeshQuad2

from fem.contact import RigidPlane
from fem.laws import Coulomb
from fem.cup import CupSetup, compress_cup
from fem.forms import Mechanics
from fem.geometry import cup_geometry
from fem.kinematics import Kinematics
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from fem.solver import SolverOptions, follow_path

MAT = NeoHookean(E_Pa=4e6, nu=0.49)


@pytest.fixture(scope="module")
def mesh():
    return cup_mesh(cup_geometry("A"), "coarse")


def _F0_end(mesh, u_mm, contact, mu=0.0):
    return compress_cup(mesh, MAT, contact=contact, friction=mu, u_max_m=u_mm * 1e-3)


def test_mu_zero_is_frictionless(mesh):
    """mu = 0: the same end state as the frictionless law, to the solver's tolerance."""
    for u_mm in (1.0, 3.0):
        a = _F0_end(mesh, u_mm, "frictionless")
        b = _F0_end(mesh, u_mm, "coulomb", 0.0)
        assert b.F0_N[-1] == pytest.approx(a.F0_N[-1], rel=2e-5)
        assert b.r_c_m[-1] == pytest.approx(a.r_c_m[-1], rel=1e-6)


def test_large_mu_is_sticking(mesh):
    """mu = 10: the sticking law's curve within 0.5 % up to touchdown of the wall (0.45 h1).
    Both laws are path dependent: the sticking curve itself moves by 0.3 % between steps of
    0.01 and 0.02 of the range, so both run with 0.01."""
    u_max = 0.45 * 9.0921e-3
    st = compress_cup(mesh, MAT, contact="sticking", u_max_m=u_max, max_step=0.01)
    co = compress_cup(mesh, MAT, contact="coulomb", friction=10.0, u_max_m=u_max, max_step=0.01)
    u = np.linspace(0.05, 1.0, 20) * u_max
    F_st, F_co = np.interp(u, st.u_m, st.F0_N), np.interp(u, co.u_m, co.F0_N)
    assert np.max(np.abs(F_co / F_st - 1.0)) < 5e-3


def _vertical_A(level):
    return cup_mesh(cup_geometry("A", thickness_convention="vertical"), level)


def _press(mesh, contact, mu=0.0, **opts):
    return compress_cup(mesh, NeoHookean(E_Pa=4e6, nu=0.45), contact=contact, friction=mu, **opts)


def _largest_deviation(ref, other):
    """max |F_other / F_ref - 1| at ref's steps (u > 0), F_other interpolated."""
    u = ref.u_m[1:]
    return float(np.max(np.abs(np.interp(u, other.u_m, other.F0_N) / ref.F0_N[1:] - 1.0)))


def test_large_mu_is_sticking_over_the_whole_curve():
    """Cup A (nu 0.45, vertical thickness, coarse, default steps) to 0.9 h1: Coulomb at mu = 10
    follows the sticking law within 3 % through the wall's landing (u ~ 4.3 mm) and the late
    instability (~7.6 mm), where a long step let the contact slide off the sticking path (-64 %
    at the end before the steps across instabilities were shortened); every state in equilibrium."""
    mesh = _vertical_A("coarse")
    st, co = _press(mesh, "sticking"), _press(mesh, "coulomb", 10.0)
    assert not co.partial and co.u_m[-1] == pytest.approx(st.u_m[-1])
    assert _largest_deviation(st, co) < 0.03
    assert np.max(co.cone_excess) < 1e-6
    np.testing.assert_allclose(co.F0_contact_N, co.F0_N, rtol=1e-5, atol=1e-6 * np.max(co.F0_N))
    assert co.stats.dissipated_J > 0.0          # the slips dissipate


def test_stiffness_rises_with_mu(mesh):
    """F0 at fixed u is monotone in mu, from the frictionless value towards the sticking one;
    every converged state lies in Coulomb's cone."""
    runs = [_F0_end(mesh, 2.0, "coulomb", mu) for mu in (0.0, 0.1, 0.3, 1.0, 3.0)]
    F = [r.F0_N[-1] for r in runs]
    lo, hi = _F0_end(mesh, 2.0, "frictionless").F0_N[-1], _F0_end(mesh, 2.0, "sticking").F0_N[-1]
    assert np.all(np.diff(F) > 0.0)
    assert F[0] == pytest.approx(lo, rel=2e-5) and F[-1] < hi * (1 + 5e-3)
    assert max(np.max(r.cone_excess) for r in runs) < 1e-6


def _ring(R, w=2e-3, H=1e-3, nr=4, nz=2):
    base = MeshQuad.init_tensor(np.linspace(R, R + w, nr + 1), np.linspace(0.0, H, nz + 1))
    return MeshQuad2.from_mesh(base).with_defaults()


def _press_and_shear(mu, R=2.0, press_m=2e-5, shear_m=2e-4, steps=40):
    """A ring (radius R, 2 mm wide, 1 mm high) on the plane: its top pressed down by press_m (t in [0, 1]), then moved
    outward by shear_m (t in [1, 2]), bottom nodes in Coulomb contact. Returns the states."""
    mesh = _ring(R)
    kin = Kinematics.of(mesh)
    plane = RigidPlane.on(kin, ["bottom"], Coulomb(mu))
    top = np.unique(kin.basis.get_dofs(mesh.boundaries["top"]).all() // 2)
    dofs = np.concatenate([2 * top, 2 * top + 1])

    def dirichlet(t):
        u_r = shear_m * max(t - 1.0, 0.0)
        return dofs, np.concatenate([np.full(len(top), u_r), np.full(len(top), -press_m * min(t, 1.0))])

    out = []
    follow_path(Mechanics(kin, MAT), dirichlet, 2.0, plane=plane, on_step=out.append,
                options=SolverOptions(initial_step=1.0 / steps, max_step=1.0 / steps))
    return plane, top, out


def _shear_ratio(s, top):
    return np.sum(s.r_int[2 * top]) / -np.sum(s.r_int[2 * top + 1])


def test_ring_slides_at_mu_times_normal_load():
    """Pressed, the ring's bottom is far inside the cone; sheared, it slides outward as a whole
    and the top's shear/normal force ratio T/N tends to mu. T/N = mu is global equilibrium of a
    plane block; in the ring the hoop stress takes a share O(w/R) of the radial balance, so the
    deviation from mu falls tenfold from R = 0.2 m to 2 m."""
    mu = 0.3
    deviation = {}
    for R in (0.2, 2.0):
        plane, top, out = _press_and_shear(mu, R)
        ratios = np.array([_shear_ratio(s, top) for s in out[1:]])
        pressed = int(np.argmin(np.abs(np.array([s.t for s in out[1:]]) - 1.0)))
        assert abs(ratios[pressed]) < 0.1 * mu
        end = out[-1].contact
        assert end.active.sum() >= len(plane.nodes) - 1      # the inner corner may tip up
        assert np.all(end.slip[end.active] == 1)
        deviation[R] = mu - ratios[-1]
    assert 0.0 < deviation[2.0] < 2e-3 * mu
    assert 5.0 < deviation[0.2] / deviation[2.0] < 20.0


def _energy_balance(steps, mu=0.3):
    """(W0 + work - W1, the friction dissipation sum mu lambda |Delta| by the trapezoidal rule)."""
    plane, top, out = _press_and_shear(mu, steps=steps)
    work = friction = 0.0
    for s0, s1 in zip(out[:-1], out[1:]):
        for d in (2 * top, 2 * top + 1):
            work += 0.5 * (s0.r_int[d] + s1.r_int[d]) @ (s1.u[d] - s0.u[d])
        slip = s1.u[2 * plane.nodes] - s0.u[2 * plane.nodes]
        lam = [np.maximum(plane.reactions(s.r_int), 0.0) * s.contact.active for s in (s0, s1)]
        friction += np.sum(mu * 0.5 * (lam[0] + lam[1]) * np.abs(slip))
    return out[0].energy_J + work - out[-1].energy_J, friction


def test_work_is_stored_energy_plus_friction_dissipation():
    """W0 + work - W1 = sum mu lambda |Delta| > 0 to the trapezoid's error, which falls at
    second order with the step (measured: 0.78 %, 0.24 %, 0.05 % at 20, 40, 80 steps per phase)."""
    errors = []
    for steps in (20, 40, 80):
        defect, friction = _energy_balance(steps)
        assert defect > 0.0 and friction > 0.0
        errors.append(abs(defect - friction) / friction)
    assert errors[-1] < 1e-3
    assert errors[1] < 0.45 * errors[0] and errors[2] < 0.45 * errors[1]


def test_converged_states_hold_coulombs_law_node_by_node(mesh):
    """Every converged state of a path with sticking and sliding nodes (coarse cup A, mu = 3, to
    3 mm) satisfies the law at each held node, checked from the states alone: lambda >= 0; a
    sticking node has not moved radially in the step (it is at its anchor) and |t| <= mu lambda;
    a sliding node carries t = -mu lambda s and has moved in its slip direction s."""
    cup = CupSetup.of(mesh, MAT, "coulomb", 3.0)
    out = []
    follow_path(cup.mech, cup.plate_at(0.0), 3e-3, plane=cup.plane, on_step=out.append,
                options=SolverOptions(initial_step=0.05, max_step=0.05))
    rd, mu, kinds = 2 * cup.plane.nodes, 3.0, set()
    for s0, s1 in zip(out[:-1], out[1:]):
        a, slip = s1.contact.active, s1.contact.slip
        lam, t = s1.r_int[rd + 1], s1.r_int[rd]
        scale = np.max(lam[a])
        moved = s1.u[rd] - s0.u[rd]
        assert np.all(lam[a] >= -1e-6 * scale)
        stuck, sliding = a & (slip == 0), a & (slip != 0)
        was = s0.contact.active                 # held at the step's start: anchored there
        assert np.all(np.abs(moved[stuck & was]) <= 1e-12 * np.max(np.abs(s1.u)))
        assert np.all(np.abs(t[stuck]) <= mu * lam[stuck] + 1e-6 * scale)
        np.testing.assert_allclose(t[sliding], -mu * lam[sliding] * slip[sliding], atol=1e-6 * scale)
        assert np.all(slip[sliding & was] * moved[sliding & was] > 0.0)
        kinds |= {int(k) for k in slip[a]}
    assert kinds >= {0, 1}


LANDING_MM = (3.95, 4.5)      # where the wall lands on the plane and F0 rises tenfold


@pytest.mark.slow
def test_large_mu_is_sticking_over_the_whole_curve_medium():
    """The same on the medium mesh, both laws at 1/4 of the default step (at the default step the
    sticking path itself jumps at u ~ 7.3 mm and lies 14 % below its refined curve). Within 3 %
    (measured 0.7 %) but for the landing, where F0 rises tenfold within 0.5 mm and a shift of
    the touchdown by a fraction of a step moves it by 4.7 %. The issue's command (u_max 4.2 mm,
    default steps), which stopped at 2.29 mm after 400 iterations (the linearized problem had no
    stick/slide set at the rim's edge node), runs, within 3 % of sticking before the landing."""
    mesh = _vertical_A("medium")
    st, co = (_press(mesh, law, mu, max_step=0.0125) for law, mu in (("sticking", 0.0), ("coulomb", 10.0)))
    assert not co.partial and co.u_m[-1] == pytest.approx(st.u_m[-1])
    u = co.u_m[1:]
    away = (u < LANDING_MM[0] * 1e-3) | (u > LANDING_MM[1] * 1e-3)
    assert np.max(np.abs(co.F0_N[1:][away] / np.interp(u[away], st.u_m, st.F0_N) - 1.0)) < 0.03
    short = _press(mesh, "coulomb", 10.0, u_max_m=4.2e-3)
    assert not short.partial and short.u_m[-1] == pytest.approx(4.2e-3)
    before = short.u_m[1:] < LANDING_MM[0] * 1e-3
    F_st = np.interp(short.u_m[1:][before], st.u_m, st.F0_N)
    assert np.max(np.abs(short.F0_N[1:][before] / F_st - 1.0)) < 0.03


@pytest.mark.slow
def test_path_through_the_snap_converges_under_step_refinement(mesh):
    """Coarse cup A (nu 0.49), mu = 2, to 0.9 h1: the wall lands (u ~ 4.6 mm) by a slip of
    ~1.6 mm that no quasi-static step resolves; with the damped motion across it the path
    converges as the largest step goes from the default 0.05 of the range to 1/2, 1/4, 1/8 of
    it: past the landing the change of F0 (at 5, 6, 7, 8 mm) falls with each halving
    (benchmarks/bench_friction.py --refine --fidelity coarse)."""
    steps = (0.05, 0.025, 0.0125, 0.00625)
    u = np.array([5.0, 6.0, 7.0, 8.0]) * 1e-3
    F = []
    for step in steps:
        r = compress_cup(mesh, MAT, contact="coulomb", friction=2.0, max_step=step)
        assert not r.partial
        F.append(np.interp(u, r.u_m, r.F0_N))
    change = [np.max(np.abs(F[i + 1] / F[i] - 1.0)) for i in range(len(steps) - 1)]
    assert change[2] < change[1] < change[0]
    assert change[2] < 0.01          # measured 3.3 %, 1.9 %, 0.57 %
