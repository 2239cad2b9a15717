"""Quasi-static path following: adaptive load steps across instabilities, with an energy balance.

The body is loaded by a parameter t (the plate displacement for the cup, a load factor elsewhere)
that enters through prescribed displacements ``dirichlet(t) -> (dofs, values)``, optionally an
external force ``f_ext(t)`` or a family of potentials (``mech.at(t)``); contact with a
`fem.contact.RigidPlane` adds unilateral constraints. `follow_path` walks t from 0 to t_max:
each load step is one Newton solve (`fem.newton`); a step that fails is halved, down to
``min_step``, where `ConvergenceError` says where and why. Nothing is accepted silently.

Instabilities: a step whose tangent lost definiteness (buckling, snap-through) that fails is
first enlarged (2x, 4x the last good step) to jump across the limit point, then halved. The
energy lost in a step, W0 + work - W1, is summed as `SolverStats.dissipated_J`; on a
conservative path (no contact or frictionless contact) an unstable step that loses more than
jump_tol of W is redone with half the step down to jump_min_step: a large step's descent may land
on another branch than the load path reaches, while a real snap keeps its loss as the step
shrinks and is accepted, localized to one small step. An incremental friction law (Coulomb)
does not jump: a step that fails or crosses an instability is halved down to a quarter of the
largest step; there, if it still fails or a held node slips more than that, it is redone as
damped motion at its load (`fem.newton.relax_step`),
so that the slip is integrated in increments no longer than the largest step and the path
converges as the step shrinks. docs/fem.md ("Solver notes") records what was measured for these
choices.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .condensation import make_solver
from .contact import ContactState, RigidPlane
from .factorization import ShiftPolicy
from .failure import StepFailure
from .forms import Mechanics
from .linesearch import conservative
from .newton import SLIP, largest_slip, newton_step, relax_step

__all__ = ["SolverOptions", "SolverStats", "ConvergenceError", "follow_path", "StepResult"]


class ConvergenceError(RuntimeError):
    """A load step could not be converged even with the smallest allowed step.

    The message is one line; the attributes say where (the step, its load range t_from -> t_to:
    t_from is the last converged load) and why (`cause`, with the likely cause), and keep the
    residual `history` of the last attempt, the cost of the path up to there (`stats`), and what
    a caller made of the converged part (`partial`, e.g. `fem.cup.CupResponse`; None if nothing).
    """

    def __init__(self, message: str, *, step: int = 0, t_from: float = math.nan,
                 t_to: float = math.nan, cause: str = "", history: tuple[float, ...] = (),
                 stats: "SolverStats | None" = None):
        super().__init__(message)
        self.step, self.t_from, self.t_to = step, t_from, t_to
        self.cause, self.history = cause, tuple(history)
        self.stats: SolverStats | None = stats
        self.partial: Any = None


@dataclass(frozen=True)
class SolverOptions:
    """Tolerances and step control (dimensionless unless suffixed)."""

    rtol: float = 1e-6          # residual / reaction
    etol: float = 1e-12         # energy norm of the correction / work scale f_ref max|u|
    max_iterations: int = 400   # a step that descends through a snap or a sticking slip: hundreds
    initial_step: float = 0.01  # first step as a fraction of t_max
    max_step: float = 0.05      # largest step as a fraction of t_max (resolution of the curve)
    min_step: float = 1e-5      # smallest step as a fraction of t_max before giving up
    growth: float = 1.5         # step growth after an easy step (<= easy_iterations)
    easy_iterations: int = 6
    jump_tol: float = 0.005     # energy defect of an unstable step / stored energy that halves it
    jump_min_step: float = 0.002  # ... down to this step (fraction of t_max): a real snap stays
    relax_move_m: float = 0.0   # the largest node move of a relaxed sub-step [m] (`fem.newton.relax_step`;
    #                             0: max_step t_max, for a path whose t is a length)

    def __post_init__(self) -> None:
        for name in ("rtol", "etol", "initial_step", "max_step", "min_step", "jump_tol",
                     "jump_min_step"):
            v = getattr(self, name)
            if not (0.0 < v <= 1.0):
                raise ValueError(f"{name}: must be in (0, 1], got {v}")
        if self.max_iterations < 2:
            raise ValueError(f"max_iterations: must be >= 2, got {self.max_iterations}")


@dataclass(frozen=True)
class SolverStats:
    """Cost of one path: accepted steps, Newton iterations, cut-backs, wall time, dofs."""

    steps: int
    newton_iterations: int
    cutbacks: int
    wall_time_s: float
    dofs: int
    unstable_steps: int = 0     # steps whose tangent was not positive definite on the way (buckling)
    dissipated_J: float = 0.0   # sum over steps of W0 + work - W1: jumps across instabilities
    #                             (snap-through), sticking-law slips, and the O(dt^3) trapezoid error
    factorizations: int = 0     # Cholesky factorizations of K_ff attempted, and those of them that
    failed_factorizations: int = 0   # failed (not positive definite: the shift search,
    #                                `fem.factorization`)


@dataclass(frozen=True, eq=False)
class StepResult:
    """A converged state: load parameter, displacement, internal force, stored energy W(u) [J]
    (the path evaluates it for its energy balance), contact state."""

    t: float
    u: np.ndarray
    r_int: np.ndarray
    energy_J: float
    contact: ContactState | None
    iterations: int
    unstable: bool = False    # the tangent lost definiteness in this step (buckling, snap-through)


def follow_path(mech: Mechanics, dirichlet: Callable[[float], tuple[np.ndarray, np.ndarray]],
                t_max: float, *, plane: RigidPlane | None = None,
                f_ext: Callable[[float], np.ndarray] | None = None,
                options: SolverOptions = SolverOptions(),
                on_step: Callable[[StepResult], None] | None = None,
                progress: Callable[[float, str], None] | None = None,
                name: str = "t", start: StepResult | None = None,
                predict: Callable[[float, np.ndarray, float], np.ndarray] | None = None) -> SolverStats:
    """Follow the equilibrium path from t = 0 to t_max; call `on_step` for every converged step
    (including t = 0). `name` names t in messages (e.g. "u [m]"). Raises `ConvergenceError` if
    a step cannot be converged.

    start: the converged state at t = 0 (default: u = 0, no contact), e.g. the end of another
    path. A `mech` with a method ``at(t)`` is a family of potentials Pi_t (a load that is not a
    prescribed displacement or a fixed force, such as a ramped cavity pressure, `fem.cavity`):
    the step to t1 minimizes ``mech.at(t1)``'s energy, and its energy balance counts the work of
    the parameter, int dPi_t/dt dt at fixed u, by the trapezoid. A `mech` with a method
    ``make_solver(pattern, coordinates, mesh)`` builds its own linear solver (a tangent that is
    not a plain sparse matrix, such as the trapped gas's rank-one term, `fem.trapped_gas`).
    predict(t0, u0, t1): the first Newton iterate of the step from the converged state (t0, u0)
    to t1 (default: u0, the prescribed increment then imposed through the tangent), e.g. the
    state's linear response to the load (`fem.branch_walk`)."""
    begin = time.perf_counter()
    n = mech.kin.ndofs
    f_ext = f_ext or (lambda t: np.zeros(n))
    at = getattr(mech, "at", lambda t: mech)
    m0 = at(0.0)
    u0 = np.zeros(n) if start is None else start.u
    state = (plane.initial_state() if start is None else start.contact) if plane is not None else None
    r0 = m0.internal_force(u0)
    build = getattr(m0, "make_solver", make_solver)
    solver = build(m0.linearize(u0)[1], m0.kin.node_coordinates(), m0.kin.mesh)
    policy = ShiftPolicy()
    t, W0 = 0.0, m0.energy(u0)
    if on_step:
        on_step(StepResult(0.0, u0, r0, W0, state, 0))
    dt = dt_ok = options.initial_step * t_max
    steps = iterations = cutbacks = unstable = jumps = 0
    # damped motion (`fem.newton.relax_step`): a mech with its own solver opts in (`fem.trapped_gas`)
    relaxes = plane is not None and getattr(plane.law, "relaxes", False) and \
        getattr(m0, "relaxes", build is make_solver)
    bound = options.max_step * t_max     # the largest move of a node in a relaxed sub-step
    short = SLIP * bound * (1 + 1e-9)     # the longest step across an instability, the largest slip
    dissipated = 0.0
    while t < t_max * (1 - 1e-12):
        t1 = min(t + dt, t_max)
        if t_max - t1 < 0.2 * dt:          # don't leave a sliver at the end
            t1 = t_max
        m1 = at(t1)
        fail = None
        try:
            guess = predict(t, u0, t1) if predict is not None else None
            u1, r1, state1, its, indefinite = newton_step(m1, dirichlet, f_ext, plane, state, u0,
                                                           t1, options, solver, policy, guess=guess)
            if relaxes and indefinite and (t1 - t > short or largest_slip(plane, state1, u1, u0) > short):
                raise StepFailure("the step crossed an instability", [math.nan] * its, indefinite=True)
        except StepFailure as err:
            fail = err
        if fail is not None and relaxes and t1 - t <= short:
            # an incremental friction law: the motion across the instability, in damped increments
            # (a longer step is halved first: where a quasi-static path exists, it follows it)
            iterations += len(fail.history)
            try:
                u1, r1, state1, its = relax_step(m1, dirichlet, f_ext, plane, state, u0, t1,
                                                 options, solver, policy, options.relax_move_m or bound)
                fail, indefinite = None, True
            except StepFailure as again:
                fail = again
        if fail is not None:
            cutbacks += 1
            iterations += getattr(fail, "iterations", len(fail.history))
            if fail.indefinite and jumps < _JUMPS and not relaxes:
                # a structural instability: smaller steps only creep up to the limit point, so
                # first try to step across it (the path jumps; the energy it loses is reported)
                jumps += 1
                dt = dt_ok * 2.0**jumps
                continue
            dt = (dt if not fail.indefinite else min(dt, dt_ok)) * 0.5
            if dt < options.min_step * t_max:
                last = f"{fail.history[-1]:.3e}" if fail.history else "n/a"
                raise ConvergenceError(
                    f"load step {steps + 1} from {name} = {t:.6g} to {t1:.6g} did not converge "
                    f"(step halved below min_step = {options.min_step:g} of the range, last "
                    f"residual {last} after {len(fail.history)} iterations): {fail.cause}",
                    step=steps + 1, t_from=t, t_to=t1, cause=fail.cause, history=fail.history,
                    stats=SolverStats(steps, iterations, cutbacks, time.perf_counter() - begin,
                                      int(n), unstable, float(dissipated), policy.factorizations,
                                      policy.failed),
                ) from None
            continue
        W1 = m1.energy(u1)
        defect = W0 + _work(dirichlet, f_ext, t, t1, u0, u1, r0, r1) - W1
        if m1 is not m0:        # the work of the potential's own parameter, by the trapezoid
            defect += 0.5 * (m1.energy(u0) - W0 + W1 - m0.energy(u1))
        if conservative(plane) and _jumped_too_far(indefinite, defect, W0, W1, t1 - t, jumps, options,
                                            t_max):
            # the descent left the path: a smaller step follows it, or shows the snap is real
            cutbacks += 1
            iterations += its
            dt = 0.5 * (t1 - t)
            continue
        steps += 1
        iterations += its
        unstable += indefinite
        dissipated += defect
        dt_ok = t1 - t
        if plane is not None:
            state1 = plane.law.commit(plane, state1, u1)
        u0, r0, W0, state, t, jumps, m0 = u1, r1, W1, state1, t1, 0, m1
        if on_step:
            try:
                on_step(StepResult(t, u1, r1, W1, state1, its, bool(indefinite)))
            except ConvergenceError as exc:      # the caller refused the state: the cost up to it
                if exc.stats is None:
                    exc.stats = SolverStats(steps - 1, iterations, cutbacks, time.perf_counter() - begin,
                                            int(n), unstable, float(dissipated), policy.factorizations,
                                            policy.failed)
                raise
        if progress:
            progress(t / t_max, f"step {steps}: {name} = {t:.4g}, {its} Newton iterations")
        if its <= options.easy_iterations:
            dt = min(dt * options.growth, options.max_step * t_max)
        dt = min(dt, options.max_step * t_max)
    return SolverStats(steps, iterations, cutbacks, time.perf_counter() - begin, int(n), unstable,
                       float(dissipated), policy.factorizations, policy.failed)


def _jumped_too_far(indefinite: bool, defect: float, W0: float, W1: float, dt: float, jumps: int,
                    opts: SolverOptions, t_max: float) -> bool:
    """Whether a converged step across an instability should be redone with half the step: its
    energy defect W0 + work - W1 (the energy a snap dissipates, plus the trapezoid's O(dt^3))
    exceeds jump_tol of the stored energy and the step is above jump_min_step (module
    docstring). Steps that converged only as a jump
    across a failed step (`_JUMPS`) and stable steps are not judged, nor (in `follow_path`)
    dissipative contact laws, whose slips lose energy at any step size."""
    if not indefinite or jumps or dt <= opts.jump_min_step * t_max * (1 + 1e-9):
        return False
    return abs(defect) > opts.jump_tol * max(abs(W0), abs(W1))


_JUMPS = 2          # attempts to step across an instability (2x, 4x the last good step)


def _work(dirichlet, f_ext, t0, t1, u0, u1, r0, r1) -> float:
    """Work done on the body in the step t0 -> t1 by the prescribed displacements (their
    reactions, r_int at those dofs) and by f_ext, by the trapezoidal rule [J]."""
    d0, v0 = dirichlet(t0)
    d1, v1 = dirichlet(t1)
    work = 0.5 * (r0[d1] + r1[d1]) @ (v1 - v0) if np.array_equal(d0, d1) else 0.0
    return work + 0.5 * (f_ext(t0) + f_ext(t1)) @ (u1 - u0)
