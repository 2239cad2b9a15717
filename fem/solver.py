"""Quasi-static path following: adaptive load steps, Newton with a contact QP and an energy line search.

The body is loaded by a parameter t (the plate displacement for the cup, a load factor elsewhere)
that enters through prescribed displacements ``dirichlet(t) -> (dofs, values)`` and optionally an
external force ``f_ext(t)``. Contact with a `RigidPlane` adds unilateral constraints g_a >= 0.

Every load step solves the equilibrium at t1 as the minimum of the total energy
Pi(u) = W(u) - f_ext . u over the admissible set (the prescribed values, g >= 0, and for the
sticking law the frozen radial positions of the nodes held on the plane). Newton's method on it:

* Predictor: the converged state u0; the first iteration imposes the prescribed increment
  through the tangent (a tangent predictor, which sees the contact; a secant extrapolation of u
  pushed the contact front through the plane and then released it node by node).
* Step: the quadratic model of Pi minimized on the free dofs (prescribed and held contact dofs
  eliminated, K_ff factored once, `fem.linsolve`) subject to the linearized contact conditions
  g_a + du_z,a >= 0 of the free nodes the unconstrained step would push through the plane, and
  of the held nodes whose linearized reaction lambda_a + (K du)_z,a would turn tensile. With the
  columns K_ff^-1 e_a of those m nodes this is the small LCP lambda >= 0, w = q + S lambda >= 0,
  lambda . w = 0 (S = E^T K_ff^-1 E), solved exactly by non-negative least squares: the whole
  contact front moves in one iteration. Nodes pressed (lambda > 0) are held afterwards; held
  nodes the LCP lets go are released.
* Line search: along the projected path P(u + a du) (penetrating nodes put back on the plane),
  backtracking until the Armijo condition on Pi holds. With frictionless contact the energy
  decreases at every iteration, so the contact set cannot cycle; with sticking contact a node
  that lands is moved to its stick point (`RigidPlane.project`), which is not an energy
  minimization, so a cycle is possible in principle (max_iterations ends it). Without contact
  or with frictionless contact, a full step of a shifted (indefinite) iteration is extrapolated:
  a = 2, 4, ... up to 1024 while Pi keeps falling by Armijo (energies only; the last such point
  is evaluated), because the shifted quadratic model does not see the floor of the unstable
  valley it descends into (not for sticking contact, whose slips dissipate: `_line_search`).
* Instability: if K_ff is not positive definite (buckling, a wall lifting off the plane), the
  diagonal is shifted, K_ff + s diag(K_ff) (Levenberg-Marquardt), by a shift within a factor of
  ten of the smallest that makes it definite (`_factor`): the last working shift is tried
  tenfold smaller at the next iteration (below 1e-10: 0); when that fails, the critical shift is
  bracketed from the last working shift (or, at the start of an unstable episode, the shift
  that opened the previous one) and the bracket bisected in log-space. The direction then
  descends, and the iteration follows the energy down to the next stable state. Near a
  bifurcation the unstable eigenvalue is tiny (below 1e-6 of the diagonal in the thin cones): a
  larger shift damps that mode so much that the descent creeps. When a step still fails, it is
  first enlarged (2x, 4x the last good step) to jump across the limit point, then halved.
  Not solved: a snap in which a thin wall leaves the plane and turns over (45 deg / 0.5 mm and
  60 deg / 1 mm cones on the medium mesh, sticking 60 deg / 0.5 mm on the coarse one) is a
  descent with a definite tangent along a curved valley whose accepted steps stay ~0.05 mm
  (a cycle of a ~ 0.1, 0.3, 1): it needs thousands of iterations. Where such a descent starts
  can hang on the shift of an indefinite tangent predictor, whose response along the unstable
  mode grows like 1 / (s - s_critical) (sticking 60 deg / 0.5 mm at u = 9.49 mm: 452 iterations
  to the turned-over wall with s = 1.3e-8, 24 to the neighbouring state with 5.6e-8); a floor
  of 1e-6 on that shift removed this instance but neither made the case run (a later snap
  needs ~460 iterations) nor saved iterations over the robustness cases (28922 against 28223;
  round-off in the linear solves alone moves that total by ~7 %), so it is not used.
* Coulomb friction (`fem.contact`, `fem.friction`): the step is `fem.friction.FrictionStep`,
  the same quadratic model with the linearized frictional contact conditions solved exactly on
  the contact dofs (the body condensed onto them with the factor of K_ff; a semismooth Newton
  method on Alart and Curnier's complementarity functions for which nodes press, stick, slide),
  so that the stick/slide set converges with the displacement. The sliding nodes carry the
  friction -mu lambda s of the iterate (part of the load, so the line search's energy is that of
  fixed friction forces); the step need not descend in it (Coulomb's law is not associated) and
  is also accepted by a fall of the residual. An iterate is converged only if the condensed
  problem keeps its sets (`settled`). Like the sticking law, no extrapolation.
* Jumps: the energy lost in a step, W0 + work - W1 (trapezoid work), is summed over the steps as
  `SolverStats.dissipated_J`. For frictionless contact (conservative: only a snap loses
  energy), a step across an instability that loses more than jump_tol = 0.5 % of W is redone
  with half the step, down to jump_min_step: a large step's descent may land on another branch
  than the one the load path reaches, a real snap keeps its loss as the step shrinks and is
  then accepted, localized to one small step. Sticking contact dissipates in slips at any step
  size, so its steps are not judged by their energy.

The step has converged when the prescribed values hold, no held node pulls on the plane beyond
the tolerance, ||r_f|| <= rtol * max(||reactions||, f_floor) (or <= 100 times that at the
round-off floor, where the Newton correction is below 1e-12 of u, `_balanced`), and the energy
norm of the next correction |du . r| <= etol * f_ref * max|u| (the work scale). A step that fails is cut back
(halved); when the step falls below ``min_step`` a `ConvergenceError` reports the step, the
residual history and the likely cause. Nothing is accepted silently.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import nnls

from .contact import ContactState, RigidPlane
from .forms import Mechanics
from .condensation import make_solver
from .friction import FrictionStep
from .linsolve import NotPositiveDefinite

__all__ = ["SolverOptions", "SolverStats", "ConvergenceError", "follow_path", "StepResult"]


class ConvergenceError(RuntimeError):
    """A load step could not be converged even with the smallest allowed step.

    The message is one line; the attributes say where (the step, its load range t_from -> t_to)
    and why (`cause`, with the likely cause), and keep the residual `history` of the last attempt.
    """

    def __init__(self, message: str, *, step: int = 0, t_from: float = math.nan,
                 t_to: float = math.nan, cause: str = "", history: tuple[float, ...] = ()):
        super().__init__(message)
        self.step, self.t_from, self.t_to = step, t_from, t_to
        self.cause, self.history = cause, tuple(history)


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
    failed_factorizations: int = 0   # failed (not positive definite: the shift search, `_factor`)


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


class _StepFailure(Exception):
    def __init__(self, cause: str, history: list[float], indefinite: bool = False):
        super().__init__(cause)
        self.cause, self.history, self.indefinite = cause, history, indefinite


def follow_path(mech: Mechanics, dirichlet: Callable[[float], tuple[np.ndarray, np.ndarray]],
                t_max: float, *, plane: RigidPlane | None = None,
                f_ext: Callable[[float], np.ndarray] | None = None,
                options: SolverOptions = SolverOptions(),
                on_step: Callable[[StepResult], None] | None = None,
                progress: Callable[[float, str], None] | None = None,
                name: str = "t", start: StepResult | None = None) -> SolverStats:
    """Follow the equilibrium path from t = 0 to t_max; call `on_step` for every converged step
    (including t = 0). `name` names t in messages (e.g. "u [m]"). Raises `ConvergenceError` if
    a step cannot be converged.

    start: the converged state at t = 0 (default: u = 0, no contact), e.g. the end of another
    path. A `mech` with a method ``at(t)`` is a family of potentials Pi_t (a load that is not a
    prescribed displacement or a fixed force, such as a ramped cavity pressure, `fem.cavity`):
    the step to t1 minimizes ``mech.at(t1)``'s energy, and its energy balance counts the work of
    the parameter, int dPi_t/dt dt at fixed u, by the trapezoid."""
    begin = time.perf_counter()
    n = mech.kin.ndofs
    f_ext = f_ext or (lambda t: np.zeros(n))
    at = getattr(mech, "at", lambda t: mech)
    m0 = at(0.0)
    u0 = np.zeros(n) if start is None else start.u
    state = (plane.initial_state() if start is None else start.contact) if plane is not None else None
    r0 = m0.internal_force(u0)
    solver = make_solver(m0.linearize(u0)[1], m0.kin.node_coordinates(), m0.kin.mesh)
    policy = _ShiftPolicy()
    t, W0 = 0.0, m0.energy(u0)
    if on_step:
        on_step(StepResult(0.0, u0, r0, W0, state, 0))
    dt = dt_ok = options.initial_step * t_max
    steps = iterations = cutbacks = unstable = jumps = 0
    dissipated = 0.0
    while t < t_max * (1 - 1e-12):
        t1 = min(t + dt, t_max)
        if t_max - t1 < 0.2 * dt:          # don't leave a sliver at the end
            t1 = t_max
        m1 = at(t1)
        try:
            u1, r1, state1, its, indefinite = _newton(m1, dirichlet, f_ext, plane, state, u0,
                                                      t1, options, solver, policy)
        except _StepFailure as fail:
            cutbacks += 1
            iterations += len(fail.history)
            if fail.indefinite and jumps < _JUMPS:
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
                ) from None
            continue
        W1 = m1.energy(u1)
        defect = W0 + _work(dirichlet, f_ext, t, t1, u0, u1, r0, r1) - W1
        if m1 is not m0:        # the work of the potential's own parameter, by the trapezoid
            defect += 0.5 * (m1.energy(u0) - W0 + W1 - m0.energy(u1))
        conservative = _conservative(plane)
        if conservative and _jumped_too_far(indefinite, defect, W0, W1, t1 - t, jumps, options,
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
            state1 = plane.commit(state1, u1)
        u0, r0, W0, state, t, jumps, m0 = u1, r1, W1, state1, t1, 0, m1
        if on_step:
            on_step(StepResult(t, u1, r1, W1, state1, its, bool(indefinite)))
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
    exceeds jump_tol of the stored energy and the step is above jump_min_step. The descent from
    a large step may land on another branch than the one the load path reaches: on the thin
    60-degree cone a 0.5 mm step "snapped" at u = 4.3 mm losing 4 % of W, while 0.27 mm steps
    pass the same u with no loss. A real snap keeps its loss as the step shrinks and is
    accepted at jump_min_step, localized to that step. Steps that converged only as a jump
    across a failed step (`_JUMPS`) and stable steps are not judged, nor (in `follow_path`)
    sticking contact, whose slips dissipate energy at any step size."""
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


