"""`fem.newton.relax_step`: the damped motion across an instability, its end and its giving up,
on a scripted sub-step (no FEM: which damped sub-steps converge and how far they move is the
test's, so the rule alone is checked against what it must do)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

import fem.newton as newton
from fem.failure import StepFailure
from fem.solver import SolverOptions

N_DOFS, BOUND = 4, 1e-4         # dofs, the largest node move of a sub-step [m]


def _problem():
    mech = SimpleNamespace(kin=None, material=None,
                           evaluate=lambda u: (0.0, np.zeros(N_DOFS), sp.identity(N_DOFS, format="csr")))
    plane = SimpleNamespace(nodes=np.array([0]), law=SimpleNamespace(commit=lambda p, s, u: s))
    state = SimpleNamespace(active=np.array([False]))
    return mech, (lambda t: (np.array([3]), np.array([0.0]))), plane, state


def _relax(monkeypatch, sub_step, **options):
    """relax_step with `sub_step(c or None, u) -> (u1, iterations)` in place of the Newton solve
    (c: the damping factor of the sub-step, None: undamped); raise StepFailure to fail."""
    calls = []

    def newton_step(body, dirichlet, f_ext, plane, s, u, t, opts, solver, policy, stall):
        c = float(body.weight[0]) if isinstance(body, newton._Damped) else None
        calls.append(c)
        u1, n = sub_step(c, u)
        return u1, np.zeros(N_DOFS), s, n, False
    monkeypatch.setattr(newton, "newton_step", newton_step)
    mech, dirichlet, plane, state = _problem()
    out = newton.relax_step(mech, dirichlet, lambda t: np.zeros(N_DOFS), plane, state, np.zeros(N_DOFS),
                            1.0, SolverOptions(max_step=1.0, **options), None, None, BOUND)
    return out, calls


def _fail(n: int = 40):
    raise StepFailure("no convergence", [1.0] * n)


def test_a_motion_that_comes_to_rest_ends_on_the_undamped_step(monkeypatch):
    """Each damped sub-step moves half as far as the last; once c is small and the move below
    1e-3 of the bound, the undamped step ends the motion (its state returned)."""
    moves = iter(0.2 * BOUND * 0.5 ** k for k in range(200))

    def sub_step(c, u):
        if c is None:
            return u + 1e-12, 1
        return u + next(moves), 3
    (u, _, _, its), calls = _relax(monkeypatch, sub_step)
    assert calls[-1] is None and calls[-2] <= 1e-3
    assert u[0] > 0.2 * BOUND


def test_a_stalled_motion_gives_up_early(monkeypatch):
    """Damped sub-steps converge only where c is so large that they do not move, and every less
    damped one fails: the motion has stalled. On a path with its own move bound (the held
    branch's) it gives up after _STALLS such failures, not after c has ratcheted up to _C_MAX at
    40 iterations per failure (thousands of iterations)."""
    def sub_step(c, u):
        if c is not None and c >= 16.0:
            return u.copy(), 1          # converges, moves nothing
        _fail()
    with pytest.raises(StepFailure, match="stalled") as err:
        _relax(monkeypatch, sub_step, relax_move_m=BOUND)
    assert err.value.iterations <= (2 + newton._STALLS) * 40 + newton._STALLS
    # a path without its own move bound (pressing) keeps raising the damping (it has no other way)
    with pytest.raises(StepFailure, match="did not settle") as err:
        _relax(monkeypatch, sub_step)
    assert err.value.iterations > 10 * (2 + newton._STALLS) * 40


def test_failures_while_the_motion_moves_do_not_stall_it(monkeypatch):
    """A sub-step that fails between sub-steps that do move (the damping too weak for a moment)
    is not a stall: c rises, the motion goes on to rest and ends on the undamped step."""
    moves = iter(0.2 * BOUND * 0.7 ** k for k in range(400))
    state = {"n": 0}

    def sub_step(c, u):
        state["n"] += 1
        if c is None:
            return u + 1e-12, 1
        if state["n"] % 3 == 0 and state["n"] < 30:
            _fail()
        return u + next(moves), 3
    (u, _, _, its), calls = _relax(monkeypatch, sub_step)
    assert calls[-1] is None
