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


class FrictionStep:
    """The Newton step of one iterate for Coulomb contact (the interface of `fem.solver._Step`):
    the quadratic model of the energy minimized on the free dofs subject to the linearized
    frictional contact conditions, solved exactly on the contact dofs (module docstring)."""

    coupled = True      # the line search may accept it by a fall of the residual

    def __init__(self, plane, state, u, res, free, du_fixed, tol, factor, friction):
        self.plane, self.old, self.u, self.free, self.tol = plane, state, u, free, tol
        self.res0 = res + friction           # r - f_ext without the friction forces
        self.du_fixed, self.factor, self.friction = du_fixed, factor, friction
        self.state, self.settled = state, False

    def solve(self, solver, K, shift, history, policy, lower=True) -> float:
        plane, old = self.plane, self.old
        nodes = np.flatnonzero(old.active)
        rd = 2 * plane.nodes
        base_free = self.free.copy()
        base_free[rd[nodes]] = False
        base_free[rd[nodes] + 1] = False
        fac, shift = self.factor(solver, K, base_free, shift, history, policy, lower)
        du_fixed = np.where(base_free, 0.0, self.du_fixed)
        du_fixed[rd[nodes]] = du_fixed[rd[nodes] + 1] = 0.0
        du0 = fac.solve(-self.res0, du_fixed)
        g = plane.gap(self.u)
        sub = _Condensed(plane, old, self.u, self.res0, K, fac, du0, nodes, self.tol)
        flight = None
        for _ in range(20):
            sub.ssn()
            du = sub.du()
            if flight is None:
                flight = du.copy()
            out = np.ones(len(g), bool)
            out[sub.cand] = False
            new = np.flatnonzero(out & (g + du[rd + 1] < 0.0))
            if len(new) == 0:
                break
            flight[rd[new]], flight[rd[new] + 1] = du[rd[new]], du[rd[new] + 1]
            sub.add(new)
        self.du, self.du0 = du, flight
        self._sub = sub
        self._outcome(sub)
        return shift

    def _outcome(self, sub) -> None:
        old, n = self.old, len(self.old.active)
        An = np.zeros(n, bool)
        An[sub.cand] = sub.An
        self.release = old.active & ~An
        self.pressed = An & ~old.active
        slip = np.zeros(n, np.int8)
        slip[sub.cand[: len(sub.rnodes)]] = np.where(sub.An[: len(sub.rnodes)], sub.slip, 0)
        keep = old.active & ~self.release
        self.state = ContactState(keep, old.u_r_stick_m, np.where(keep, slip, 0).astype(np.int8))
        self.settled = sub.converged and not self.release.any() and not self.pressed.any() \
            and np.array_equal(self.state.slip, old.slip)

    def holds(self, alpha: float) -> np.ndarray:
        active = self.state.active.copy()
        if alpha >= 1.0:
            active |= self.pressed
        return active

    def reduces_residual(self, r_trial: np.ndarray, fext0: np.ndarray, alpha: float) -> bool:
        base = r_trial - fext0
        res = base - self.plane.friction_force(self.state, base)
        free = self.free.copy()
        dofs, _ = self.plane.constraints(self.state)
        free[dofs] = False
        old = self.res0 - self.friction
        return bool(np.linalg.norm(res[free]) <= (1.0 - 1e-4 * alpha) * np.linalg.norm(old[self.free]))