def _newton(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy):
    """Newton iterations of one step with a contact QP per iteration (module docstring);
    returns (u, r_int, contact state, iterations, whether the tangent was indefinite on the way)."""
    flags = {"indefinite": False}
    try:
        return _iterate(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy, flags)
    except _StepFailure as fail:
        fail.indefinite = flags["indefinite"]
        raise


def _iterate(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy, flags):
    n = mech.kin.ndofs
    fixed_dofs, fixed_vals = dirichlet(t)
    fext0 = fext = f_ext(t)
    history: list[float] = []
    try:
        u = plane.project(u_start, u_start, state, state.active) if plane is not None else u_start
        Pi, r, K = _evaluate(mech, u, fext)
    except FloatingPointError as err:
        raise _StepFailure(f"{err} at the predictor; likely cause: the step is too large for "
                           "the deformation, or the mesh is too coarse", history) from None
    it, shift, indefinite = 0, 0.0, False
    released = np.zeros(len(plane.nodes), bool) if plane is not None else None
    while True:
        res = r - fext0
        free, dofs, du_fixed = _free_dofs(n, fixed_dofs, fixed_vals, u, plane, state)
        f_ref = max(np.linalg.norm(res[dofs]), np.linalg.norm(fext0), _force_floor(mech))
        if plane is not None and plane.law == "coulomb":
            fric = plane.friction_force(state, res)
            Pi += (fext - fext0 - fric) @ u           # the same W, the new load
            fext = fext0 + fric
            res = r - fext
            free, dofs, du_fixed = _free_dofs(n, fixed_dofs, fixed_vals, u, plane, state)
        rnorm = np.linalg.norm(res[free])
        history.append(rnorm / f_ref)
        if not np.all(np.isfinite(res)):
            raise _StepFailure("the residual is not finite", history)
        if plane is not None and plane.law == "coulomb":
            step = FrictionStep(plane, state, u, res, free, du_fixed, opts.rtol * f_ref, _factor,
                                fext - fext0)
        else:
            step = _Step(plane, state, u, res, free, du_fixed, opts.rtol * f_ref)
        shift = step.solve(solver, K, shift, history, policy)
        indefinite |= shift > 0.0
        flags["indefinite"] = indefinite
        energy = abs(step.du @ res)
        e_ref = f_ref * max(np.max(np.abs(u)), np.max(np.abs(step.du)), 1e-9 * _size(mech))
        held = not np.any(du_fixed)
        tensile = plane is not None and np.any(plane.reactions(res)[state.active] < -opts.rtol * f_ref)
        if held and not tensile and _balanced(rnorm, opts.rtol * f_ref, step.du, u) \
                and energy <= opts.etol * e_ref and getattr(step, "settled", True):
            if plane is not None and plane.cone_excess(state, res) > 1e3 * opts.rtol:
                raise _StepFailure("Coulomb's stick/slide set cycled and the node held stuck lies "
                                   f"outside the friction cone ({plane.cone_excess(state, res):.2g} "
                                   "of the largest normal reaction); likely cause: a too-large step, "
                                   "or a friction bound falling steeply with the slip", history)
            return u, r, state, it, indefinite
        it += 1
        if it >= opts.max_iterations:
            raise _StepFailure(f"no convergence in {opts.max_iterations} Newton iterations; likely cause: a "
                               "structural instability (snap-through/buckling) that the step jumps "
                               "across, or a too-large step", history)
        u_prev = u
        alpha, u, Pi, r, K, shift = _line_search(mech, solver, policy, step, u_start, u, Pi, res,
                                                 K, fext, shift, held, history)
        if plane is not None:
            released |= step.release
            u_free = u_prev + max(alpha, 1.0) * step.du0
            state = plane.hold(step.state, step.holds(alpha), u, u_start, u_free, released)


