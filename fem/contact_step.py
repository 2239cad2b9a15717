"""The Newton step with frictionless or sticking contact: a quadratic model minimized under g >= 0.

The quadratic model of the energy is minimized on the free dofs (prescribed and held contact
dofs eliminated, K_ff factored once) subject to the linearized contact conditions
g_a + du_z,a >= 0 of the free nodes the unconstrained step would push through the plane, and of
the held nodes whose linearized reaction lambda_a + (K du)_z,a would turn tensile. With the
columns K_ff^-1 e_a of those m nodes this is the small LCP lambda >= 0, w = q + S lambda >= 0,
lambda . w = 0 (S = E^T K_ff^-1 E), solved exactly by non-negative least squares (`lcp`), so the
whole contact front moves in one iteration. Nodes pressed (lambda > 0) are held afterwards; held
nodes the LCP lets go are released. Coulomb's step is `fem.friction.FrictionStep`.
"""

from __future__ import annotations

import numpy as np

from .factorization import factor_shifted
from .linsolve import NotPositiveDefinite
from .nnls import nnls

__all__ = ["ContactStep", "lcp"]


class ContactStep:
    """The Newton step of one iterate (module docstring); without a plane, the plain Newton step.
    After `solve`: du (the step), du0 (the unconstrained step: the nodes' free flight), the QP's
    nodes and reactions, and the held nodes it releases."""

    coupled = False     # accepted by the energy only (`fem.friction.FrictionStep`: also the residual)

    def __init__(self, plane, state, u, res, free, du_fixed, tol):
        self.plane, self.state, self.u, self.res, self.du_fixed = plane, state, u, res, du_fixed
        self.free, self.tol = free, tol

    def solve(self, solver, K, shift, history, policy, lower=True) -> float:
        """Factor (with a diagonal shift if K_ff is not positive definite), solve, and add
        contact constraints until no free candidate penetrates; then let the held nodes the
        step would pull on take part. `shift`: the last one used (tried smaller first,
        `fem.factorization.factor_shifted`), or with `lower` False the one to try first.
        Returns the shift used."""
        fac, shift = factor_shifted(solver, K, self.free, shift, history, policy, lower)
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
                fac, shift = factor_shifted(solver, K, free, shift, history, policy, lower=False)
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
            self.lam = lcp(0.5 * (S + S.T), g[self.qp] + du0[zdof[self.qp]])
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


def lcp(S, q):
    """lambda >= 0 with w = q + S lambda >= 0 and lambda . w = 0 (S symmetric positive definite):
    the minimizer of lambda S lambda / 2 + q . lambda over lambda >= 0, by non-negative least
    squares on the Cholesky factor S = L L^T (Lawson-Hanson, finite)."""
    scale = np.sqrt(np.diag(S))
    Sn = S / np.outer(scale, scale)
    L = np.linalg.cholesky(Sn)
    y = np.linalg.solve(L, q / scale)
    x = nnls(L.T, -y)
    return x / scale
