"""Coulomb friction in the Newton iteration: the linearized frictional contact problem, solved exactly.

The law and its state live in `fem.contact` (`RigidPlane`: held nodes, anchors, slip directions).
Every Newton iteration of a load step (`fem.newton`) minimizes the quadratic model of the energy
subject to the linearized contact and friction conditions at the candidate nodes a:

    normal:      g_a + du_z,a >= 0,  lambda_a >= 0,  lambda_a (g_a + du_z,a) = 0
    tangential:  |t_a| <= mu lambda_a;  t_a = -mu lambda_a sign(Delta_a) where Delta_a != 0

with lambda_a, t_a the reactions the step predicts (r - f_ext + K du at the node's z-, r-dof) and
Delta_a = u_r,a + du_r,a - anchor_a the slip in the load step (backward Euler). The rest of the
body is condensed onto the contact dofs with the Cholesky factor of K_ff (`fem.friction_condensed`), and the
small non-smooth system is solved by a semismooth Newton method on Alart and Curnier's
complementarity functions (P. Alart, A. Curnier, CMAME 92 (1991) 353; in the primal-dual active
set form of S. Hueber, G. Stadler, B. Wohlmuth, SIAM J. Sci. Comput. 30 (2008) 572):

    lambda = max(0, lambda - c_n (g + du_z)),     t = proj_[-mu lh, mu lh](t - c_t Delta),
    lh = max(0, lambda - c_n (g + du_z)),

i.e. node a is pressed where lh > 0, sticks (Delta = 0) where |t - c_t Delta| <= mu lh, and slides
(t = -mu lambda s, s = -sign(t - c_t Delta)) otherwise. Each active-set guess is one linear solve
of the condensed system; the coupling of a sliding node's friction to its normal reaction (Coulomb's
law is not associated, the matrix is not symmetric) is in it exactly, so the outer Newton iteration
keeps its quadratic rate and the stick/slide set is decided with the displacement instead of
between iterations, where it cycled (docs/fem.md, solver notes).

The augmentation c > 0 (here the node's diagonal stiffness) cannot change a converged state: at a
zero of the complementarity functions the conditions above hold for any c. In this form it does
not even change the iterates: every set is judged at the solution of the previous guess, which
satisfies one branch's equation exactly (a pressed node g + du_z = 0, so lh = lambda; a free one
lambda = 0, so only the sign of the gap counts; a stuck one Delta = 0, so the test is |t| <= mu
lambda; a sliding one |t| = mu lambda, so only the direction of Delta counts, and a reversing
slide sticks first). Runs with c x 1e-3 and x 1e3 take the same iterations to the same digits
(coarse cup A, mu = 3); so c is not a parameter.
"""

from __future__ import annotations

import numpy as np

from .contact import ContactState, RigidPlane
from .friction_condensed import CondensedProblem

__all__ = ["FrictionStep"]


class FrictionStep:
    """The Newton step of one iterate for Coulomb contact (the interface of `fem.contact_step.ContactStep`).

    The base factor holds every node held at the iterate (z and r) and the prescribed dofs; the
    condensed problem then decides, in one iteration, which nodes are pressed, released, stuck or
    sliding, and the free nodes the step pushes through the plane join it (their touchdown is
    anchored by `RigidPlane.hold` after the line search; they slide or stick from the next
    iteration on). `settled`: the condensed problem converged and kept the iterate's sets, the
    condition for accepting the iterate as converged (with the residual and the correction)."""

    coupled = True      # the line search may accept it by a fall of the residual (not symmetric)

    def __init__(self, plane: RigidPlane, state: ContactState, u, res, free, du_fixed, tol,
                 factor, friction):
        self.plane, self.old, self.u, self.free, self.tol = plane, state, u, free, tol
        self.res0 = res + friction           # r - f_ext without the friction forces
        self.du_fixed, self.factor, self.friction = du_fixed, factor, friction
        self.state, self.settled, self.solvable = state, False, True

    def solve(self, solver, K, shift, history, policy, lower=True) -> float:
        """Factor the base block (`factor`: `fem.factorization.factor_shifted`, shifted if not positive
        definite), solve the condensed problem, add the free nodes the step penetrates until none
        does. Returns the shift used."""
        plane, old = self.plane, self.old
        held = np.flatnonzero(old.active)
        rd = 2 * plane.nodes
        base_free = self.free.copy()
        base_free[rd[held]] = base_free[rd[held] + 1] = False
        fac, shift = self.factor(solver, K, base_free, shift, history, policy, lower)
        du_fixed = np.where(base_free, 0.0, self.du_fixed)
        du_fixed[rd[held]] = du_fixed[rd[held] + 1] = 0.0      # the condensed problem moves them
        sub = CondensedProblem(plane, old, self.u, self.res0, K, fac, fac.solve(-self.res0, du_fixed),
                         held, self.tol)
        g, flight = plane.gap(self.u), None
        for _ in range(20):
            sub.ssn()
            du = sub.du()
            if flight is None:      # the free flight of the nodes not yet held (their touchdown)
                flight = du.copy()
            outside = np.ones(len(g), bool)
            outside[sub.nodes] = False
            new = np.flatnonzero(outside & (g + du[rd + 1] < 0.0))
            if len(new) == 0:
                break
            flight[rd[new]], flight[rd[new] + 1] = du[rd[new]], du[rd[new] + 1]
            sub.add(new)
        self.du, self.du0 = du, flight
        self._outcome(sub)
        return shift

    def _outcome(self, sub: CondensedProblem) -> None:
        old, n, nh = self.old, len(self.old.active), len(sub.held)
        pressed = np.zeros(n, bool)
        pressed[sub.nodes] = sub.An
        self.release = old.active & ~pressed
        self.pressed = pressed & ~old.active
        slip = np.zeros(n, np.int8)
        slip[sub.held] = np.where(sub.An[:nh], sub.slip, 0)
        keep = old.active & ~self.release
        self.state = ContactState(keep, old.u_r_stick_m, np.where(keep, slip, 0).astype(np.int8))
        self.solvable = sub.converged
        self.settled = sub.converged and not self.release.any() and not self.pressed.any() \
            and np.array_equal(self.state.slip, old.slip)

    def holds(self, alpha: float) -> np.ndarray:
        """The held set after a step of length alpha: the nodes pressed anew only after a full
        step (a shorter one does not reach the plane)."""
        return self.state.active | (self.pressed if alpha >= 1.0 else False)

    def reduces_residual(self, r_trial: np.ndarray, fext0: np.ndarray, alpha: float) -> bool:
        """The merit test of a step that need not descend in the energy: the free residual of
        the new sets, friction included, falls by 1e-4 alpha of the iterate's; or the full step
        presses a node onto the plane. That changes the sets and, at the rim, the cavity's chain
        (the suction reaches the faces beyond the last contact): the residual jumps there, and
        refused, the iterations crept to the plane by a tenth of the way each."""
        if alpha >= 1.0 and self.pressed.any():
            return True
        base = r_trial - fext0
        res = base - self.plane.law.friction_force(self.plane, self.state, base)
        free = self.free.copy()
        free[self.plane.constraints(self.state)[0]] = False
        now = (self.res0 - self.friction)[self.free]
        return bool(np.linalg.norm(res[free]) <= (1.0 - 1e-4 * alpha) * np.linalg.norm(now))