def _balanced(rnorm: float, tol: float, du: np.ndarray, u: np.ndarray) -> bool:
    """The residual test: ||r_f|| <= tol, or, at the round-off floor, ||r_f|| <= 100 tol with a
    Newton correction below 1e-12 of the displacement: the state is then converged to 12 digits
    in displacement, and the residual left is the assembly's round-off, which no iteration
    reduces (in the 0.1 mm walls the element forces that cancel at a node are ~1e8 times the
    plate reaction the tolerance is relative to; the residual stagnated at 1.2e-6 (45 deg) and
    1.4e-5 (70 deg) of it, with corrections of 1e-16 to 1e-14 m, for 400 iterations)."""
    if rnorm <= tol:
        return True
    return rnorm <= 100.0 * tol and np.max(np.abs(du)) <= 1e-12 * np.max(np.abs(u))


class _Step:
    """The Newton step of one iterate: the quadratic model of the energy minimized on the free
    dofs subject to the linearized contact conditions g_a + du_z,a >= 0 (a small QP, module
    docstring) of the free nodes it would push through the plane and of the held nodes whose
    linearized reaction lambda + (K du)_z would turn tensile (these are freed in K_ff, if it
    stays positive definite without them)."""

    coupled = False     # accepted by the energy only (`fem.friction.FrictionStep`: also the residual)

    def __init__(self, plane, state, u, res, free, du_fixed, tol):
        self.plane, self.state, self.u, self.res, self.du_fixed = plane, state, u, res, du_fixed
        self.free, self.tol = free, tol

    def solve(self, solver, K, shift, history, policy, lower=True) -> float:
        """Factor (with a diagonal shift if K_ff is not positive definite), solve, and add
        contact constraints until no free candidate penetrates; then let the held nodes the
        step would pull on take part. `shift`: the last one used (tried smaller first, `_factor`),
        or with `lower` False the one to try first. Returns the shift used."""
        fac, shift = _factor(solver, K, self.free, shift, history, policy, lower)
        self._constrained(fac, np.zeros(0, int))
        if self.plane is None:
            return shift
        zdof = 2 * self.plane.nodes + 1
        tensile = self.state.active & ((self.res + K @ self.du)[zdof] < -self.tol)
        self.release = np.zeros_like(tensile)
        if tensile.any():
            try:        # bordered by the freed dofs (Schur complement): no new factorization
                fac = fac.freeing(zdof[tensile])
            except NotPositiveDefinite:
                # without them K_ff is indefinite (the contact held the structure): shifted
                free = self.free.copy()
                free[zdof[tensile]] = True
                fac, shift = _factor(solver, K, free, shift, history, policy, lower=False)
            self._constrained(fac, np.flatnonzero(tensile))
            self.release = tensile
        return shift

    def _constrained(self, fac, candidates: np.ndarray) -> None:
        """du0 = -K_ff^-1 r, then the LCP of `candidates` and every free node that du penetrates."""
        du0 = fac.solve(-self.res, self.du_fixed)
        self.du, self.du0, self.qp, self.lam = du0, du0, np.zeros(0, int), np.zeros(0)
        if self.plane is None:
            return
        zdof = 2 * self.plane.nodes + 1
        g = self.plane.gap(self.u)
        add = np.zeros(len(g), bool)
        add[candidates] = True
        cols = np.zeros((len(du0), 0))
        for _ in range(20):
            add |= ~self.state.active & (g + self.du[zdof] < 0.0)
            add[self.qp] = False
            if not add.any():
                break
            new = np.flatnonzero(add)
            E = np.zeros((len(du0), len(new)))
            E[zdof[new], np.arange(len(new))] = 1.0
            cols = np.hstack([cols, fac.solve(E)])
            self.qp = np.concatenate([self.qp, new])
            S = cols[zdof[self.qp]]
            self.lam = _lcp(0.5 * (S + S.T), g[self.qp] + du0[zdof[self.qp]])
            self.du = du0 + cols @ self.lam
            add[:] = False

    def holds(self, alpha: float) -> np.ndarray:
        """The held set after a step of length alpha (also the nodes the step puts exactly on
        the plane, removing the round-off of g + du_z = 0): the held nodes outside the QP, those
        in it that stay pressed (lambda > 0), and after a full step the free nodes it presses
        onto the plane."""
        active = self.state.active & ~self.release
        pressed = self.qp[self.lam > 0.0]
        if alpha >= 1.0:
            active[pressed] = True
        else:
            active[pressed] = self.state.active[pressed]
        return active


