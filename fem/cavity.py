"""The cavity's gas pressure as a conservative load: Pi(u) = W(u) + dp V_cav(u).

The cavity of the cup is the region of revolution bounded by the rigid plate's roof (z = h from
the axis to the plate edge r_0), the deformed cavity-facing surface from the plate edge down to
its first point on the plane (the seal, r_k), the vertical drop from there to z = 0 (zero length
when the seal touches, as it does at equilibrium) and the plane back to the axis. Its volume,
by the divergence theorem in the meridian plane, is the line integral over the open chain

    V_cav = pi r_k^2 z_k - pi int_chain r^2 dz,                        (the region of eq. 4)

the roof, axis and plane contributing nothing. With the pressure difference dp = p_a - p_b > 0
(the gas inside below the ambient) acting on the cavity surface, the load is conservative: the
gas does work p_b dV on the surface and the uniform ambient pressure none on the closed body,
so the potential energy gains dp V_cav and the equilibrium minimizes W(u) + dp V_cav(u) under the
plate displacement and the contact conditions. `PressurizedMechanics` adds dp V_cav, its exact
gradient and Hessian on the quadratic edges (6-point Gauss per edge: the integrand r^2 dz/dxi is
a quintic) to `fem.forms.Mechanics`; the solver (`fem.solver`) needs nothing else.

The chain is cut at its last node on the plane (z <= a round-off tolerance), the outer end of
the outermost contact zone: beyond it the surface lies outside the gas region, and the gas fills
every pocket the wall lifts between contact zones inside it (an inner touchdown does not seal a
pocket off; it shares the cavity's pressure). So V_cav is continuous as nodes touch down and lift
off inside the outermost contact, and as that contact's end moves from node to node (z_k = 0 at
the cut); it is piecewise smooth like the contact conditions it follows. (Cut at the end of the
first contact zone instead, V jumped by a pocket's volume when an inner touchdown lifted: an
energy barrier that stalled the Newton iteration of a sticking cup under suction.) The seal r_k
is the first node on the plane, the inner edge of the contact.

Global equilibrium (tested): the vertical resultant of the pressure on any surface of revolution
between radii r_0 and r_k is dp pi (r_k^2 - r_0^2), pulling the wall towards the plane, so the
plate's force on the body P_z, the contact force N and the suction balance:

    P_z + N = dp pi (r_k^2 - r_0^2),

and with the roof's share dp pi r_0^2 on the rigid plate, the pull on the handle is
F1 = dp pi r_0^2 + P_z = dp pi r_k^2 - N (eq. 5 with the FEM's N and r_k in place of kappa F0 and r).
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp
from skfem import Mesh

from .forms import Mechanics
from .mesh import boundary_path

__all__ = ["CavitySurface", "PressurizedMechanics"]

_XI, _W = np.polynomial.legendre.leggauss(6)


def _shape(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quadratic line shape functions (start, mid, end) and their xi-derivatives, [3, nq]."""
    N = np.stack([0.5 * xi * (xi - 1.0), 1.0 - xi**2, 0.5 * xi * (xi + 1.0)])
    dN = np.stack([xi - 0.5, -2.0 * xi, xi + 0.5])
    return N, dN


