"""The Newton iteration of one load step, and its convergence test.

The step to t solves the equilibrium at t as the minimum of the total energy Pi(u) = W(u) -
f_ext . u over the admissible set (the prescribed values, g >= 0, and the anchors of the nodes
held on the plane). The predictor is the converged state of the last step; the first iteration
imposes the prescribed increment through the tangent (a tangent predictor, which sees the
contact; a secant extrapolation pushed the contact front through the plane). Each iteration
takes the contact law's step (`fem.laws`: `fem.contact_step`, or Coulomb's `fem.friction`) on the shifted
factorization (`fem.factorization`) and the line search (`fem.linesearch`).

Converged: the prescribed values hold, no held node pulls on the plane beyond the tolerance,
||r_f|| <= rtol * max(||reactions||, f_floor) (or at the round-off floor, `balanced`), the energy
norm of the next correction |du . r| <= etol * f_ref * max|u| (the work scale), and Coulomb's
condensed problem keeps its sets. Anything else raises `fem.failure.StepFailure` with its cause,
and so does a Coulomb step whose residual creeps (`creeping`: such steps failed later all the same).

`relax_step` is the load step of an incremental friction law across an instability (or where its
quasi-static step has no solution): a sequence of damped sub-steps, the friction's anchors moved
after each, which ends on the undamped equilibrium.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .contact_step import ContactStep
from .failure import NoContactSet, StepFailure
from .linesearch import line_search, total_potential

__all__ = ["newton_step", "relax_step", "balanced", "creeping", "largest_move", "largest_slip", "SLIP",
           "out_of_balance", "slip_metric"]

_STALLED = 12           # Newton iterations in a row whose linearized frictional problem found no set
_CREEP = 20             # Newton iterations of a coupled (Coulomb) step in which the residual must halve


def newton_step(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy,
                stall: int = _STALLED, guess: np.ndarray | None = None):
    """Newton iterations of one step with a contact step per iteration (module docstring), to the
    tolerances of `opts` (a `fem.solver.SolverOptions`); returns (u, r_int, contact state,
    iterations, whether the tangent was indefinite on the way). guess: the first iterate (a
    predictor, projected onto the admissible set) instead of u_start, which stays the step's
    start for the contact history (where a node landing in the step touched down)."""
    flags = {"indefinite": False}
    try:
        return _iterate(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy, flags,
                        stall, guess)
    except StepFailure as fail:
        fail.indefinite = flags["indefinite"]
        raise


def _iterate(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy, flags, stall,
             guess=None):
    n = mech.kin.ndofs
    fixed_dofs, fixed_vals = dirichlet(t)
    fext0 = fext = f_ext(t)
    history: list[float] = []
    try:
        u = u_start if guess is None else guess
        u = plane.project(u, u_start, state, state.active) if plane is not None else u
        Pi, r, K = total_potential(mech, u, fext)
    except FloatingPointError as err:
        raise StepFailure(f"{err} at the predictor; likely cause: the step is too large for "
                          "the deformation, or the mesh is too coarse", history) from None
    it, shift, indefinite, stalled = 0, 0.0, False, 0
    released = np.zeros(len(plane.nodes), bool) if plane is not None else None
    while True:
        res = r - fext0
        free, dofs, du_fixed = _free_dofs(n, fixed_dofs, fixed_vals, u, plane, state)
        f_ref = max(np.linalg.norm(res[dofs]), np.linalg.norm(fext0), _force_floor(mech))
        fric = plane.law.friction_force(plane, state, res) if plane is not None else None
        if fric is not None:                          # the friction of the iterate is a load
            Pi += (fext - fext0 - fric) @ u           # the same W, the new load
            fext = fext0 + fric
            res = r - fext
            free, dofs, du_fixed = _free_dofs(n, fixed_dofs, fixed_vals, u, plane, state)
        rnorm = np.linalg.norm(res[free])
        history.append(rnorm / f_ref)
        if not np.all(np.isfinite(res)):
            raise StepFailure("the residual is not finite", history)
        if plane is not None:
            step = plane.law.step(plane, state, u, res, free, du_fixed, opts.rtol * f_ref, fext - fext0)
        else:
            step = ContactStep(None, state, u, res, free, du_fixed, opts.rtol * f_ref)
        shift = step.solve(solver, K, shift, history, policy)
        indefinite |= shift > 0.0
        stalled = 0 if getattr(step, "solvable", True) else stalled + 1
        if stalled >= stall:
            raise NoContactSet(f"Coulomb's linearized contact problem found no stick/slide set in {stalled} "
                               "iterations in a row; likely cause: a friction bound falling with the slip "
                               "faster than the elastic drive grows (no quasi-static solution)", history)
        flags["indefinite"] = indefinite
        energy = abs(step.du @ res)
        e_ref = f_ref * max(np.max(np.abs(u)), np.max(np.abs(step.du)), 1e-9 * _size(mech))
        held = not np.any(du_fixed)
        tensile = plane is not None and np.any(plane.reactions(res)[state.active] < -opts.rtol * f_ref)
        if held and not tensile and balanced(rnorm, opts.rtol * f_ref, step.du, u) \
                and energy <= opts.etol * e_ref and getattr(step, "settled", True):
            excess = plane.law.cone_excess(plane, state, res) if plane is not None else 0.0
            if excess > 1e3 * opts.rtol:
                raise StepFailure("Coulomb's stick/slide set cycled and the node held stuck lies "
                                  f"outside the friction cone ({excess:.2g} "
                                  "of the largest normal reaction); likely cause: a too-large step, "
                                  "or a friction bound falling steeply with the slip", history)
            return u, r, state, it, indefinite
        it += 1
        if getattr(step, "coupled", False) and opts.max_iterations > 2 * _CREEP and creeping(history):
            raise StepFailure(f"the residual of Coulomb's Newton iteration stopped falling (not halved in "
                              f"{_CREEP} iterations); likely cause: a contact set the line search does not "
                              "reach (nodes the step presses, short steps that never press them)", history)
        if it >= opts.max_iterations:
            raise StepFailure(f"no convergence in {opts.max_iterations} Newton iterations; likely cause: a "
                              "structural instability (snap-through/buckling) that the step jumps "
                              "across, or a too-large step", history)
        u_prev = u
        alpha, u, Pi, r, K, shift = line_search(mech, solver, policy, step, u_start, u, Pi, res,
                                                K, fext, shift, held, history)
        if plane is not None:
            released |= step.release
            u_free = u_prev + max(alpha, 1.0) * step.du0
            state = plane.hold(step.state, step.holds(alpha), u, u_start, u_free, released)


def creeping(history: list[float], window: int = _CREEP) -> bool:
    """Whether a Newton iteration goes nowhere: the residuals of its last `window` iterations all
    stay above half the least one before them (the first, taken before the prescribed increment is
    imposed, not counted). Under Coulomb's law the line search may accept ever shorter steps
    towards a contact set they never reach; such a step would fail only when the line search
    reaches round-off, hundreds of iterations later, while a converging step halves its residual
    well within the window (benchmarks/fem_route_mesh_study.md, cost). Applied only where the
    iteration cap is well beyond the window: `relax_step`'s short sub-steps keep their own
    schedule of failures and damping."""
    if len(history) <= window + 1:
        return False
    return min(history[-window:]) > 0.5 * min(history[1:-window])


def balanced(rnorm: float, tol: float, du: np.ndarray, u: np.ndarray) -> bool:
    """The residual test: ||r_f|| <= tol, or, at the round-off floor, ||r_f|| <= 100 tol with a
    Newton correction below 1e-12 of the displacement: the state is then converged to 12 digits
    in displacement, and the residual left is the assembly's round-off, which no iteration
    reduces (in thin walls the element forces that cancel at a node are ~1e8 times the plate
    reaction the tolerance is relative to)."""
    if rnorm <= tol:
        return True
    return rnorm <= 100.0 * tol and np.max(np.abs(du)) <= 1e-12 * np.max(np.abs(u))


def _free_dofs(n, fixed_dofs, fixed_vals, u, plane, state):
    """(free mask, constrained dofs, du on the constrained dofs): the prescribed and the held
    contact dofs move to their values (a node held anew jumps to where it stuck)."""
    dofs, vals = fixed_dofs, fixed_vals
    if plane is not None:
        cd, cv = plane.constraints(state)
        dofs, vals = np.concatenate([fixed_dofs, cd]), np.concatenate([fixed_vals, cv])
    du_fixed = np.zeros(n)
    du_fixed[dofs] = vals - u[dofs]
    free = np.ones(n, bool)
    free[dofs] = False
    return free, dofs, du_fixed


def _size(mech) -> float:
    return float(np.max(np.ptp(mech.kin.node_coordinates(), axis=1)))


def _force_floor(mech) -> float:
    """A force scale below which residuals are round-off: 1e-6 mu L^2 with L the body's size."""
    return 1e-6 * mech.material.mu * _size(mech) ** 2