def _lcp(S, q):
    """lambda >= 0 with w = q + S lambda >= 0 and lambda . w = 0 (S symmetric positive definite):
    the minimizer of lambda S lambda / 2 + q . lambda over lambda >= 0, by non-negative least
    squares on the Cholesky factor S = L L^T (Lawson-Hanson, finite)."""
    scale = np.sqrt(np.diag(S))
    Sn = S / np.outer(scale, scale)
    L = np.linalg.cholesky(Sn)
    y = np.linalg.solve(L, q / scale)
    x, _ = nnls(L.T, -y)
    return x / scale


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


def _evaluate(mech, u, fext):
    """Total potential Pi = W(u) - f_ext . u, internal force and tangent at u."""
    W, r, K = mech.evaluate(u)
    return W - fext @ u, r, K


class _ShiftPolicy:
    """The memory of the diagonal shift across the iterations of a path (`_factor`): the shift
    that worked first in the last unstable episode, where the search of the next one starts;
    and the count of factorizations (attempted, failed)."""

    def __init__(self) -> None:
        self.onset = 0.0
        self.factorizations = self.failed = 0

    def factor(self, solver, K, free, shift):
        """solver.factor(K, free, shift), counted."""
        self.factorizations += 1
        try:
            return solver.factor(K, free, shift)
        except NotPositiveDefinite:
            self.failed += 1
            raise