def _rule(upper: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """N, dN/dxi and weights of the Gauss rule on xi in [-1, upper]."""
    half = 0.5 * (upper + 1.0)
    xi = -1.0 + half * (_XI + 1.0)
    N, dN = _shape(xi)
    return N, dN, _W * half


_RULES = tuple(np.stack(pair) for pair in zip(_rule(1.0), _rule(0.0)))   # full edge, half edge


def wetted_fraction(z: np.ndarray, z_ref: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """phi(z): the share of the cavity pressure acting at height z above the plane, rising
    smoothly (C1) from 0 on the plane to 1 at z_ref; returns (Phi = int_0^z phi, phi, phi', phi'')."""
    if z_ref <= 0.0:
        one = np.ones_like(z)
        return z, one, 0.0 * one, 0.0 * one
    s = np.clip(z / z_ref, 0.0, 1.0)
    inside = (z > 0.0) & (z < z_ref)
    Phi = np.where(z >= z_ref, z - 0.5 * z_ref, z_ref * (s**3 - 0.5 * s**4))
    phi = 3.0 * s**2 - 2.0 * s**3
    dphi = np.where(inside, (6.0 * s - 6.0 * s**2) / z_ref, 0.0)
    d2phi = np.where(inside, (6.0 - 12.0 * s) / z_ref**2, 0.0)
    return Phi, phi, dphi, d2phi


@dataclass(frozen=True)
class CavitySurface:
    """The cavity-facing chain of quadratic edges, from the plate edge to the rim.

    `nodes` [n] are the mesh nodes along the chain (vertices and mid-side nodes interleaved,
    `fem.mesh.boundary_path`); edge e has nodes nodes[2e], nodes[2e + 1], nodes[2e + 2].
    `wetting_m` is z_ref of `wetted_fraction` (0: the pressure acts up to the seal node).
    """

    nodes: np.ndarray
    tolerance_m: float
    wetting_m: float = 0.0
    _chains: dict = field(default_factory=dict, repr=False, compare=False)   # by cut index

    @classmethod
    def of(cls, mesh: Mesh, wetting_m: float = 0.0) -> "CavitySurface":
        nodes = boundary_path(mesh, "cavity")
        if nodes.size % 2 == 0:
            raise ValueError("mesh: the cavity chain must consist of quadratic edges (odd node count)")
        if not (np.isfinite(wetting_m) and wetting_m >= 0.0):
            raise ValueError(f"wetting_m: must be >= 0 m, got {wetting_m}")
        size = float(np.max(np.ptp(mesh.doflocs, axis=1)))
        return cls(nodes, 1e-12 * size, float(wetting_m))

    def on_plane(self, x: np.ndarray) -> np.ndarray:
        """Whether each chain node lies on the plane at the deformed coordinates x [n]."""
        return x[1, self.nodes] <= self.tolerance_m

    def seal_index(self, x: np.ndarray) -> int:
        """Position along the chain of the first node on the plane, the seal (the last node if
        none is)."""
        on = np.flatnonzero(self.on_plane(x))
        return int(on[0]) if on.size else self.nodes.size - 1

    def cut_index(self, x: np.ndarray) -> int:
        """Position of the last node on the plane, the outer end of the outermost contact: the
        load acts on the chain up to here (module docstring); the last node if none is."""
        return self.cut_of(self.on_plane(x))

    def cut_of(self, on: np.ndarray) -> int:
        """The cut of a chain whose nodes `on` lie on the plane: the last of them, else the
        chain's end (`cut_index`)."""
        at = np.flatnonzero(on)
        return int(at[-1]) if at.size else self.nodes.size - 1

    def seal_radius(self, x: np.ndarray) -> float:
        """r_k: the deformed radius of the seal node [m]."""
        return float(x[0, self.nodes[self.seal_index(x)]])

    def volume(self, x: np.ndarray) -> float:
        """The geometric V_cav [m^3] of the deformed node coordinates x [2, nnodes]."""
        return self._terms(x, 0, 0.0)[0]

    def loaded_volume(self, x: np.ndarray) -> float:
        """V_phi = int phi(z) dV over the cavity [m^3], whose dp-multiple is the load's potential
        (= `volume` for wetting_m = 0)."""
        return self._terms(x, 0, self.wetting_m)[0]

    def derivatives(self, x: np.ndarray) -> tuple[float, tuple, np.ndarray, np.ndarray]:
        """(V_phi, (dofs, dV_phi/dx there), the Hessian's entries, their dof pairs [2, m]):
        dofs 2n (r) and 2n + 1 (z) of node n, as in `fem.kinematics`."""
        return self._terms(x, 2, self.wetting_m)

    def gradient_cut_at(self, x: np.ndarray, k: int) -> np.ndarray:
        """dV_phi/du [2 nnodes] of the chain cut at position k instead of at `cut_index`."""
        V, (dofs, grad) = self._terms(x, 1, self.wetting_m, k)
        return np.bincount(dofs, grad, minlength=x.size)

    def _chain(self, k: int) -> "_Chain":
        """The chain cut at position k: its edges and their quadrature, dofs and Hessian dof
        pairs (index work only, kept per cut: a path meets a handful of cuts)."""
        chain = self._chains.get(k)
        if chain is None:
            full_edges, half = divmod(k, 2)
            edges = self.nodes[2 * np.arange(full_edges + half)[:, None] + np.arange(3)]   # [E, 3]
            rule = np.zeros(edges.shape[0], int)
            rule[full_edges:] = 1
            seal = int(self.nodes[k])
            dofs = np.concatenate([2 * edges, 2 * edges + 1], axis=1)                   # [E, 6]
            shape = (edges.shape[0], 6, 6)
            d = np.array([2 * seal, 2 * seal + 1])
            pairs = np.concatenate([np.stack([np.broadcast_to(dofs[:, :, None], shape).reshape(-1),
                                              np.broadcast_to(dofs[:, None, :], shape).reshape(-1)]),
                                    np.stack([np.repeat(d, 2), np.tile(d, 2)])], axis=1)
            chain = self._chains[k] = _Chain(edges, _RULES[0][rule], _RULES[1][rule], _RULES[2][rule],
                                             seal, np.concatenate([dofs.ravel(), d]), pairs)
        return chain

    def _terms(self, x: np.ndarray, order: int, z_ref: float, cut: int | None = None):
        """V_phi = pi r_k^2 Phi(z_k) - pi int_chain r^2 phi(z) dz and its derivatives up to `order`
        (1: the gradient, 2: and the Hessian), the chain cut at `cut` (default `cut_index`); all
        edges at once, in chain order (the last one halved if the cut is at a mid-side node)."""
        c = self._chain(self.cut_index(x) if cut is None else cut)
        if z_ref <= 0.0:
            return self._geometric_terms(x, order, c)
        edges, N, dN, w = c.edges, c.N, c.dN, c.w                       # [E, 3], [E, 3, q], [E, q]
        rk, zk = x[:, c.seal]
        Phi_k, phi_k, dphi_k, _ = (float(v) for v in wetted_fraction(np.array(zk), z_ref))
        xr, xz = x[0, edges], x[1, edges]
        r = np.einsum("eiq,ei->eq", N, xr)
        z = np.einsum("eiq,ei->eq", N, xz)
        dz = np.einsum("eiq,ei->eq", dN, xz)
        _, phi, dphi, d2phi = wetted_fraction(z, z_ref)
        V = np.pi * rk**2 * Phi_k - np.pi * np.sum(w * r**2 * phi * dz)
        if not order:
            return (float(V),)
        g_r = np.einsum("eiq,eq->ei", N, 2.0 * r * phi * dz * w)
        g_z = np.einsum("eiq,eq->ei", N, r**2 * dphi * dz * w) \
            + np.einsum("eiq,eq->ei", dN, r**2 * phi * w)
        grad = -np.pi * np.concatenate([g_r, g_z], axis=1)
        seal_grad = np.array([2.0 * np.pi * rk * Phi_k, np.pi * rk**2 * phi_k])
        if order == 1:
            return float(V), (c.dofs, np.concatenate([grad.ravel(), seal_grad]))

        def outer(a, weight, b):
            return np.einsum("eiq,eq,ejq->eij", a, weight, b)
        H = np.empty((edges.shape[0], 6, 6))
        H[:, :3, :3] = outer(N, 2.0 * phi * dz * w, N)
        H[:, :3, 3:] = outer(N, 2.0 * r * dphi * dz * w, N) + outer(N, 2.0 * r * phi * w, dN)
        H[:, 3:, :3] = H[:, :3, 3:].transpose(0, 2, 1)
        B = outer(N, r**2 * dphi * w, dN)
        H[:, 3:, 3:] = outer(N, r**2 * d2phi * dz * w, N) + B + B.transpose(0, 2, 1)
        seal_hess = np.array([2.0 * np.pi * Phi_k, 2.0 * np.pi * rk * phi_k,
                              2.0 * np.pi * rk * phi_k, np.pi * rk**2 * dphi_k])
        return (float(V), (c.dofs, np.concatenate([grad.ravel(), seal_grad])),
                np.concatenate([-np.pi * H.ravel(), seal_hess]), c.pairs)


    @staticmethod
    def _geometric_terms(x: np.ndarray, order: int, c: "_Chain"):
        """`_terms` for phi = 1 (z_ref = 0: the geometric volume, the gas's): the same products
        without the factors phi = 1 and the terms in phi' = phi'' = 0."""
        edges, N, dN, w = c.edges, c.N, c.dN, c.w
        rk, zk = x[:, c.seal]
        xr, xz = x[0, edges], x[1, edges]
        r = np.einsum("eiq,ei->eq", N, xr)
        dz = np.einsum("eiq,ei->eq", dN, xz)
        V = np.pi * rk**2 * zk - np.pi * np.sum(w * r**2 * dz)
        if not order:
            return (float(V),)
        g_r = np.einsum("eiq,eq->ei", N, 2.0 * r * dz * w)
        g_z = np.einsum("eiq,eq->ei", dN, r**2 * w)
        grad = -np.pi * np.concatenate([g_r, g_z], axis=1)
        seal_grad = np.array([2.0 * np.pi * rk * zk, np.pi * rk**2])
        if order == 1:
            return float(V), (c.dofs, np.concatenate([grad.ravel(), seal_grad]))
        H = np.zeros((edges.shape[0], 6, 6))
        H[:, :3, :3] = np.einsum("eiq,eq,ejq->eij", N, 2.0 * dz * w, N)
        H[:, :3, 3:] = np.einsum("eiq,eq,ejq->eij", N, 2.0 * r * w, dN)
        H[:, 3:, :3] = H[:, :3, 3:].transpose(0, 2, 1)
        seal_hess = np.array([2.0 * np.pi * zk, 2.0 * np.pi * rk, 2.0 * np.pi * rk, 0.0])
        return (float(V), (c.dofs, np.concatenate([grad.ravel(), seal_grad])),
                np.concatenate([-np.pi * H.ravel(), seal_hess]), c.pairs)


@dataclass(frozen=True)
class _Chain:
    """`CavitySurface._chain`: edges [E, 3], shape functions N, dN [E, 3, q] and weights w [E, q]
    of their rules, the seal node, the gradient's dofs and the Hessian's dof pairs [2, m]
    (read-only: shared by every evaluation at this cut)."""

    edges: np.ndarray
    N: np.ndarray
    dN: np.ndarray
    w: np.ndarray
    seal: int
    dofs: np.ndarray
    pairs: np.ndarray

    def __post_init__(self) -> None:
        for a in (self.edges, self.N, self.dN, self.w, self.dofs, self.pairs):
            a.flags.writeable = False


@dataclass
class PressurizedMechanics:
    """`fem.forms.Mechanics` of the cup loaded by dp = p_a - p_b [Pa] on its cavity surface:
    energy W + dp V_cav, force r + dp dV/du, tangent K + dp d2V/du2 (module docstring), with the
    tangent in the body's own CSR pattern (the solver's factorization is built for it).

    schedule: dp as a function of the path parameter t (e.g. a ramp at fixed plate position);
    `at(t)` is then the potential at t, which `fem.solver.follow_path` minimizes step by step."""

    body: Mechanics
    cavity: CavitySurface
    dp_Pa: float
    schedule: Callable[[float], float] | None = None
    _table: dict | None = field(default=None, repr=False)     # CSR positions, one per body

    def __post_init__(self) -> None:
        if self._table is None:        # shared by every load on the body: a branch makes hundreds
            self._table = _TABLES.setdefault(self.body, {})

    def at(self, t: float) -> "PressurizedMechanics":
        if self.schedule is None:
            return self
        return replace(self, dp_Pa=float(self.schedule(t)), schedule=None)

    @property
    def kin(self):
        return self.body.kin

    @property
    def material(self):
        return self.body.material

    def coordinates(self, u: np.ndarray) -> np.ndarray:
        """Deformed node coordinates x = X + u [2, nnodes]."""
        return self.kin.node_coordinates() + np.stack([u[0::2], u[1::2]])

    def energy(self, u: np.ndarray) -> float:
        return self.body.energy(u) + self.dp_Pa * self.cavity.loaded_volume(self.coordinates(u))

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return self.evaluate(u)[1]

    def linearize(self, u: np.ndarray) -> tuple[np.ndarray, sp.csr_matrix]:
        return self.evaluate(u)[1:]

    def evaluate(self, u: np.ndarray) -> tuple[float, np.ndarray, sp.csr_matrix]:
        W, r, K = self.body.evaluate(u)
        if self.dp_Pa == 0.0:
            return W, r, K
        V, (dofs, grad), hess, pairs = self.cavity.derivatives(self.coordinates(u))
        r = r + self.dp_Pa * np.bincount(dofs, grad, minlength=r.size)
        data = self.add_hessian(K, pairs, hess, self.dp_Pa)
        return W + self.dp_Pa * V, r, sp.csr_matrix((data, K.indices, K.indptr), shape=K.shape)

    def add_hessian(self, K: sp.csr_matrix, pairs: np.ndarray, hess: np.ndarray, scale: float) -> np.ndarray:
        """K's CSR data plus `scale` times the Hessian entries `hess` at the dof `pairs` (summed
        where pairs repeat), touching only the entries the pairs reach."""
        slots, inverse = self._slots(K, pairs)
        data = K.data.copy()
        data[slots] += scale * np.bincount(inverse, hess, minlength=slots.size)
        return data

    def _slots(self, K: sp.csr_matrix, pairs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The distinct CSR positions of the dof pairs and each pair's index among them (kept as
        `_positions`)."""
        key = ("slots", id(pairs), K.nnz)
        kept = self._table.get(key)
        if kept is not None and kept[0] is pairs:
            return kept[1]
        slots = np.unique(self._positions(K, pairs), return_inverse=True)
        if not pairs.flags.writeable:
            self._table[key] = (pairs, slots)
        return slots

    def _positions(self, K: sp.csr_matrix, pairs: np.ndarray) -> np.ndarray:
        """Positions of the dof pairs (i, j) in K's CSR data (sorted column indices per row);
        kept for a read-only `pairs` (a cut's, `CavitySurface._chain`) and K's pattern."""
        key = ("positions", id(pairs), K.nnz)
        kept = self._table.get(key)
        if kept is not None and kept[0] is pairs:
            return kept[1]
        pos = self._search(K, pairs)
        if not pairs.flags.writeable:
            self._table[key] = (pairs, pos)
        return pos

    def _search(self, K: sp.csr_matrix, pairs: np.ndarray) -> np.ndarray:
        table = self._lookup(K)
        keys = pairs[0].astype(np.int64) * K.shape[0] + pairs[1]
        pos = np.searchsorted(table, keys)
        if np.any(pos >= table.size) or np.any(table[np.minimum(pos, table.size - 1)] != keys):
            raise ValueError("cavity: an edge's dofs are not coupled in the tangent's pattern")
        return pos

    def _lookup(self, K: sp.csr_matrix) -> np.ndarray:
        table = self._table.get(K.nnz)
        if table is None:
            rows = np.repeat(np.arange(K.shape[0], dtype=np.int64), np.diff(K.indptr))
            table = self._table[K.nnz] = rows * K.shape[0] + K.indices
            if np.any(np.diff(table) <= 0):
                raise ValueError("cavity: the tangent's CSR column indices must be sorted")
        return table


_TABLES: "weakref.WeakKeyDictionary[Mechanics, dict]" = weakref.WeakKeyDictionary()