class _Condensed:
    """The linearized frictional contact problem on the contact dofs C, the rest of the body
    condensed. C: the z- and r-dofs of the nodes held at the start of the iteration (constrained
    in the base factor: their unknowns are displacement increments) and the z-dofs of the free
    nodes the step would push through the plane (free in it: their unknowns are the contact
    forces). With the base step du0 and the columns Z (the response to a unit increment or a unit
    force), du = du0 + Z y and the reactions at C are f = q + F y. Solved by a semismooth Newton
    (primal-dual active set) method on Alart and Curnier's complementarity functions."""

    def __init__(self, plane, old, u, res0, K, fac, du0, nodes, tol):
        self.plane, self.K, self.fac, self.du0, self.tol = plane, K, fac, du0, tol
        self.mu, self.n = plane.friction, len(u)
        rd = 2 * plane.nodes
        self.rnodes, self.cand = nodes, nodes.copy()
        self.An = np.ones(len(nodes), bool)
        self.slip = old.slip[nodes].astype(np.int8)
        self.g_all = plane.gap(u)
        self.d0 = u[rd[nodes]] - old.u_r_stick_m[nodes]
        self.res0 = res0
        self.rows = np.zeros(0, int)
        self.Z = np.zeros((self.n, 0))
        self.force = np.zeros(0, bool)
        self._columns(np.concatenate([rd[nodes] + 1, rd[nodes]]), force=False)
        self.converged = False

    def _columns(self, dofs, force):
        if len(dofs) == 0:
            return
        E = np.zeros((self.n, len(dofs)))
        E[dofs, np.arange(len(dofs))] = 1.0
        if force:
            Z = self.fac.solve(E)
        else:
            Z = self.fac.solve(-(self.K @ E))
            Z[dofs, np.arange(len(dofs))] = 1.0
        self.Z = np.hstack([self.Z, Z])
        self.rows = np.concatenate([self.rows, dofs])
        self.force = np.concatenate([self.force, np.full(len(dofs), force)])

    def add(self, new):
        self._columns(2 * self.plane.nodes[new] + 1, force=True)
        self.cand = np.concatenate([self.cand, new])
        self.An = np.concatenate([self.An, np.ones(len(new), bool)])

    def du(self):
        return self.du0 + self.Z @ self.y

    def ssn(self, maxit=30):
        if len(self.rows) == 0:
            self.y, self.converged = np.zeros(0), True
            return
        F = (self.K @ self.Z)[self.rows]
        D = self.Z[self.rows]
        q = (self.res0 + self.K @ self.du0)[self.rows]
        w0 = self.du0[self.rows]
        c = np.where(self.force, 1.0 / np.maximum(np.abs(np.diag(D)), 1e-300), np.abs(np.diag(F)))
        nc, nr = len(self.cand), len(self.rnodes)
        # row order: z of the nr held nodes, r of the held nodes, z of later candidates
        iz = np.concatenate([np.arange(nr), 2 * nr + np.arange(nc - nr)])
        ir = nr + np.arange(nr)
        g, mu = self.g_all[self.cand], self.mu
        An, slip = self.An.copy(), self.slip.copy()
        p = len(self.rows)
        self.converged = False
        for _ in range(maxit):
            A, b = F.copy(), -q.copy()          # default rows: reaction = 0 (free of the plane)
            on = iz[An]
            A[on], b[on] = D[on], -g[An] - w0[on]
            Ar = An[:nr]
            stick = ir[Ar & (slip == 0)]
            A[stick], b[stick] = D[stick], -self.d0[Ar & (slip == 0)] - w0[stick]
            sl = Ar & (slip != 0)
            k = -mu * slip[sl]                   # f_r = -mu slip f_z
            A[ir[sl]] = F[ir[sl]] - k[:, None] * F[iz[:nr][sl]]
            b[ir[sl]] = -(q[ir[sl]] - k * q[iz[:nr][sl]])
            y = np.linalg.solve(A, b)
            f, w = q + F @ y, w0 + D @ y
            lam_hat = f[iz] - c[iz] * (g + w[iz])
            An_new = lam_hat > np.where(An, -self.tol, self.tol)
            zeta = f[ir] - c[ir] * (self.d0 + w[ir])
            bound = mu * np.maximum(lam_hat[:nr], 0.0)
            hyst = np.where(slip == 0, self.tol, -self.tol)
            slip_new = np.where(np.abs(zeta) <= bound + hyst, 0, -np.sign(zeta)).astype(np.int8)
            slip_new[(slip != 0) & (slip_new == -slip)] = 0      # a reversing slide sticks first
            slip_new = np.where(An_new[:nr], slip_new, 0).astype(np.int8)
            self.y, self.An, self.slip, self.f = y, An, slip, f
            if np.array_equal(An_new, An) and np.array_equal(slip_new[An[:nr]], slip[An[:nr]]):
                self.converged = True
                break
            An, slip = An_new, slip_new