def _factor(solver, K, free, shift, history, policy=None, lower=True):
    """Factor K_ff; if it is not positive definite (the Newton direction would not descend in
    energy: a structural instability), shift the diagonal, K_ff + s diag(K_ff)
    (Levenberg-Marquardt), by a shift within a factor of ten of the smallest that makes it
    definite: near a bifurcation the negative eigenvalue is tiny (below 1e-6 of the diagonal in
    the thin cones), and a shift far above it damps the unstable mode so much that the descent
    creeps (5 % longer steps per iteration).

    The shift s that worked at the last iteration is tried tenfold smaller first (`lower`; below
    _SHIFT_MIN: 0). If that fails, the search brackets the critical shift between the failed
    value and one that works (s itself, else the shift that opened the last unstable episode,
    else thousandfold steps up from _SHIFT_MIN) and bisects the bracket in log-space down to a
    factor of ten: an episode that needs 1e-1 costs ~5 factorizations instead of the 11 of a
    tenfold ladder from _SHIFT_MIN. Returns (factor, shift)."""
    policy = policy or _ShiftPolicy()
    trial = shift
    if lower:
        trial = shift / 10.0 if shift >= 10.0 * _SHIFT_MIN else 0.0
    try:
        return policy.factor(solver, K, free, trial), trial
    except NotPositiveDefinite:
        pass
    lo = max(trial, 0.1 * _SHIFT_MIN)
    hi = next((c for c in (shift, policy.onset) if c > lo), max(1e3 * lo, _SHIFT_MIN))
    while True:                              # bracket: lo fails, hi works
        try:
            fac = policy.factor(solver, K, free, hi)
            break
        except NotPositiveDefinite:
            lo, hi = hi, 1e3 * hi
            if hi > 1e3 * (1 + 1e-9):
                raise _StepFailure("the tangent is not positive definite even with a diagonal shift "
                                   "of 1e3; likely cause: an unconstrained rigid-body mode", history) from None
    while hi > 10.0 * lo * (1 + 1e-9):       # bisect in log-space
        mid = float(np.sqrt(lo * hi))
        try:
            fac, hi = policy.factor(solver, K, free, mid), mid
        except NotPositiveDefinite:
            lo = mid
    if trial == 0.0:
        policy.onset = hi
    return fac, hi