def out_of_balance(mech, dirichlet, f_ext, plane, state, u, r_int, t, rtol: float) -> float:
    """The undamped out-of-balance force of a damped sub-step's state: its free residual, the
    friction of `state` included and the viscous force left out, over rtol of the reactions (as
    `newton_step` measures them); inf where the prescribed values do not hold, a held node pulls
    on the plane or a stuck one lies outside the cone. At most 1: the state is the undamped
    equilibrium (at rest). Where the motion comes to rest on the edge of the friction cone (a
    node that would slide at zero rate) the undamped Newton step from there may have no
    solution at large mu (sticking lies a round-off outside the cone, sliding runs backwards:
    Klarbring's non-existence), while the state the damped motion tends to is an equilibrium."""
    fixed_dofs, fixed_vals = dirichlet(t)
    if np.any(fixed_vals != u[fixed_dofs]):
        return np.inf
    fext = f_ext(t)
    res = r_int - fext
    free, dofs, _ = _free_dofs(len(u), fixed_dofs, fixed_vals, u, plane, state)
    f_ref = max(np.linalg.norm(res[dofs]), np.linalg.norm(fext), _force_floor(mech))
    if np.any(plane.reactions(res)[state.active] < -rtol * f_ref) or \
            plane.law.cone_excess(plane, state, res) > 1e3 * rtol:
        return np.inf
    fric = plane.law.friction_force(plane, state, res)
    if fric is not None:
        res = res - fric
    return float(np.linalg.norm(res[free]) / (rtol * f_ref))


