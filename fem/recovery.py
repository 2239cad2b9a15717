"""Nodal fields for pictures: Gauss-point quantities and the contact pressure recovered to the nodes.

The solver knows the stress and the stretches at the 3x3 Gauss points of each element, and the
contact pressure as nodal reactions; a colour map over the mesh needs one value per node.

* Volume fields (von Mises stress, smallest principal stretch) are recovered by the **L2
  projection** onto the continuous Q2 (P2) nodal space of the mesh with the axisymmetric weight
  dV = 2 pi R dA: M x = b, M_ab = int N_a N_b dV, b_a = int N_a q dV, both by the Gauss rule the
  solver uses. It is the best fit in the space the picture interpolates in, continuous by
  construction, exact for any field in that space (a quadratic in R and Z: tested), and it keeps
  the field's volume integral. Nodal averaging of element means would smear a gradient over an
  element and is not exact even for a linear field; the projection can overshoot by a few per cent
  next to a singular point (the rim corner), which a picture tolerates.
* The contact pressure is recovered by **nodal averaging of a force-conserving facet mean**. The
  lumped nodal pressure p_a = lambda_a / int N_a dA (`fem.contact`) alternates between the vertex
  and the midpoint node of a quadratic facet (node-to-plane contact loads the two kinds of node
  unequally), which shows as element-scale stripes. Each contact facet f gets its mean pressure
  p_f = F_f / A_f, F_f = int_f (sum_a p_a N_a) dA (the facet's share of the reactions: the facets'
  F_f add up to the total contact force exactly), A_f = int_f dA, dA = 2 pi r ds on the deformed
  boundary; a vertex gets sum F_f / sum A_f over its facets, a midpoint the mean of its two vertices.
  The result is continuous and piecewise linear along the boundary, >= 0, and 0 away from the
  contact facets; it spreads the pressure by at most half a facet beyond the contact edge.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, ElementQuad2, ElementTriP2, MeshQuad2

from .forms import Mechanics
from .kinematics import Kinematics
from .material import cauchy_stress
from .postprocess import smallest_stretch

if TYPE_CHECKING:
    from .cup import CupResponse

__all__ = ["FIELDS", "project_to_nodes", "von_mises", "smooth_contact_pressure", "nodal_field"]

#: the fields `nodal_field` recovers, with their display names and units
FIELDS = {"contact_pressure": "contact pressure (kPa)", "von_mises": "von Mises stress (kPa)",
          "min_stretch": "smallest principal stretch (-)"}

# 1D quadratic shape functions on s in [0, 1] (vertex 0, vertex 1, midpoint), 4-point Gauss rule
_S, _W = np.polynomial.legendre.leggauss(4)
_S, _W = 0.5 * (_S + 1.0), 0.5 * _W
_N = np.stack([(1 - _S) * (1 - 2 * _S), _S * (2 * _S - 1), 4 * _S * (1 - _S)])
_DN = np.stack([4 * _S - 3, 4 * _S - 1, 4 - 8 * _S])


def project_to_nodes(kin: Kinematics, values: np.ndarray) -> np.ndarray:
    """L2 projection (weight dV = 2 pi R dA) of a Gauss-point field [nel, nq] onto the nodes [nnodes]."""
    values = np.asarray(values, float)
    if values.shape != kin.dV.shape:
        raise ValueError(f"values: expected one value per Gauss point {kin.dV.shape}, got {values.shape}")
    element = ElementQuad2() if isinstance(kin.mesh, MeshQuad2) else ElementTriP2()
    basis = Basis(kin.mesh, element, intorder=4)            # the solver's quadrature points
    phi = np.stack([np.asarray(b[0]) for b in basis.basis])   # [nbfun, nel, nq]
    dofs = basis.element_dofs                                  # [nbfun, nel], dof n = node n
    Me = np.einsum("aeq,beq,eq->eab", phi, phi, kin.dV)
    rows = np.broadcast_to(dofs.T[:, :, None], Me.shape).ravel()
    cols = np.broadcast_to(dofs.T[:, None, :], Me.shape).ravel()
    M = sp.csr_matrix((Me.ravel(), (rows, cols)), shape=(basis.N, basis.N))
    b = np.bincount(dofs.ravel(), weights=np.einsum("aeq,eq->ae", phi, values * kin.dV).ravel(),
                    minlength=basis.N)
    return spla.spsolve(M.tocsc(), b)


def von_mises(sigma: np.ndarray) -> np.ndarray:
    """Von Mises stress [Pa] of the axisymmetric Cauchy stress (s_rr, s_zz, s_tt, s_rz) [4, ...]."""
    s_rr, s_zz, s_tt, s_rz = sigma
    return np.sqrt(0.5 * ((s_rr - s_zz) ** 2 + (s_zz - s_tt) ** 2 + (s_tt - s_rr) ** 2) + 3.0 * s_rz**2)


def smooth_contact_pressure(mesh, u: np.ndarray, p_lumped_Pa: np.ndarray) -> np.ndarray:
    """The contact pressure recovered to the nodes [Pa] (module docstring) from the lumped nodal
    pressure `p_lumped_Pa` [nnodes] of the deformed state `u` (dof 2n + c: component c of node n)."""
    p = np.asarray(p_lumped_Pa, float)
    out = np.zeros_like(p)
    nv = int(mesh.t.max()) + 1
    bf = mesh.boundary_facets()
    fn = np.vstack([mesh.facets[:, bf], nv + bf])             # [3, nbf]: vertex, vertex, midpoint
    fn = fn[:, np.any(p[fn] > 0, axis=0)]
    if fn.shape[1] == 0:
        return out
    x = mesh.doflocs[:, fn.ravel()] + np.stack([u[0::2], u[1::2]])[:, fn.ravel()]
    x = x.reshape(2, 3, -1)                                    # [2, 3, nf] deformed
    r_g = np.einsum("ag,an->gn", _N, x[0])
    ds = np.linalg.norm(np.einsum("ag,dan->dgn", _DN, x), axis=0)
    w = 2.0 * np.pi * r_g * ds * _W[:, None]                   # [ng, nf]
    area = w.sum(axis=0)
    force = np.einsum("ag,an,gn->n", _N, p[fn], w)             # F_f = int (sum p_a N_a) dA
    verts = fn[:2].ravel()
    f_sum = np.bincount(verts, weights=np.tile(force, 2), minlength=p.size)
    a_sum = np.bincount(verts, weights=np.tile(area, 2), minlength=p.size)
    on = a_sum > 0
    out[on] = f_sum[on] / a_sum[on]
    out[fn[2]] = 0.5 * (out[fn[0]] + out[fn[1]])
    return out


def nodal_field(resp: "CupResponse", name: str, step: int = -1) -> np.ndarray:
    """The field `name` (one of `FIELDS`) of step `step` at every mesh node, in SI units."""
    if name not in FIELDS:
        raise ValueError(f"field: expected one of {', '.join(FIELDS)}, got {name!r}")
    u = resp.displacements[step]
    if name == "contact_pressure":
        return smooth_contact_pressure(resp.mesh, u, resp.nodal_pressure_Pa[step])
    kin = Kinematics.of(resp.mesh)
    f = kin.deformation_gradient(u)
    if name == "min_stretch":
        return project_to_nodes(kin, smallest_stretch(f))
    mech = Mechanics(kin, resp.material)
    return project_to_nodes(kin, von_mises(cauchy_stress(f, mech.stress(f))))