_SHIFT_MIN = 1e-10      # smallest diagonal shift (relative); cond(K_ff + s D) stays < ~1e12


def _line_search(mech, solver, policy, step, u_start, u, Pi, res, K, fext, shift, held, history,
                 tries: int = 8):
    """The next iterate P(u + a du) (projected onto the admissible set) and its linearization.

    While prescribed values are still being imposed (not `held`), a = 1 unless an element would
    invert (halve). Then a backtracks (quadratic interpolation, a in [0.1 a, 0.5 a]) until the
    Armijo condition Pi(P(u + a du)) <= Pi(u) + 1e-4 r . (P(u + a du) - u) holds (to round-off
    of Pi); if no a does, the direction is not one of descent: the diagonal shift is raised
    (at most three times) and the direction recomputed. A full step with a shift is extrapolated
    (`_extrapolate`) where the energy is the path's potential (no contact, or frictionless
    contact): with sticking contact the slips dissipate, and a long move along the direction let
    nodes land far from where the load path puts them (fine cup A, default steps: F0 fell from
    2.08 to 0.60 N at u = 0.063 h1, the rim slipped). Returns (a, u, Pi, r, K, shift)."""
    slack = 1e-12 * abs(Pi) + 1e-14 * np.linalg.norm(res) * np.max(np.abs(u))
    plane = step.plane
    for attempt in range(4):
        du = step.du
        s0 = du @ res
        alpha = 1.0
        for _ in range(tries):
            try:
                trial = u + alpha * du
                if plane is not None:
                    trial = plane.project(trial, u_start, step.state, step.holds(alpha))
                Pi1, r1, K1 = _evaluate(mech, trial, fext)
            except FloatingPointError:
                alpha *= 0.5
                continue
            if not held or Pi1 - Pi <= 1e-4 * (res @ (trial - u)) + slack or (
                    step.coupled and step.reduces_residual(r1, fext - step.friction, alpha)):
                if held and alpha == 1.0 and shift > 0.0 and _conservative(plane):
                    return _extrapolate(mech, step, u_start, u, Pi, res, fext, trial, Pi1, r1, K1,
                                        slack) + (shift,)
                return alpha, trial, Pi1, r1, K1, shift
            # quadratic model along the ray: Pi(a) ~ Pi + s0 a + c a^2
            curv = (Pi1 - Pi - s0 * alpha) / alpha**2
            a_min = -s0 / (2.0 * curv) if curv > 0 and s0 < 0 else 0.1 * alpha
            alpha = float(np.clip(a_min, 0.1 * alpha, 0.5 * alpha))
        if not held or attempt == 3:
            break
        shift = step.solve(solver, K, max(10.0 * shift, 1e-4), history, policy, lower=False)
    raise _StepFailure("line search failed: no step length decreases the energy (or every one "
                       "inverts an element); likely cause: the load step is too large for the "
                       "deformation", history)


