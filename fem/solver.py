"""Quasi-static path following: adaptive load steps, a secant predictor, Newton with line search.

The body is loaded by a parameter t (the plate displacement for the cup, a load factor elsewhere)
that enters through prescribed displacements ``dirichlet(t) -> (dofs, values)`` and optionally an
external force ``f_ext(t)``. Contact with a `RigidPlane` adds the active-set constraints.

Each step t0 -> t1 starts from the secant predictor u1 = u0 + (t1 - t0)/(t0 - t_prev) (u0 - u_prev)
and iterates Newton on the free dofs (prescribed and active-contact dofs eliminated). The step has
converged when

* the active contact set did not change in the last iteration and all constraints hold,
* the free residual satisfies ||r_f|| <= rtol * max(||reactions||, f_floor), and
* the energy norm of the last correction |du . r_f| <= etol * f_ref * max|u| (the work scale).

A line search along the Newton direction (secant on the energy slope s(a) = du . r_f(u + a du))
is taken when the slope does not drop below 0.8 |s(0)|, or when an element would invert. A step
that fails is cut back (halved); when the step falls below ``min_step`` a `ConvergenceError`
reports the step, the residual history and the likely cause. Nothing is accepted silently.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from .contact import ContactState, RigidPlane
from .forms import Mechanics

__all__ = ["SolverOptions", "SolverStats", "ConvergenceError", "follow_path", "StepResult"]


class ConvergenceError(RuntimeError):
    """A load step could not be converged even with the smallest allowed step."""


@dataclass(frozen=True)
class SolverOptions:
    """Tolerances and step control (dimensionless unless suffixed)."""

    rtol: float = 1e-6          # residual / reaction
    etol: float = 1e-12         # energy norm of the correction / work scale f_ref max|u|
    max_iterations: int = 25
    initial_step: float = 0.01  # first step as a fraction of t_max
    max_step: float = 0.05      # largest step as a fraction of t_max (resolution of the curve)
    min_step: float = 1e-5      # smallest step as a fraction of t_max before giving up
    growth: float = 1.5         # step growth after an easy step (<= easy_iterations)
    easy_iterations: int = 6
    active_set_rtol: float = 1e-3   # residual / reaction below which the contact set is revisited
    max_active_sets: int = 40       # distinct contact sets tried in one step before giving up

    def __post_init__(self) -> None:
        for name in ("rtol", "etol", "initial_step", "max_step", "min_step", "active_set_rtol"):
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


@dataclass(frozen=True, eq=False)
class StepResult:
    """A converged state: load parameter, displacement, internal force, contact state."""

    t: float
    u: np.ndarray
    r_int: np.ndarray
    contact: ContactState | None
    iterations: int


class _StepFailure(Exception):
    def __init__(self, cause: str, history: list[float]):
        super().__init__(cause)
        self.cause, self.history = cause, history


def follow_path(mech: Mechanics, dirichlet: Callable[[float], tuple[np.ndarray, np.ndarray]],
                t_max: float, *, plane: RigidPlane | None = None,
                f_ext: Callable[[float], np.ndarray] | None = None,
                options: SolverOptions = SolverOptions(),
                on_step: Callable[[StepResult], None] | None = None,
                progress: Callable[[float, str], None] | None = None,
                name: str = "t") -> SolverStats:
    """Follow the equilibrium path from t = 0 to t_max; call `on_step` for every converged step
    (including t = 0). `name` names t in messages (e.g. "u [m]"). Raises `ConvergenceError` if
    a step cannot be converged."""
    start = time.perf_counter()
    n = mech.kin.ndofs
    f_ext = f_ext or (lambda t: np.zeros(n))
    u0 = np.zeros(n)
    state = plane.initial_state() if plane is not None else None
    r0 = mech.internal_force(u0)
    if on_step:
        on_step(StepResult(0.0, u0, r0, state, 0))
    t, u_prev, t_prev = 0.0, None, None
    dt = options.initial_step * t_max
    steps = iterations = cutbacks = 0
    while t < t_max * (1 - 1e-12):
        t1 = min(t + dt, t_max)
        if t_max - t1 < 0.2 * dt:          # don't leave a sliver at the end
            t1 = t_max
        guess = u0 if u_prev is None else u0 + (t1 - t) / (t - t_prev) * (u0 - u_prev)
        try:
            u1, r1, state1, its = _newton(mech, dirichlet, f_ext, plane, state, u0, guess, t1, options)
        except _StepFailure as fail:
            cutbacks += 1
            iterations += len(fail.history)
            dt *= 0.5
            if dt < options.min_step * t_max:
                raise ConvergenceError(
                    f"load step {steps + 1} from {name} = {t:.6g} to {t1:.6g} did not converge "
                    f"(step halved below min_step = {options.min_step:g} of the range; "
                    f"{cutbacks} cut-backs in this run): "
                    f"{fail.cause}; residual history {', '.join(f'{h:.3e}' for h in fail.history)}"
                ) from None
            continue
        steps += 1
        iterations += its
        u_prev, t_prev, u0, state, t = u0, t, u1, state1, t1
        if on_step:
            on_step(StepResult(t, u1, r1, state1, its))
        if progress:
            progress(t / t_max, f"step {steps}: {name} = {t:.4g}, {its} Newton iterations")
        if its <= options.easy_iterations:
            dt = min(dt * options.growth, options.max_step * t_max)
    return SolverStats(steps, iterations, cutbacks, time.perf_counter() - start, int(n))


def _newton(mech, dirichlet, f_ext, plane, state, u_start, guess, t, opts):
    """Newton iterations of one step; returns (u, r_int, contact state, iterations).

    The contact active set is revisited whenever the iterate is nearly converged for the
    current set (||r_f|| <= active_set_rtol * f_ref): all violating nodes change at once; if
    that reproduces a set already tried in this step, only the worst violation changes."""
    n = mech.kin.ndofs
    fixed_dofs, fixed_vals = dirichlet(t)
    fext = f_ext(t)
    u = guess.copy()
    history: list[float] = []
    seen = {state.key()} if plane is not None else set()
    it = 0
    try:
        r, K = mech.linearize(u)
    except FloatingPointError as err:
        raise _StepFailure(f"{err} at the predictor; likely cause: the step is too large for "
                           "the deformation, or the mesh is too coarse", history) from None
    while True:
        res = r - fext
        if plane is not None:
            cd, cv = plane.constraints(state)
            dofs, vals = np.concatenate([fixed_dofs, cd]), np.concatenate([fixed_vals, cv])
        else:
            dofs, vals = fixed_dofs, fixed_vals
        free = np.ones(n, bool)
        free[dofs] = False
        du = np.zeros(n)
        du[dofs] = vals - u[dofs]
        f_ref = max(np.linalg.norm(res[dofs]), np.linalg.norm(fext), _force_floor(mech))
        rnorm = np.linalg.norm(res[free])
        history.append(rnorm / f_ref)
        if not np.all(np.isfinite(res)):
            raise _StepFailure("the residual is not finite", history)
        try:
            du = _solve_constrained(K, -res, free, du)
        except RuntimeError as err:  # singular factor
            raise _StepFailure(f"singular tangent ({err}); likely cause: an unconstrained "
                               "rigid-body mode or a structural instability", history) from None
        if not np.all(np.isfinite(du)):
            raise _StepFailure("singular tangent; likely cause: an unconstrained rigid-body mode "
                               "or a structural instability (buckling)", history)
        energy = abs(du[free] @ res[free])
        e_ref = f_ref * max(np.max(np.abs(u)), np.max(np.abs(du)), 1e-9 * _size(mech))
        held = np.max(np.abs(du[dofs]), initial=0.0) <= 1e-14 * (1.0 + np.max(np.abs(u)))
        converged = held and rnorm <= opts.rtol * f_ref and energy <= opts.etol * e_ref
        if plane is not None and held and (converged or rnorm <= opts.active_set_rtol * f_ref):
            new = plane.update(state, u, res, u_start)
            if np.any(new.active != state.active):
                if new.key() in seen and plane.law == "sticking":
                    new = plane.let_slip(state, new.active != state.active)
                if new.key() in seen:
                    new = plane.update(state, u, res, u_start, stiffness=K.diagonal())
                if new.key() in seen or len(seen) > opts.max_active_sets:
                    raise _StepFailure("the contact active set cycles (nodes chatter between "
                                       "contact and lift-off); likely cause: too large a step", history)
                seen.add(new.key())
                state = new
                continue
        if converged:
            return u, r, (plane.settle(state, u) if plane is not None else state), it
        it += 1
        if it >= opts.max_iterations:
            raise _StepFailure(f"no convergence in {opts.max_iterations} Newton iterations; likely "
                               "cause: a structural instability (snap-through/buckling) or a "
                               "too-large step", history)
        # full steps while constraints are being imposed; line search once they hold
        alpha, (r, K) = _line_search(mech, u, du, res[free], free, fext, history, exact=not held)
        u = u + alpha * du


def _line_search(mech, u, du, res_free, free, fext, history, exact=False, tries: int = 6):
    """Step length along du: 1 unless an element inverts (halve) or the energy slope
    s(a) = du . r_f(u + a du) changes sign and stays above 0.8 |s(0)| (secant to s = 0).
    With `exact`, only inversion shortens the step (prescribed jumps in du make s meaningless).
    Returns (alpha, linearization at u + alpha du)."""
    s0 = du[free] @ res_free
    alpha = 1.0
    for _ in range(tries):
        try:
            trial = mech.linearize(u + alpha * du)
        except FloatingPointError:
            alpha *= 0.5
            continue
        s1 = du[free] @ (trial[0] - fext)[free]
        if exact or s0 == 0.0 or np.sign(s1) == np.sign(s0) or abs(s1) <= 0.8 * abs(s0):
            return alpha, trial
        alpha *= max(0.1, s0 / (s0 - s1))
    try:
        return alpha, mech.linearize(u + alpha * du)
    except FloatingPointError:
        raise _StepFailure("line search failed: every step length inverts an element; likely "
                           "cause: the load step is too large for the deformation", history) from None


def _solve_constrained(K, rhs, free, du_fixed):
    """Solve K du = rhs on the free dofs with du = du_fixed on the others, by symmetric
    elimination in place of the rows and columns (the sparsity pattern is kept)."""
    K = K.copy()
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    fixed = ~free
    b = rhs - K @ np.where(fixed, du_fixed, 0.0)
    K.data[fixed[rows] | fixed[K.indices]] = 0.0
    K.data[fixed[rows] & (rows == K.indices)] = 1.0
    b[fixed] = du_fixed[fixed]
    # the pattern is structurally symmetric: a minimum-degree ordering of A^T + A suits it
    return spla.spsolve(K.tocsc(), b, permc_spec="MMD_AT_PLUS_A")


def _size(mech: Mechanics) -> float:
    return float(np.max(np.ptp(mech.kin.node_coordinates(), axis=1)))


def _force_floor(mech: Mechanics) -> float:
    """A force scale below which residuals are round-off: 1e-6 mu L^2 with L the body's size."""
    return 1e-6 * mech.material.mu * _size(mech) ** 2