def largest_move(u1: np.ndarray, u0: np.ndarray) -> float:
    """The largest displacement of a node between two states [m]."""
    return float(np.max(np.hypot(*(u1 - u0).reshape(-1, 2).T)))


def largest_slip(plane, state, u1: np.ndarray, u0: np.ndarray) -> float:
    """The largest radial move between two states of a node that `state` holds on the plane [m]."""
    rd = 2 * plane.nodes[state.active]
    return float(np.max(np.abs(u1[rd] - u0[rd]), initial=0.0))


class _Damped:
    """The body with a viscous term of one pseudo-time step: Pi(u) + (u - u_k) . C (u - u_k) / 2,
    C = diag(weight). Its minimizer is backward Euler's step of the damped motion C du/ds =
    -grad Pi from u_k; the tangent gains C on its diagonal (the pattern is K's). A tangent with a
    rank-one term (the trapped gas's `fem.trapped_gas.GasTangent`) keeps it: C is added to its
    sparse part."""

    def __init__(self, mech, u_k: np.ndarray, weight: np.ndarray):
        self.mech, self.kin, self.material, self.u_k, self.weight = mech, mech.kin, mech.material, u_k, weight

    def evaluate(self, u):
        W, r, K = self.mech.evaluate(u)
        d = u - self.u_k
        rank_one = getattr(K, "rank_one", None)
        D = K.copy() if rank_one is None else K.plain().copy()
        D.setdiag(D.diagonal() + self.weight)
        if rank_one is not None:
            D = type(K).of(D, D.data, *rank_one)
        return W + 0.5 * d @ (self.weight * d), r + self.weight * d, D

    def energy(self, u):
        d = u - self.u_k
        return self.mech.energy(u) + 0.5 * d @ (self.weight * d)


