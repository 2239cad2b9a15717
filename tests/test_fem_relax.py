"""`fem.newton.relax_step`: the damped motion across an instability, its end and its giving up,
on a scripted sub-step (no FEM: which damped sub-steps converge and how far they move is the
test's, so the rule alone is checked against what it must do)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

import fem.newton as newton
from fem.failure import NoContactSet, StepFailure
from fem.solver import SolverOptions

N_DOFS, BOUND = 4, 1e-4         # dofs, the largest node move of a sub-step [m]


def _problem():
    kin = SimpleNamespace(node_coordinates=lambda: np.array([[0.0, 1.0], [0.0, 1.0]]))
    mech = SimpleNamespace(kin=kin, material=SimpleNamespace(mu=1.0),
                           evaluate=lambda u: (0.0, np.zeros(N_DOFS), sp.identity(N_DOFS, format="csr")))
    law = SimpleNamespace(commit=lambda p, s, u: s, friction_force=lambda p, s, r: None,
                          cone_excess=lambda p, s, r: 0.0)
    plane = SimpleNamespace(nodes=np.array([0]), law=law, reactions=lambda r: r[[1]],
                            constraints=lambda s: (np.zeros(0, int), np.zeros(0)))
    state = SimpleNamespace(active=np.array([False]))
    return mech, (lambda t: (np.array([3]), np.array([0.0]))), plane, state


def _relax(monkeypatch, sub_step, **options):
    """relax_step with `sub_step(c or None, u) -> (u1, iterations[, residual])` in place of the
    Newton solve (c: the damping factor of the sub-step, None: undamped; residual: the body's
    own out-of-balance force at u1, the viscous force left out, default 1 N on every dof: not at
    rest); raise StepFailure to fail."""
    calls = []

    def newton_step(body, dirichlet, f_ext, plane, s, u, t, opts, solver, policy, stall):
        c = float(body.weight[0]) if isinstance(body, newton._Damped) else None
        calls.append(c)
        u1, n, *res = sub_step(c, u)
        r = res[0] if res else np.ones(N_DOFS)
        return u1, r + (body.weight * (u1 - u) if c is not None else 0.0), s, n, False
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
    # a path without its own move bound (pressing) goes on at the least damping that converges
    # (one iteration a sub-step), not raising it by 40-iteration failures, until it gives up
    with pytest.raises(StepFailure, match="did not settle") as err:
        _relax(monkeypatch, sub_step)
    assert err.value.iterations < 2 * newton._RELAX_ATTEMPTS


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


def test_a_motion_at_rest_where_the_undamped_step_has_no_solution_ends_there(monkeypatch):
    """At large mu the motion may come to rest with a node on the edge of the friction cone,
    where the undamped step has no stick/slide set (Klarbring). A damped sub-step whose state
    is the undamped equilibrium within the tolerance (its out-of-balance force, the viscous
    force left out, at most rtol of the reactions) ends the motion there."""
    moves = iter(0.2 * BOUND * 0.5 ** k for k in range(400))

    def sub_step(c, u):
        if c is None:
            raise NoContactSet("no stick/slide set", [1.0] * 4)
        du = next(moves)
        u1 = u + np.array([du, du, du, 0.0])
        return u1, 2, np.array([1e4 * du, 1e4 * du, 1e4 * du, 1.0])   # 1 N: the plate's reaction
    (u, r, _, _), calls = _relax(monkeypatch, sub_step)
    assert calls[-1] is not None                      # a damped sub-step ended it
    assert np.linalg.norm(r[:3]) <= 1e-6 * 1.0 < np.linalg.norm(r[:3]) * 1e4 ** 2
    assert u[0] > 0.39 * BOUND


def test_a_sub_step_without_a_stick_slide_set_raises_the_slip_damping(monkeypatch):
    """A sub-step whose linearized frictional problem has no stick/slide set raises the damping
    of the held nodes' slip, not of the body: the body's damping keeps falling."""
    mech, dirichlet, plane, state = _problem()
    plane.law.mu = 10.0
    state = SimpleNamespace(active=np.array([True]))
    weights = []

    def newton_step(body, dirichlet, f_ext, plane, s, u, t, opts, solver, policy, stall):
        if not isinstance(body, newton._Damped):
            raise NoContactSet("no stick/slide set", [1.0] * 4)
        weights.append(body.weight.copy())
        if body.weight[0] - body.weight[1] < 10.0 * 4.0:    # the slip's damping: mu c_s metric
            raise NoContactSet("no stick/slide set", [1.0] * 4)
        du = 1e-3 * BOUND * 0.5 ** len(weights)
        u1 = u + np.array([0.0, 0.0, du, 0.0])
        return u1, body.weight * (u1 - u) + np.array([0.0, 1e4 * du, 0.0, 1.0]), s, 1, False
    monkeypatch.setattr(newton, "newton_step", newton_step)
    newton.relax_step(mech, dirichlet, lambda t: np.zeros(N_DOFS), plane, state, np.zeros(N_DOFS),
                      1.0, SolverOptions(max_step=1.0), None, None, BOUND)
    body = np.array([w[1] for w in weights])          # c metric on a dof off the plane
    assert weights[1][0] - weights[1][1] == 10.0 * 4.0 and weights[1][1] == 1.0
    assert body[-1] < 1e-3 and np.all(np.diff(body) <= 0.0)


def test_a_motion_that_cycles_on_the_branch_gives_up_within_its_budget(monkeypatch):
    """Sub-steps that move and fail in turn (a contact set cycling) never stall; on a path with
    its own move bound the motion gives up once it has spent _BUDGET times the path's iteration
    cap, and says so; the pressing path goes on to its attempts."""
    state = {"n": 0}

    def sub_step(c, u):
        state["n"] += 1
        if state["n"] % 2 == 0:
            _fail()
        return u + 0.1 * BOUND * np.array([1.0, 1.0, 1.0, 0.0]) * (-1) ** (state["n"] // 2), 3
    with pytest.raises(StepFailure, match="did not settle within") as err:
        _relax(monkeypatch, sub_step, relax_move_m=BOUND)
    cap = SolverOptions().max_iterations
    assert newton._BUDGET * cap < err.value.iterations <= newton._BUDGET * cap + 40 + 3   # + a cycle
    state["n"] = 0
    with pytest.raises(StepFailure, match="did not settle \\(") as err:
        _relax(monkeypatch, sub_step)
    assert err.value.iterations > 2 * newton._BUDGET * cap
