"""Path following through the instabilities of thin and steep walls (issue 3, robustness).

Three cases that failed with ConvergenceError before (benchmarks/bench_robustness.py), each for a
different reason, run to the end and are checked against laws the solver does not enforce:

* the equilibrium of the converged states: the plate reaction F0 equals the integrated contact
  pressure 2 pi int p r dr (to 1e-4 of max F0; the Newton tolerance is 1e-6 of the reaction);
* the energy bookkeeping: int F0 du (trapezoid) = W(end) + the dissipation the solver reports,
  and for frictionless contact the dissipation is small (no snap that a smaller step would not
  reproduce is accepted), for sticking it is >= 0 (slip and snaps can only lose energy).

These are tests of the solver: the states of the thin walls are followed with
`admissible_only=False`, since by default `fem.integrity` ends them where they turn over and a
facet dips below the plane between its nodes (tests/test_fem_integrity.py).

The parts are tested on small matrices: the diagonal shift stays within a factor of ten of the
smallest one that makes the tangent definite, and is found in few factorizations; the line search
extrapolates a shifted step down an energy valley; and the round-off acceptance of the residual.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from fem.cup import compress_cup
from fem.linsolve import BandedCholesky
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from fem.factorization import ShiftPolicy, factor_shifted
from fem.linesearch import extrapolate
from fem.newton import balanced
from fem.solver import SolverOptions
from validation.crosscheck.runs import FemRun


def _run(alpha_deg, d_root_mm, contact, u_max_over_h1=0.9, max_step=0.05):
    req = FemRun(cup="A", contact=contact, alpha_deg=alpha_deg, d_root_mm=d_root_mm,
                 u_max_over_h1=u_max_over_h1, max_step=max_step)
    g = req.geometry()
    # the solver's path regardless of admissibility: these walls turn over and their contact edge
    # falls inside an element, which `fem.integrity` refuses by default (tests/test_fem_integrity.py)
    r = compress_cup(cup_mesh(g, "coarse"), NeoHookean(), contact,
                     u_max_m=u_max_over_h1 * g.h1_m, max_step=max_step, admissible_only=False)
    return g, r


def _checks(g, r, u_max_over_h1):
    assert r.u_m[-1] == pytest.approx(u_max_over_h1 * g.h1_m)
    # global equilibrium: plate reaction = sum of the contact reactions (what is left is the
    # z-sum of the free residual, so this bounds the Newton tolerance's effect on F0)
    assert np.max(np.abs(r.F0_N - r.F0_contact_N)) <= 1e-4 * np.max(r.F0_N)
    # a bookkeeping identity, not a physics check: dissipated_J is defined as the trapezoid work
    # minus the stored energy; it guards the accounting of redone and jumped steps
    work = np.sum(0.5 * (r.F0_N[1:] + r.F0_N[:-1]) * np.diff(r.u_m))
    assert work == pytest.approx(r.energy_J[-1] + r.stats.dissipated_J, rel=1e-9)
    return work


def test_thin_cone_is_followed_through_its_buckling():
    """alpha = 45 deg, root 0.5 mm, frictionless: the LM shift floor of 1e-6 damped the unstable
    mode (its eigenvalue is below 1e-6 of the diagonal) and the descent crept until
    max_iterations at u = 5.4 mm. Now it reaches 0.9 h1 in equilibrium, and int F0 du = W to
    2 % of W (measured 0.9 %: 0.45 % lost in the snaps, which a step may carry up to
    jump_tol = 0.5 % of W, and 0.56 % of trapezoid error on F0(u) sampled every <= 0.05 u_max
    with kinks where the wall's nodes land)."""
    g, r = _run(45.0, 0.5, "frictionless")
    _checks(g, r, 0.9)
    assert r.unstable.sum() > 0
    assert abs(r.stats.dissipated_J) <= 0.02 * r.energy_J[-1]


def test_sticking_thin_wall_slips_through():
    """alpha = 45 deg, root 1 mm, sticking: the wall slips node by node through a snap, a descent
    of up to ~300 Newton iterations in one step that the earlier limit of 100 cut off. Sticking
    may only lose energy (slip, snaps): the reported dissipation is >= 0 up to the trapezoid
    error, budgeted at 2 % of W as for the frictionless cone above."""
    g, r = _run(45.0, 1.0, "sticking")
    _checks(g, r, 0.9)
    assert r.stats.dissipated_J >= -0.02 * r.energy_J[-1]


def test_thinnest_wall_converges_at_its_round_off_floor():
    """alpha = 45 deg, root 0.1 mm, frictionless to u = h1 in 1 % steps (the extremes grid): the
    residual stagnated at 1.2e-6 of the reaction with Newton corrections of 1e-16 m (the wall's
    cancelling element forces dwarf the reaction) until max_iterations at u = 3.07 mm. It now
    reaches h1 in equilibrium. (The energy at u -> h1, where F0 rises a hundredfold in the last
    step, is the trapezoid's to judge, not the solver's: bench_robustness.py.)"""
    g, r = _run(45.0, 0.1, "frictionless", u_max_over_h1=1.0, max_step=0.01)
    _checks(g, r, 1.0)


def test_shift_stays_near_the_critical_one():
    """A definite matrix but for one eigenvalue of -1e-8 (relative to the unit diagonal): the
    shift s that factors K + s diag(K) lies in (1e-8, 1e-7], within the factor of ten of the
    policy, not at a fixed floor of 1e-6 that would damp the unstable mode a hundredfold."""
    n = 8
    rng = np.random.default_rng(3)
    Q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    lam = np.linspace(1.0, 2.0, n)
    lam[0] = -1e-8
    A = Q @ np.diag(lam) @ Q.T
    A /= np.sqrt(np.outer(np.diag(A), np.diag(A)))     # unit diagonal, same inertia
    K = sp.csr_matrix(A)
    coords = np.vstack([np.arange(n // 2, dtype=float), np.zeros(n // 2)])
    solver = BandedCholesky(K, coords)
    crit = -np.linalg.eigvalsh(A)[0]
    _, shift = factor_shifted(solver, K, np.ones(n, bool), 0.0, [])
    assert crit < shift <= 10.0 * crit * (1 + 1e-12) or crit < shift <= 1e-10
    _, again = factor_shifted(solver, K, np.ones(n, bool), shift, [])
    assert again == pytest.approx(shift)      # tried tenfold smaller, failed, back


def test_round_off_residual_is_accepted_only_with_a_vanishing_correction():
    """||r|| = 1.2 tol is accepted when the Newton correction is below 1e-12 of u (round-off: it
    cannot be reduced), not when the correction is still 1e-9 of u, and never above 100 tol."""
    u = np.full(4, 3e-3)
    assert balanced(0.9, 1.0, np.full(4, 1.0), u)
    assert balanced(1.2, 1.0, np.full(4, 2e-16), u)
    assert not balanced(1.2, 1.0, np.full(4, 3e-12), u)
    assert not balanced(101.0, 1.0, np.zeros(4), u)


def test_jump_options_are_validated():
    with pytest.raises(ValueError, match="jump_tol"):
        SolverOptions(jump_tol=0.0)


def _indefinite(critical: float, n: int = 8, seed: int = 3):
    """A symmetric matrix with unit diagonal, definite but for one eigenvalue -critical, and its
    banded solver."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    lam = np.linspace(1.0, 2.0, n)
    lam[0] = -critical
    A = Q @ np.diag(lam) @ Q.T
    A /= np.sqrt(np.outer(np.diag(A), np.diag(A)))
    coords = np.vstack([np.arange(n // 2, dtype=float), np.zeros(n // 2)])
    K = sp.csr_matrix(A)
    return K, BandedCholesky(K, coords), -np.linalg.eigvalsh(A)[0]


def test_shift_search_is_short_and_remembers_the_last_episode():
    """An unstable episode that needs a shift of ~1e-2 (sticking cup A's episodes need 1e-3 to
    1e-1): the search from 0 brackets and bisects in log-space, <= 8 factorizations, where a
    tenfold ladder from 1e-10 takes 11. The next episode starts from the shift that opened this
    one: <= 6 factorizations. Both end within the factor of ten above the critical shift."""
    K, solver, crit = _indefinite(1e-2)
    free = np.ones(K.shape[0], bool)
    policy = ShiftPolicy()
    _, shift = factor_shifted(solver, K, free, 0.0, [], policy)
    assert crit < shift <= 10.0 * crit
    assert policy.factorizations <= 8 and policy.failed >= 1
    first = policy.factorizations
    K2, solver2, crit2 = _indefinite(3e-3, seed=5)      # the next episode, a little milder
    _, shift2 = factor_shifted(solver2, K2, free, 0.0, [], policy)
    assert crit2 < shift2 <= 10.0 * crit2
    assert policy.factorizations - first <= 6


class _Valley:
    """Pi(u) = k/2 (u0 - 6)^2 on one dof (a minimum six unit steps away) that inverts an element
    (FloatingPointError) beyond u0 = `wall`; `evaluate` as `fem.forms.Mechanics`."""

    def __init__(self, wall=np.inf):
        self.wall = wall

    def energy(self, u):
        if u[0] > self.wall:
            raise FloatingPointError("inverted element")
        return 0.5 * (u[0] - 6.0) ** 2

    def evaluate(self, u):
        return self.energy(u), np.array([u[0] - 6.0]), sp.csr_matrix(np.eye(1))


class _UnitStep:
    plane, du = None, np.array([1.0])


@pytest.mark.parametrize("wall, expected", [(np.inf, 4.0), (3.0, 2.0)])
def test_shifted_step_is_extrapolated_down_the_valley(wall, expected):
    """After a full shifted step u = 1 is accepted, the step doubles while the energy falls by
    Armijo: 2 and 4 do, 8 does not (Pi(8) = Pi(4)), so u = 4; an element inverting beyond u = 3
    stops it at 2. The state returned is evaluated there (energy and residual of that u)."""
    mech, u = _Valley(wall), np.zeros(1)
    Pi, r, _ = mech.evaluate(u)
    trial = np.array([1.0])
    Pi1, r1, K1 = mech.evaluate(trial)
    alpha, u1, Pi_a, r_a, _ = extrapolate(mech, _UnitStep(), u, u, Pi, r, np.zeros(1), trial,
                                           Pi1, r1, K1, 0.0)
    assert alpha == expected and u1[0] == expected
    assert Pi_a == mech.energy(u1) < Pi1 and r_a[0] == expected - 6.0


@pytest.mark.slow
def test_sticking_rim_does_not_snap_on_the_fine_level():
    """Sticking contact dissipates in slips, so its line search does not extrapolate a shifted
    step down the energy (`fem.solver._line_search`): on the fine level with default steps the
    extrapolated descent made the rim slip, F0 falling from 2.08 to 0.60 N at u = 0.063 h1.
    With small steps (the reference runs) F0 rises monotonically up to its peak near 0.3 h1; so
    must the default-step path, up to 0.2 h1 (~30 s)."""
    from fem.geometry import cup_geometry
    geometry = cup_geometry("A")
    # the solver's path to 0.9 h1 (its last state folds the outer face into the clamped end face,
    # which fem.integrity refuses by default; this test is about the early path)
    r = compress_cup(cup_mesh(geometry, "fine"), NeoHookean(), "sticking", u_max_m=0.9 * geometry.h1_m,
                     admissible_only=False)
    early = r.u_m <= 0.2 * geometry.h1_m
    assert np.all(np.diff(r.F0_N[early]) > 0)
    assert r.F0_N[early][-1] > 4.5          # 4.81 N at 0.18 h1 (small steps: 4.92 at 0.2 h1)