_SUB_ITERATIONS, _SUB_STALL = 40, 4    # a sub-step is short: it fails early (and c rises) instead
_RELAX_ATTEMPTS = 400               # damped sub-steps (accepted or redone) of one relaxed load step
#                                     at the default largest step (0.05 of the range); more below
_C_START, _C_SETTLED, _C_MAX = 1.0, 1e-3, 1e8
SLIP = 0.25                         # the largest slip of a held node in a (sub-)step / the bound
_SETTLED = 1e-3                     # a damped sub-step moving less than this of the bound: try undamped
_STALLS = 3                         # failed sub-steps after one that moved < _SETTLED bound: stalled
_BUDGET = 10                        # on a path with its own move bound: Newton iterations of the
#                                     motion / the path's cap (a contact set cycling, landing and
#                                     releasing the same nodes, spent minutes on one move)


def slip_metric(plane, state, metric: np.ndarray) -> np.ndarray:
    """The damping metric of the held nodes' slip: mu times a node's normal stiffness (`metric`,
    the tangent's diagonal) on its radial dof, zero elsewhere. Klarbring's condition compares
    the tangential stiffness a sliding node meets with mu times its normal-tangential coupling:
    a viscous slip of this scale restores a solution of the incremental problem without
    damping the rest of the body (whose soft modes a body-wide damping slows to a creep)."""
    w = np.zeros_like(metric)
    held = 2 * plane.nodes[state.active]
    w[held] = getattr(plane.law, "mu", 0.0) * metric[held + 1]
    return w


