"""The line search of a Newton step: backtracking on the energy, and extrapolation down a valley.

The next iterate lies on the projected path P(u + a du) (penetrating nodes put back on the
plane); a backtracks until the Armijo condition on the total potential Pi = W - f_ext . u holds.
With frictionless contact the energy falls at every iteration, so the contact set cannot cycle;
with sticking contact a node that lands is moved to its stick point, which is not an energy
minimization (max_iterations ends a cycle). Where the energy is the path's potential (no
contact, or frictionless contact), a full step of a shifted (indefinite) iteration is
extrapolated, a = 2, 4, ... while Pi keeps falling: the shifted quadratic model does not see the
floor of the unstable valley it descends into. Steps that dissipate (sticking slips, Coulomb)
are not extrapolated: a long move lets nodes land far from where the load path puts them.
"""

from __future__ import annotations

import numpy as np

from .failure import StepFailure

__all__ = ["line_search", "extrapolate", "total_potential", "conservative", "EXTRAPOLATE_MAX"]

EXTRAPOLATE_MAX = 1024.0


def total_potential(mech, u, fext):
    """Total potential Pi = W(u) - f_ext . u, internal force and tangent at u."""
    W, r, K = mech.evaluate(u)
    return W - fext @ u, r, K


def conservative(plane) -> bool:
    """Whether the total energy is the path's potential: no contact, or frictionless contact."""
    return plane is None or plane.law.conservative


def line_search(mech, solver, policy, step, u_start, u, Pi, res, K, fext, shift, held, history,
                tries: int = 8):
    """The next iterate P(u + a du) (projected onto the admissible set) and its linearization.

    While prescribed values are still being imposed (not `held`), a = 1 unless an element would
    invert (halve). Then a backtracks (quadratic interpolation, a in [0.1 a, 0.5 a]) until the
    Armijo condition Pi(P(u + a du)) <= Pi(u) + 1e-4 r . (P(u + a du) - u) holds (to round-off
    of Pi); if no a does, the direction is not one of descent: the diagonal shift is raised
    (at most three times) and the direction recomputed. A full step with a shift is extrapolated
    (`extrapolate`) where the path is conservative. Returns (a, u, Pi, r, K, shift)."""
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
                Pi1, r1, K1 = total_potential(mech, trial, fext)
            except FloatingPointError:
                alpha *= 0.5
                continue
            if not held or Pi1 - Pi <= 1e-4 * (res @ (trial - u)) + slack or (
                    step.coupled and step.reduces_residual(r1, fext - step.friction, alpha)):
                if held and alpha == 1.0 and shift > 0.0 and conservative(plane):
                    return extrapolate(mech, step, u_start, u, Pi, res, fext, trial, Pi1, r1, K1,
                                       slack) + (shift,)
                return alpha, trial, Pi1, r1, K1, shift
            # quadratic model along the ray: Pi(a) ~ Pi + s0 a + c a^2
            curv = (Pi1 - Pi - s0 * alpha) / alpha**2
            a_min = -s0 / (2.0 * curv) if curv > 0 and s0 < 0 else 0.1 * alpha
            alpha = float(np.clip(a_min, 0.1 * alpha, 0.5 * alpha))
        if not held or attempt == 3:
            break
        shift = step.solve(solver, K, max(10.0 * shift, 1e-4), history, policy, lower=False)
    raise StepFailure("line search failed: no step length decreases the energy (or every one "
                      "inverts an element); likely cause: the load step is too large for the "
                      "deformation", history)


def extrapolate(mech, step, u_start, u, Pi, res, fext, trial, Pi1, r1, K1, slack):
    """A full shifted step was accepted: the direction descends into an unstable valley whose
    floor the shifted quadratic model does not see. Double the step (a = 2, 4, ...,
    EXTRAPOLATE_MAX) while the energy keeps falling by Armijo, and return the last such point
    (a, u, Pi, r, K). The energies of the trials only are evaluated."""
    plane, best, alpha = step.plane, (trial, Pi1), 1.0
    while alpha < EXTRAPOLATE_MAX:
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
            return (alpha, best[0]) + total_potential(mech, best[0], fext)
        except FloatingPointError:
            pass
    return 1.0, trial, Pi1, r1, K1
