"""Weak forms of axisymmetric finite-strain hyperelasticity, and their fast element kernels.

The total potential energy of the body (no body forces) is Pi(u) = int_Omega0 W(F(u)) dV with
dV = 2 pi R dA. Its first and second variations are

    r(u; v)     = int P(F) : dF[v] dV                        (internal force)
    K(u; v, du) = int dF[v] : A(F) : dF[du] dV               (consistent tangent)

with dF[v] = d f / d u . v (see `fem.kinematics`). The readable scikit-fem forms
`internal_force_form` and `tangent_form` are the reference; `Mechanics` evaluates the same
integrals as batched matrix products of the precomputed B-operator (two per assembly instead of
18 x 18 form calls per element), and the tests check that both agree.

Mixed (nearly incompressible) formulation, ``material.formulation == "mixed"``: the volumetric
energy U = lambda/2 (ln J)^2 is evaluated on Theta = Pi_h J, the L2(dV) projection of J onto
discontinuous linear polynomials {1, R - R_e, Z - Z_e} per element (Q2-P1disc, the three-field
Hu-Washizu form with condensed pressure p = Pi_h U'(Theta) and dilatation Theta). Then

    r_vol = int p dJ[v] dV,
    K_vol = int p d2J[v, du] dV + G^T M^-1 D M^-1 G,

with G_a[v] = int q_a dJ[v] dV, M_ab = int q_a q_b dV, D_ab = int U''(Theta) q_a q_b dV per element.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
from skfem import BilinearForm, LinearForm, MeshQuad2

from .kinematics import IDENTITY, Kinematics
from .material import (NeoHookean, jacobian, jacobian_gradient, jacobian_hessian, jacobian_minus_one,
                       tangent_points_first)

__all__ = ["Mechanics", "internal_force_form", "tangent_form", "energy_form"]


# --------------------------------------------------------------------------------------------
# Reference weak forms (displacement formulation), plain scikit-fem: they read like the math.
# --------------------------------------------------------------------------------------------
def _f(w_u, R):
    """5-vector f = (F_rR, F_rZ, F_zR, F_zZ, F_tt) of a vector field at the points."""
    g, v = w_u.grad, np.asarray(w_u)
    return np.stack([1.0 + g[0, 0], g[0, 1], g[1, 0], 1.0 + g[1, 1], 1.0 + v[0] / R])


def _df(v, R):
    """Variation dF[v] as a 5-vector."""
    g, val = v.grad, np.asarray(v)
    return np.stack([g[0, 0], g[0, 1], g[1, 0], g[1, 1], val[0] / R])


def internal_force_form(material: NeoHookean) -> LinearForm:
    """r(u; v) = int P(F(u)) : dF[v] 2 pi R dA, with u passed as ``w['u']``."""

    @LinearForm
    def internal_force(v, w):
        R = w.x[0]
        P = material.stress(_f(w["u"], R))
        return np.sum(P * _df(v, R), axis=0) * 2.0 * np.pi * R

    return internal_force


def tangent_form(material: NeoHookean) -> BilinearForm:
    """K(u; v, du) = int dF[v] : A(F(u)) : dF[du] 2 pi R dA."""

    @BilinearForm
    def tangent(du, v, w):
        R = w.x[0]
        A = material.tangent(_f(w["u"], R))
        return np.einsum("k...,kl...,l...->...", _df(v, R), A, _df(du, R)) * 2.0 * np.pi * R

    return tangent


def energy_form(material: NeoHookean) -> "skfem.Functional":
    """Pi(u) = int W(F(u)) 2 pi R dA as a scikit-fem Functional."""
    from skfem import Functional

    @Functional
    def energy(w):
        R = w.x[0]
        return material.energy(_f(w["u"], R)) * 2.0 * np.pi * R

    return energy


# --------------------------------------------------------------------------------------------
# Vectorized kernels with a reused sparsity pattern.
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Mechanics:
    """Energy, internal force and tangent of one body: kinematics + material."""

    kin: Kinematics
    material: NeoHookean

    # --- sparsity pattern, computed once ---------------------------------------------------
    @cached_property
    def _pattern(self):
        d = self.kin.dofs                                  # [18, nel]
        n = self.kin.ndofs
        rows = np.broadcast_to(d.T[:, :, None], (d.shape[1], d.shape[0], d.shape[0])).ravel()
        cols = np.broadcast_to(d.T[:, None, :], (d.shape[1], d.shape[0], d.shape[0])).ravel()
        # the pattern by scipy's COO -> CSR (sorted, duplicates summed), then each element
        # entry's position in it by binary search on the (row, column) keys
        pattern = sp.csr_matrix((np.ones(rows.size, np.int8), (rows, cols)), shape=(n, n))
        pattern.sum_duplicates()
        indptr, indices = pattern.indptr, pattern.indices
        keys = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr)) * n + indices
        inverse = np.searchsorted(keys, rows.astype(np.int64) * n + cols)
        return inverse, indices.astype(np.int32), indptr.astype(np.int32), len(indices)

    def _matrix(self, Ke: np.ndarray) -> sp.csr_matrix:
        inverse, indices, indptr, nnz = self._pattern
        data = np.bincount(inverse, weights=Ke.ravel(), minlength=nnz)
        n = self.kin.ndofs
        return sp.csr_matrix((data, indices, indptr), shape=(n, n))

    def _vector(self, re: np.ndarray) -> np.ndarray:
        """Assemble element vectors re[nel, 18]."""
        return np.bincount(self.kin.dofs.T.ravel(), weights=re.ravel(), minlength=self.kin.ndofs)

    @property
    def _B(self) -> np.ndarray:
        """B, the linearized deformation gradient per dof, stacked over the points: [nel, nq * 5, 18]
        (`Kinematics.B_stacked`)."""
        return self.kin.B_stacked

    @cached_property
    def _BT(self) -> np.ndarray:
        """B^T as [nel, 18, nq * 5] (contiguous), the left factor of K_e."""
        return np.ascontiguousarray(np.transpose(self._B, (0, 2, 1)))

    def _element_forces(self, PdV: np.ndarray) -> np.ndarray:
        """r_e,i = sum_q B_iq . P_q dV_q for P dV [5, nel, nq]: [nel, 18]."""
        ne, nq = PdV.shape[1:]
        return (np.transpose(PdV, (1, 2, 0)).reshape(ne, 1, nq * 5) @ self._B)[:, 0]

    def _element_tangents(self, AdV: np.ndarray) -> np.ndarray:
        """K_e = sum_q B_q^T (A_q dV_q) B_q for A dV [nel, nq, 5, 5]: [nel, 18, 18], as two
        batched products (the 5 x 5 blocks with B^T per point, then B over all points)."""
        ne, nq = AdV.shape[:2]
        nb = self._B.shape[2]
        C = np.ascontiguousarray(AdV) @ self._B.reshape(ne, nq, 5, nb)
        return self._BT @ C.reshape(ne, nq * 5, nb)

    # --- P1disc projection for the mixed formulation ---------------------------------------
    @cached_property
    def _p1(self):
        """q[a, e, q] = {1, (R - R_e)/h_e, (Z - Z_e)/h_e} (quads: Q2-P1disc) or {1} (triangles:
        P2-P0, as P2-P1disc is not inf-sup stable) and the inverse Gram matrices M^-1 [nel, n, n]."""
        X = np.asarray(self.kin.basis.global_coordinates())       # [2, nel, nq]
        dV = self.kin.dV
        vol = dV.sum(axis=1)
        c = np.einsum("deq,eq->de", X, dV) / vol
        h = np.sqrt(self.kin.basis.dx.sum(axis=1))
        q = [np.ones_like(dV)]
        if isinstance(self.kin.mesh, MeshQuad2):
            q += [(X[0] - c[0][:, None]) / h[:, None], (X[1] - c[1][:, None]) / h[:, None]]
        q = np.stack(q)
        M = np.einsum("aeq,beq,eq->eab", q, q, dV)
        return q, np.linalg.inv(M)

    def project(self, values: np.ndarray) -> np.ndarray:
        """L2(dV) projection of quadrature-point values [nel, nq] onto P1disc, evaluated at the points."""
        q, Minv = self._p1
        coef = np.einsum("eab,beq,eq->ea", Minv, q, values * self.kin.dV)
        return np.einsum("ea,aeq->eq", coef, q)

    # --- the three quantities -------------------------------------------------------------
    def pressure_and_dilatation(self, f: np.ndarray, h: np.ndarray | None = None
                                ) -> tuple[np.ndarray, np.ndarray]:
        """For the mixed form: Theta = Pi_h J, p = Pi_h U'(Theta) at the points (h = f - 1 if known)."""
        # project J - 1 rather than J: the projection of the constant 1 carries round-off that
        # lambda would amplify into a spurious pressure (~1e-6 Pa at nu = 0.49)
        dtheta = self.project(jacobian(f) - 1.0 if h is None else jacobian_minus_one(h))
        if np.any(dtheta <= -1.0):
            raise FloatingPointError("projected dilatation Theta <= 0 (inverted element)")
        theta = 1.0 + dtheta
        return theta, self.project(self.material.volumetric(theta, np.log1p(dtheta))[1])

    def energy(self, u: np.ndarray) -> float:
        """Stored elastic energy Pi(u) [J] (the last `evaluate`'s if u is the same)."""
        last = self._last
        if "u" in last and np.array_equal(last["u"], u):
            return last["out"][0]
        h = self.kin.displacement_gradient(u)
        f = IDENTITY[:, None, None] + h
        m = self.material
        if m.formulation == "displacement":
            W = m.energy(f, h)
        else:
            theta, _ = self.pressure_and_dilatation(f, h)
            W = m.isochoric_energy(h) + m.volumetric(theta, np.log1p(theta - 1.0))[0]
        return float(np.sum(W * self.kin.dV))

    def stress(self, f: np.ndarray) -> np.ndarray:
        """First Piola-Kirchhoff stress P [5, nel, nq] (with the condensed pressure if mixed)."""
        m = self.material
        if m.formulation == "displacement":
            return m.stress(f)
        _, p = self.pressure_and_dilatation(f)
        return m.isochoric(f)[1] + p * jacobian_gradient(f)

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        """r(u) = dPi/du, the assembled internal force vector [N]."""
        f = self.kin.deformation_gradient(u)
        if np.any(jacobian(f) <= 0):
            raise FloatingPointError("J <= 0 at a quadrature point (inverted element)")
        return self._vector(self._element_forces(self.stress(f) * self.kin.dV))

    def linearize(self, u: np.ndarray) -> tuple[np.ndarray, sp.csr_matrix]:
        """Internal force r(u) and consistent tangent K(u) = d2Pi/du2."""
        return self.evaluate(u)[1:]

    @cached_property
    def _last(self) -> dict:
        """The last evaluation (u and its results): a path solver evaluates the converged state
        of a load step and then starts the next step from it."""
        return {}

    def evaluate(self, u: np.ndarray) -> tuple[float, np.ndarray, sp.csr_matrix]:
        """Stored energy Pi(u) [J], internal force r(u) and tangent K(u), from one evaluation of F
        (the previous call's results if u is the same; r and K's data are read-only)."""
        last = self._last
        if "u" in last and np.array_equal(last["u"], u):
            return last["out"]
        out = self._evaluate(u)
        out[1].flags.writeable = out[2].data.flags.writeable = False     # shared with the memo
        last.update(u=np.array(u, copy=True), out=out)
        return out

    def _evaluate(self, u: np.ndarray) -> tuple[float, np.ndarray, sp.csr_matrix]:
        h = self.kin.displacement_gradient(u)
        f = IDENTITY[:, None, None] + h
        J = jacobian(f)
        if np.any(J <= 0):
            raise FloatingPointError("J <= 0 at a quadrature point (inverted element)")
        m, dV = self.material, self.kin.dV
        g = jacobian_gradient(f)
        if m.formulation == "displacement":
            lnJ = np.log1p(jacobian_minus_one(h))
            W = m.isochoric_energy(h) + m.volumetric(J, lnJ)[0]
            a, b = m.tangent_coefficients(J, lnJ)
            P = m.stress_with(f, g, b)
            AdV = tangent_points_first(f, g, m.mu * dV, a * dV, b * dV)
        else:
            theta, p = self.pressure_and_dilatation(f, h)
            W, P, A = m.isochoric(f, h)
            W = W + m.volumetric(theta, np.log1p(theta - 1.0))[0]
            P = P + p * g
            AdV = np.transpose((A + p * jacobian_hessian(f)) * dV, (2, 3, 0, 1))
        re = self._element_forces(P * dV)
        Ke = self._element_tangents(AdV)
        if m.formulation == "mixed":
            q, Minv = self._p1
            d2U = m.volumetric(theta, np.log1p(theta - 1.0))[2]
            ne, nq = dV.shape
            dJ = np.einsum("keq,eqki->eqi", g * dV, self._B.reshape(ne, nq, 5, -1))  # dJ[v] dV
            G = np.einsum("aeq,eqi->eai", q, dJ)                     # [nel, 3, 18]
            D = np.einsum("aeq,beq,eq->eab", q, q, d2U * dV)
            C = Minv @ D @ Minv
            Ke += np.einsum("eai,eab,ebj->eij", G, C, G)
        return float(np.sum(W * dV)), self._vector(re), self._matrix(Ke)
