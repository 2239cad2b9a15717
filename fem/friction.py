"""Coulomb friction in the Newton iteration: the stick/slide set and the consistent Newton matrix.

The law and its active set live in `fem.contact` (`RigidPlane.slide`, `friction_force`). A
sliding node a carries the plane's friction f_a = -mu s_a lambda_a(u) on its radial dof, where the
normal reaction lambda_a = (r_int - f_ext)_z,a moves with u. The residual's derivative is then

    dR/du = K + sum_a e_r,a (mu s_a dlambda_a/du)^T = K + U V^T,   dlambda_a/du = K[z_a, :],

a rank-m update of the symmetric tangent (m sliding nodes; not symmetric: Coulomb's law is not
associated). `CoupledFactor` solves with it by the Woodbury identity on the existing Cholesky
factor of K_ff (m extra solves), so that the iteration keeps Newton's quadratic rate instead of
the linear rate of a fixed point on lambda (8-11 iterations per step on cup A, mu = 1).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .contact import ContactState, RigidPlane

__all__ = ["CoupledFactor", "friction_iterate"]


def friction_iterate(plane: RigidPlane, state: ContactState, u: np.ndarray, lin: np.ndarray,
                     res: np.ndarray, K: sp.csr_matrix, tol: float, flips: np.ndarray
                     ) -> tuple[ContactState, np.ndarray, np.ndarray]:
    """The stick/slide set at the iterate u and the friction force it carries. The set is decided
    on `lin`, the reactions the last Newton step predicted for u (the multipliers of the
    linearized problem, as a semismooth Newton method does, not the out-of-balance residual of an
    iterate far from equilibrium: that one let a stuck rim corner slide on the first iterate of a
    step), with c the radial diagonal stiffness; the force is mu lambda of u itself (`res`), so a
    converged state holds Coulomb's law with its own normal reactions.

    `flips` counts each node's switches in this load step. A node that has switched FREEZE times
    sticks for the rest of the step: where the friction bound falls steeply with the slip
    (mu dlambda/dDelta < -c: cup A with mu = 10 at 0.88 h1), the node is consistent neither
    stuck (|t| > mu lambda by a few %) nor sliding (its slide reverses), and the set would cycle
    for ever. A state converged so that violates the cone by more than 1e3 rtol of the largest
    normal reaction is refused (the step is cut back, `fem.solver`); below, the excess is what
    `RigidPlane.cone_excess` reports per step."""
    c = np.maximum(K.diagonal()[2 * plane.nodes], 1e-300)
    new = plane.slide(state, u, lin, c, tol)
    flips = flips + (new.slip != state.slip)
    frozen = flips >= FREEZE
    if frozen.any():
        new = ContactState(new.active, new.u_r_stick_m, np.where(frozen, 0, new.slip).astype(np.int8))
    return new, plane.friction_force(new, res), flips


def landing_slip(plane: RigidPlane, before: ContactState, after: ContactState, u_free: np.ndarray,
                 lin: np.ndarray, K: sp.csr_matrix) -> ContactState:
    """The stick/slide status of the nodes held anew (`RigidPlane.hold` makes them stick) for
    mu = 0: they slide at once, along their free flight past the touchdown point (z = -c Delta,
    Delta = u_free,r - anchor, the rule of `RigidPlane.slide` with t = 0). Sticking first cost
    every landing an iteration or more and let the set cycle (cup A, medium, to 0.9 h1: 536
    Newton iterations against the frictionless law's 94). With mu > 0 a landing node sticks
    first and `slide` decides on the reactions of the next step: sliding first wherever
    c |Delta| > mu lambda (lambda predicted by the step) let cup A with mu = 10 settle on sliding
    states at the contact edge, 0.51 % off the sticking curve (0.39 % sticking first)."""
    if plane.law != "coulomb" or plane.friction > 0.0:
        return after
    new = after.active & ~before.active
    if not new.any():
        return after
    rdof = 2 * plane.nodes
    c = np.maximum(K.diagonal()[rdof], 1e-300)
    z = -c * (u_free[rdof] - after.u_r_stick_m)
    slides = new & (np.abs(z) > plane.friction_bound(lin))
    slip = np.where(slides, -np.sign(z), after.slip).astype(np.int8)
    return ContactState(after.active, after.u_r_stick_m, slip)


FREEZE = 6      # switches of a node's stick/slide status in one load step before it is held stuck


def sliding_coupling(plane: RigidPlane, state: ContactState, res: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(radial dofs, normal dofs, mu s) of the sliding nodes that carry friction (lambda > 0),
    or None if there are none."""
    if plane.law != "coulomb" or plane.friction == 0.0:
        return None
    k = np.flatnonzero(state.active & (state.slip != 0) & (plane.reactions(res) > 0.0))
    if k.size == 0:
        return None
    rdofs = 2 * plane.nodes[k]
    return rdofs, rdofs + 1, plane.friction * state.slip[k].astype(float)


class CoupledFactor:
    """Solves with K_ff + U V^T (module docstring) through a factor of K_ff, by Woodbury:
    x = y - Y (I + V^T Y)^-1 V^T y, with y the base solution and Y = K_ff^-1 U. The same
    interface as the base factor (`solve(rhs, du_fixed)`, `freeing(dofs)`); V^T acts on the whole
    x, the prescribed part included, since lambda moves with every dof."""

    def __init__(self, base, K: sp.csr_matrix, coupling: tuple[np.ndarray, np.ndarray, np.ndarray]):
        self.base, self.K, self.coupling = base, K, coupling
        rdofs, _, _ = coupling
        U = np.zeros((K.shape[0], len(rdofs)))
        U[rdofs, np.arange(len(rdofs))] = 1.0
        self.Y = base.solve(U)
        self.capacitance = np.eye(len(rdofs)) + self._V(self.Y)

    def _V(self, x: np.ndarray) -> np.ndarray:
        _, zdofs, coef = self.coupling
        Kx = self.K @ x
        return (coef[:, None] * Kx[zdofs]) if x.ndim == 2 else coef * Kx[zdofs]

    def solve(self, rhs: np.ndarray, du_fixed: np.ndarray | None = None) -> np.ndarray:
        y = self.base.solve(rhs, du_fixed)
        return y - self.Y @ np.linalg.solve(self.capacitance, self._V(y))

    def freeing(self, dofs: np.ndarray) -> "CoupledFactor":
        return CoupledFactor(self.base.freeing(dofs), self.K, self.coupling)
