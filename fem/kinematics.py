"""Total-Lagrangian axisymmetric kinematics on quadratic elements.

A point at (R, Z) of the reference half-plane moves by u = (u_r, u_z). The deformation gradient is

    F = [[1 + u_r,R,  u_r,Z,      0      ],
         [u_z,R,      1 + u_z,Z,  0      ],
         [0,          0,          1 + u_r/R]]

and the reference volume element is dV = 2 pi R dA. F is affine in u, so with the 5-vector
f = (F_rR, F_rZ, F_zR, F_zZ, F_tt) we precompute, once per mesh, the strain-displacement operator
B[i, k, e, q] = d f_k / d u_i for local dof i of element e at quadrature point q, and then
f = 1 + sum_i B_i u_i. The element kernels in `fem.forms` are contractions of B with the material.

Elements: 9-node biquadratic quadrilaterals (scikit-fem ``ElementQuad2`` on ``MeshQuad2``),
isoparametric: the cup's cross-section is a thin, structured strip, where Q2 bends without shear
locking and maps curved edges exactly; 3x3 Gauss points (``intorder=4``) integrate the stiffness.
6-node triangles (``ElementTriP2`` on ``MeshTri2``) are accepted for users' unstructured meshes.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from skfem import Basis, ElementQuad2, ElementTriP2, ElementVector, Mesh, MeshQuad2, MeshTri2

__all__ = ["Kinematics", "IDENTITY"]

#: f of the undeformed state
IDENTITY = np.array([1.0, 0.0, 0.0, 1.0, 1.0])


@dataclass(frozen=True, eq=False)
class Kinematics:
    """Per-mesh precomputed quantities: basis, B-operator, quadrature weights dV = 2 pi R dA."""

    basis: Basis

    @classmethod
    def of(cls, mesh: Mesh, intorder: int = 4) -> "Kinematics":
        if not isinstance(mesh, (MeshQuad2, MeshTri2)):
            raise ValueError("mesh: a quadratic mesh (skfem.MeshQuad2 or MeshTri2) is required, "
                             f"got {type(mesh).__name__}")
        if np.min(mesh.doflocs[0]) < -1e-12 * np.ptp(mesh.doflocs[0]):
            raise ValueError("mesh: the axisymmetric cross-section must lie in R >= 0 (x = r, y = z)")
        element = ElementQuad2() if isinstance(mesh, MeshQuad2) else ElementTriP2()
        return cls(Basis(mesh, ElementVector(element), intorder=intorder))

    @property
    def mesh(self) -> Mesh:
        return self.basis.mesh

    @property
    def ndofs(self) -> int:
        return self.basis.N

    @property
    def dofs(self) -> np.ndarray:
        """Global dof of local dof i in element e, [18 or 12, nel]. Dof 2n + c is component c of node n."""
        return self.basis.element_dofs

    @cached_property
    def R(self) -> np.ndarray:
        """Reference radius at the quadrature points [nel, nq]."""
        return np.asarray(self.basis.global_coordinates())[0]

    @cached_property
    def dV(self) -> np.ndarray:
        """Reference volume weight 2 pi R |dX/dxi| w at the quadrature points [nel, nq]."""
        return 2.0 * np.pi * self.R * self.basis.dx

    @cached_property
    def B(self) -> np.ndarray:
        """d f_k / d u_i as [ndofs_per_element, 5, nel, nq]."""
        out = np.zeros((self.basis.Nbfun, 5) + self.R.shape)
        for i, (phi,) in enumerate(self.basis.basis):
            grad, value = phi.grad, np.asarray(phi)
            out[i, 0:2] = grad[0]           # F_rR, F_rZ from u_r
            out[i, 2:4] = grad[1]           # F_zR, F_zZ from u_z
            out[i, 4] = value[0] / self.R   # hoop stretch from u_r / R
        return out

    @cached_property
    def B_stacked(self) -> np.ndarray:
        """B as [nel, nq * 5, ndofs_per_element], row (q, k) = d f_k / d u at point q (contiguous,
        the layout of the batched products in `displacement_gradient` and `fem.forms`)."""
        nb, _, ne, nq = self.B.shape
        return np.ascontiguousarray(np.transpose(self.B, (2, 3, 1, 0)).reshape(ne, nq * 5, nb))

    def local(self, u: np.ndarray) -> np.ndarray:
        """Element dof values [18, nel] of a global vector u."""
        return u[self.dofs]

    def deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """f(u) at the quadrature points, [5, nel, nq]."""
        return IDENTITY[:, None, None] + self.displacement_gradient(u)

    def displacement_gradient(self, u: np.ndarray) -> np.ndarray:
        """h(u) = f(u) - 1 at the quadrature points, [5, nel, nq] (exact for small u, unlike f - 1)."""
        ne, nq = self.R.shape
        hq = self.B_stacked @ self.local(u).T[:, :, None]          # [nel, nq * 5, 1]
        return np.ascontiguousarray(np.transpose(hq.reshape(ne, nq, 5), (2, 0, 1)))

    def node_coordinates(self) -> np.ndarray:
        """Reference coordinates of the mesh nodes [2, nnodes] (node n carries dofs 2n, 2n+1)."""
        return self.mesh.doflocs
