"""The cost of the held branch (`fem.gas_branch`, `fem.branch_walk`) as a count of Newton
iterations, and its states checked against a second walk: Coulomb's F1 roots correct their first
trial by a trial started from it (its displacement moved by its linear response, its stick/slide
set, the branch state's anchors: `Walk._corrects`); the reference walk starts every trial at the
branch state, as the step's history defines it. Both must find the same states (to the root's
tolerance) where the step has one solution (mu = 0.5) and where it has two (mu = 2: the seal's
inner nodes held or let go), the started one in fewer Newton iterations."""

from __future__ import annotations

import numpy as np
import pytest

import reduced
from fem.branch_walk import Walk
from fem.gas_branch import equilibrium_branch
from fem.interface import ContactLaw
from validation.bridge.fem_route import DEFAULT_DU_M, FemCup, register
from validation.bridge.pipeline import surface_uc_table

F1 = 10.0           # N


class FromState(Walk):
    """The reference: every trial of an F1 root started at the branch state (no started trial)."""

    def __init__(self, cup, F1_N):
        super().__init__(cup, F1_N)
        self.predicting = False


@pytest.fixture(scope="module")
def model():
    return reduced.reference_model(reduced.CUP_A, surface_uc_table())


def _both(model, mu: float, u_min_m: float):
    route = register()
    cup = FemCup("A", "coarse", contact=ContactLaw("coulomb", mu))
    sealed = route.seal(model, {**route.options, "cup": cup})
    run = lambda walk: equilibrium_branch(sealed.cup, sealed.state, F1, du_m=DEFAULT_DU_M,  # noqa: E731
                                          u_min_m=u_min_m, walk=walk)
    return sealed.cup, run(None), run(FromState)


def _same_states(cup, b, ref) -> None:
    assert b.reason == ref.reason == "u_min"
    assert len(b.states) == len(ref.states) >= 5
    tolerance = Walk(cup, F1).tolerance            # |F1 - F1_N| a root accepts [N]
    for s, r in zip(b.states, ref.states):
        assert abs(s.F1_N - F1) <= tolerance and abs(r.F1_N - F1) <= tolerance
        assert s.N == pytest.approx(r.N, rel=1e-6)
        assert s.u_m == pytest.approx(r.u_m, rel=1e-6)
        assert s.seal_r_m == pytest.approx(r.seal_r_m, rel=1e-6)


def test_corrections_started_from_the_first_trial_find_the_same_states_in_fewer_iterations(model):
    """mu = 0.5 from the sealed state to u = 4.4 mm (7 states): every state but the first is the
    tangent's trial and one correction; the correction from the branch state takes 4 Newton
    iterations, started from the first trial 0-1."""
    cup, b, ref = _both(model, 0.5, 4.4e-3)
    _same_states(cup, b, ref)
    n, n_ref = b.stats.newton_iterations, ref.stats.newton_iterations
    print(f"mu 0.5: {len(b.states)} states, {n} Newton iterations, from the state {n_ref}")
    assert n_ref >= 75 and n <= 0.75 * n_ref


def test_where_the_step_has_two_solutions_the_started_trials_keep_the_branch_states(model):
    """mu = 2 to u = 3.9 mm: at u = 3.9 mm the step from the branch state has two solutions for
    the same N (inner seal nodes held or let go; the pull jumps between them along the
    reference's trials), and a correction started from a trial that let them go would follow
    the other one; it is given up (its set changed, or more than PREDICTED_ITERATIONS), and the
    states are the reference's."""
    cup, b, ref = _both(model, 2.0, 3.9e-3)
    _same_states(cup, b, ref)
    n, n_ref = b.stats.newton_iterations, ref.stats.newton_iterations
    print(f"mu 2: {len(b.states)} states, {n} Newton iterations, from the state {n_ref}")
    assert n < n_ref


def test_a_started_root_that_contradicts_a_monotone_pull_is_found_again_from_the_state(model):
    """mu = 2, the state midway between the branch states at u = 0.77 and 0.53 mm
    (`fem.gas_branch.state_between`, as the route refines its leak there): at the plate midway
    the reference's trials in N find the pull jumping across F1 (its inner seal nodes held: above
    F1; let go: below), so N is not found there and the state is taken at N midway. Corrections
    started from the trial that let the nodes go follow that set to a root at less N, where a
    trial from the state pulls more than F1: F1(N) would rise with N between them. That
    contradiction sends the root back to the state, and the midway state is the reference's."""
    from fem.gas_branch import state_between

    route = register()
    cup = FemCup("A", "coarse", contact=ContactLaw("coulomb", 2.0))
    sealed = route.seal(model, {**route.options, "cup": cup})
    b = equilibrium_branch(sealed.cup, sealed.state, F1, du_m=DEFAULT_DU_M)
    u = b.column("u_m")
    k = int(np.argmin(np.abs(u - 0.769e-3)))
    assert abs(u[k] - 0.769e-3) < 0.01e-3 and abs(u[k + 1] - 0.525e-3) < 0.01e-3
    mid = state_between(sealed.cup, b.states[k], b.states[k + 1], F1)
    ref = state_between(sealed.cup, b.states[k], b.states[k + 1], F1, walk=FromState)
    print(f"midway: u = {mid.u_m * 1e3:.6g} mm, N = {mid.N:.8g}; "
          f"from the state {ref.u_m * 1e3:.6g} mm, {ref.N:.8g}")
    assert mid.N == pytest.approx(0.5 * (b.states[k].N + b.states[k + 1].N), rel=1e-12)   # N midway
    assert mid.u_m == pytest.approx(ref.u_m, rel=1e-6) and mid.N == pytest.approx(ref.N, rel=1e-9)