def relax_step(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy, bound):
    """The load step to t as the damped motion that leaves an unstable state, with the friction
    integrated along it: for an incremental (Coulomb) law, where the quasi-static step has no
    solution or snaps, its end state depends on how the slip is divided into increments.

    Each sub-step minimizes the energy plus the viscous term of `_Damped`, C = c_b diag(K(u_start))
    + c_s `slip_metric` (the body's damping and the held nodes' slip's; the metrics fixed for the
    step), from the last sub-step's state, whose positions are the friction's anchors (committed
    after every sub-step): backward Euler on the damped motion, whose incremental frictional
    problems have a solution for c_s large enough (the damping adds to the stiffness that
    Klarbring's condition compares mu with). A sub-step whose frictional problem has no
    stick/slide set raises c_s fourfold; one that fails otherwise, moves a node more than `bound`
    [m] beyond the prescribed increment or slips a held node by more than SLIP bound raises c_b.
    Both fall fourfold after a sub-step that moves less than bound / 4, not below a factor that
    failed right after such a fall (the least damping known to converge, forgotten once a
    sub-step moves _SETTLED bound): near the critical damping a fall and a failure alternated, 40
    Newton iterations a failure. The motion ends at a damped sub-step whose state is the
    undamped equilibrium within the tolerance (`out_of_balance`: where it rests on the cone's
    edge at large mu the undamped step has no solution), or, once a sub-step with c <=
    _C_SETTLED moves less than _SETTLED bound, on the undamped step from its state, if it moves
    no node more than bound. Where the motion stalls (_STALLS times a sub-step that moved less
    than _SETTLED bound and then a failure, or a converged one at the least damping that neither
    moves nor halves its out-of-balance force) on a path with its own move bound
    (`SolverOptions.relax_move_m`: the held branch's moves, which have their own way on), the
    step fails at once and the caller shortens its move; a path whose load is its length
    (pressing) goes on. As bound -> 0 the sequence tends to the damped motion, independent of
    the load step. Returns (u, r_int, contact state, Newton iterations); raises StepFailure
    (with the `iterations` spent)."""
    metric = np.abs(mech.evaluate(u_start)[2].diagonal())
    sub_opts = replace(opts, max_iterations=min(opts.max_iterations, _SUB_ITERATIONS))
    dofs, values = dirichlet(t)
    u, s, its, history = u_start, state, 0, []
    settled, settle = False, _SETTLED * bound
    still, stalls, stalled, spent = False, 0, False, False   # the last sub-step moved nothing; failures since
    c = np.array([_C_START, _C_START])      # the damping of the body and of the held nodes' slip
    floor, lowered = np.zeros(2), np.zeros(2, bool)     # the least known to converge; just lowered
    last = np.inf                   # the out-of-balance force of the last sub-step (`out_of_balance`)
    for _ in range(int(_RELAX_ATTEMPTS * max(1.0, 0.05 / opts.max_step))):   # sub-steps ~ 1 / bound
        body = mech if settled else _Damped(mech, u, c[0] * metric + c[1] * slip_metric(plane, s, metric))
        allowed = bound + np.max(np.abs(values - u[dofs]), initial=0.0)
        try:
            u1, r1, s1, n, _ = newton_step(body, dirichlet, f_ext, plane, s, u, t, sub_opts, solver,
                                           policy, _SUB_STALL)
            its += n
            if largest_move(u1, u) > allowed or largest_slip(plane, s1, u1, u) > SLIP * bound:
                raise StepFailure("a node moved or slipped too far", [])
        except StepFailure as fail:
            its, history = its + len(fail.history), fail.history or history
            if settled:         # the undamped step fails: damped again, and settle closer first
                settled, settle = False, 0.1 * settle
                continue
            stalls += still
            spent = bool(opts.relax_move_m) and its > _BUDGET * opts.max_iterations
            stalled = bool(opts.relax_move_m) and stalls >= _STALLS
            if c.max() >= _C_MAX or stalled or spent:
                break
            # no stick/slide set (Klarbring): the slip needs damping; else the body does
            which = np.array([False, True]) if isinstance(fail, NoContactSet) else np.array([True, False])
            floor = np.where(lowered & which, 4.0 * c, floor)   # the least damping known to converge
            c, lowered = np.where(which, 4.0 * c, c), np.zeros(2, bool)
            continue
        if body is mech:
            return u1, r1, s1, its
        r_rest = r1 - body.weight * (u1 - u)        # the body's own internal force at u1
        imbalance = out_of_balance(mech, dirichlet, f_ext, plane, s1, u1, r_rest, t, opts.rtol)
        if imbalance <= 1.0:
            return u1, r_rest, s1, its
        move = largest_move(u1, u)
        still = move < _SETTLED * bound
        stalls, floor = (stalls, floor) if still else (0, np.zeros(2))    # moving: the state is new
        if still and np.any(0.25 * c < floor) and not imbalance < 0.5 * last:
            stalls += 1             # at the least damping that converges, neither moving nor settling
            stalled = bool(opts.relax_move_m) and stalls >= _STALLS
            if stalled:
                break
        last = imbalance
        s, u = plane.law.commit(plane, s1, u1), u1
        settled = move < settle and c.max() <= _C_SETTLED
        lowered = (move < 0.25 * bound) & (0.25 * c >= floor)
        c = np.where(lowered, 0.25 * c, c)
    why = "stalled (the sub-steps that converge no longer move)" if stalled else \
        f"did not settle within {_BUDGET} times the path's iteration cap" if spent else "did not settle"
    fail = StepFailure(f"the damped motion across the instability {why} ({its} Newton "
                       "iterations); likely cause: a friction bound falling with the slip faster "
                       "than the damping can hold", history, indefinite=True)
    fail.iterations = its
    raise fail