def _extrapolate(mech, step, u_start, u, Pi, res, fext, trial, Pi1, r1, K1, slack):
    """A full shifted step was accepted: the direction descends into an unstable valley whose
    floor the shifted quadratic model does not see. Double the step (a = 2, 4, ...,
    _EXTRAPOLATE_MAX) while the energy keeps falling by Armijo, and return the last such point
    (a, u, Pi, r, K). The energies of the trials only are evaluated."""
    plane, best, alpha = step.plane, (trial, Pi1), 1.0
    while alpha < _EXTRAPOLATE_MAX:
        a = 2.0 * alpha
        t = u + a * step.du
        if plane is not None:
            t = plane.project(t, u_start, step.state, step.holds(a))
        try:
            with np.errstate(invalid="ignore", divide="ignore"):     # an inverted element: NaN
                P = mech.energy(t) - fext @ t
        except FloatingPointError:
            break
        if not np.isfinite(P) or P >= best[1] or P - Pi > 1e-4 * (res @ (t - u)) + slack:
            break
        best, alpha = (t, P), a
    if alpha > 1.0:
        try:                 # the full evaluation also checks every quadrature point's J > 0
            return (alpha, best[0]) + _evaluate(mech, best[0], fext)
        except FloatingPointError:
            pass
    return 1.0, trial, Pi1, r1, K1


_EXTRAPOLATE_MAX = 1024.0


def _conservative(plane: RigidPlane | None) -> bool:
    """Whether the total energy is the path's potential: no contact, or frictionless contact."""
    return plane is None or plane.law == "frictionless"


def _size(mech: Mechanics) -> float:
    return float(np.max(np.ptp(mech.kin.node_coordinates(), axis=1)))


def _force_floor(mech: Mechanics) -> float:
    """A force scale below which residuals are round-off: 1e-6 mu L^2 with L the body's size."""
    return 1e-6 * mech.material.mu * _size(mech) ** 2
