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
condensed problem keeps its sets. Anything else raises `fem.failure.StepFailure` with its cause.
"""

from __future__ import annotations

import numpy as np

from .contact_step import ContactStep
from .failure import StepFailure
from .linesearch import line_search, total_potential

__all__ = ["newton_step", "balanced"]


def newton_step(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy):
    """Newton iterations of one step with a contact step per iteration (module docstring), to the
    tolerances of `opts` (a `fem.solver.SolverOptions`); returns (u, r_int, contact state,
    iterations, whether the tangent was indefinite on the way)."""
    flags = {"indefinite": False}
    try:
        return _iterate(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy, flags)
    except StepFailure as fail:
        fail.indefinite = flags["indefinite"]
        raise


def _iterate(mech, dirichlet, f_ext, plane, state, u_start, t, opts, solver, policy, flags):
    n = mech.kin.ndofs
    fixed_dofs, fixed_vals = dirichlet(t)
    fext0 = fext = f_ext(t)
    history: list[float] = []
    try:
        u = plane.project(u_start, u_start, state, state.active) if plane is not None else u_start
        Pi, r, K = total_potential(mech, u, fext)
    except FloatingPointError as err:
        raise StepFailure(f"{err} at the predictor; likely cause: the step is too large for "
                          "the deformation, or the mesh is too coarse", history) from None
    it, shift, indefinite = 0, 0.0, False
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
