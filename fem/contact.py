"""Contact with the rigid plane z = 0: node-based Signorini conditions, no penalty parameter.

Every boundary node that may touch the plane (all boundary nodes except those clamped to the top
plate) is a candidate. A *held* (active) node is kept exactly on the plane, z = Z + u_z = 0, by
eliminating its vertical dof like a Dirichlet condition; for ``"sticking"`` contact its radial
displacement is also frozen where it touched down. The nodal contact reaction lambda_a (the
internal force at the eliminated dof, > 0 when the plane pushes) is what the constraint costs.
Which nodes are held is decided inside each Newton step by a small linear complementarity
problem (`fem.contact_step`): the nodes the step would push through the plane and the held nodes it
would pull on; `project` puts any node that still penetrates back on the plane, `hold` records
the new set. A converged step satisfies g >= 0, lambda >= 0, g lambda = 0 at the nodes (to the
Newton tolerance), so there is no enforcement parameter whose value could change the result.
Between nodes the quadratic edge may dip below the plane; `largest_penetration` reports the
largest such violation.

Sticking: a node that lands sticks at its touchdown point, interpolated linearly in the load
step between the step's start and its free flight (`hold`); a held node whose reaction turns
tensile is released (it carries no normal force, so no friction holds it) and lands again where
the iteration puts it: it has slipped.

Coulomb friction (``"coulomb"``, coefficient mu): a held node sticks at its anchor (where it was
at the start of the load step, or where it touched down in it) while its tangential reaction
|t| <= mu lambda, and slides otherwise with t = -mu lambda sign(Delta), Delta = u_r - anchor: the
plane's friction opposes the slip. The step is the backward-Euler increment of the law (the
history is the anchor, moved to the converged position by `fem.laws.Coulomb.commit`). Which nodes press, stick
and slide is decided in every Newton iteration on the linearized problem, exactly
(`fem.friction`: a semismooth Newton method on Alart and Curnier's complementarity functions,
whose augmentation moves the iterates only, not the solution). A sliding node's radial dof is
free and loaded by the friction -mu lambda s of the iterate; at convergence the residual holds
t = -mu lambda s with lambda of the converged state itself. No regularisation: mu = 0 is
frictionless, and a large mu sticks wherever lambda > 0.

The contact pressure p is the L2 projection, on the deformed contact boundary (weight 2 pi r ds),
of the nodal reactions: M p = lambda over the facets touching an active node. With the consistent
boundary mass matrix, int p 2 pi r ds = sum lambda exactly, i.e. the integrated contact force, and
its integrals (the strip width) converge; pointwise it oscillates at the contact edge, so the
pointwise profile is the lumped projection p_a = lambda_a / sum_b M_ab, which is >= 0 and exactly
0 off contact (for the contact edge and the half-maximum width).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .interface import CONTACT_LAWS
from .kinematics import Kinematics

__all__ = ["RigidPlane", "ContactState", "PressureProfile", "PlaneLaw", "CONTACT_LAWS"]

# 1D quadratic shape functions on s in [0, 1] for facet nodes (vertex 0, vertex 1, midpoint)
_GAUSS_S, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_GAUSS_S, _GAUSS_W = 0.5 * (_GAUSS_S + 1.0), 0.5 * _GAUSS_W


def _shape(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    N = np.stack([(1 - s) * (1 - 2 * s), s * (2 * s - 1), 4 * s * (1 - s)])
    dN = np.stack([4 * s - 3, 4 * s - 1, 4 - 8 * s])
    return N, dN


@dataclass(frozen=True)
class ContactState:
    """Which candidate nodes are held on the plane, where they stick, and (Coulomb) which slide."""

    active: np.ndarray         # bool [ncand]
    u_r_stick_m: np.ndarray    # float [ncand], where active: the radial displacement of the anchor
    #                            (sticking: the touchdown point; coulomb: the step's start or touchdown)
    slip: np.ndarray           # int8 [ncand]: coulomb: 0 sticks, +1 / -1 slides outward / inward


class PlaneLaw(Protocol):
    """What the path follower asks of a contact law (`fem.laws` holds the three laws)."""

    name: ClassVar[str]             # one of CONTACT_LAWS
    mu: float                       # Coulomb's coefficient (0 but for coulomb)
    conservative: ClassVar[bool]    # the total energy is the path's potential
    anchored: ClassVar[bool]        # held nodes keep their radial anchor
    incremental: ClassVar[bool]     # the anchors move to the converged state at every commit (Coulomb)

    def step(self, plane: "RigidPlane", state: ContactState, u: np.ndarray, res: np.ndarray,
             free: np.ndarray, du_fixed: np.ndarray, tol: float, friction: np.ndarray) -> Any:
        """The Newton step of an iterate (`fem.contact_step.ContactStep`'s interface)."""

    def friction_force(self, plane: "RigidPlane", state: ContactState,
                       res: np.ndarray) -> np.ndarray | None:
        """The plane's friction on the sliding nodes [N], or None for a law without friction."""

    def cone_excess(self, plane: "RigidPlane", state: ContactState, r_int: np.ndarray) -> float:
        """The largest excess of a stuck node over the friction cone / max lambda."""

    def commit(self, plane: "RigidPlane", state: ContactState, u: np.ndarray) -> ContactState:
        """The state carried into the next load step."""


@dataclass(frozen=True)
class PressureProfile:
    """Contact pressure along the deformed contact boundary.

    r_m, p_Pa: the nodes of the facets that touch the plane, sorted by deformed radius [m], with
    the lumped projection p_a = lambda_a / int N_a dA [Pa] (>= 0 by the active-set conditions,
    0 at the free nodes next to the contact; the pointwise profile, for plots, the contact edge
    and the half-maximum width). r_gauss_m, p_gauss_Pa, w_m2: the
    consistent L2 projection at the Gauss points of the contact facets with the weights
    2 pi r ds [m^2], so that int g(p) dA = sum g(p_gauss) w (for integrals: it oscillates near
    the contact edge, but its integrals converge in L2).
    """

    r_m: np.ndarray
    p_Pa: np.ndarray
    r_gauss_m: np.ndarray
    p_gauss_Pa: np.ndarray
    w_m2: np.ndarray


@dataclass(frozen=True, eq=False)
class RigidPlane:
    """The rigid plane z = 0, the boundary facets that may touch it, and the contact law
    (`fem.laws`: frictionless, sticking, coulomb)."""

    kin: Kinematics
    facets: np.ndarray            # candidate boundary facets (global facet indices)
    law: PlaneLaw
    exclude: np.ndarray | None = None   # nodes that are never candidates (e.g. clamped ones)
    nodes: np.ndarray = field(init=False, repr=False)           # the candidate nodes
    _facet_nodes: np.ndarray = field(init=False, repr=False)    # [3, nfacets]: vertices, midpoint

    def __post_init__(self) -> None:
        mesh = self.kin.mesh
        nv = int(mesh.t.max()) + 1      # number of vertices; Q2 edge nodes follow them
        # facet nodes: two vertices and the midpoint node (numbered after the vertices)
        fn = np.vstack([mesh.facets[:, self.facets], nv + self.facets[None, :]])
        object.__setattr__(self, "_facet_nodes", fn)
        nodes = np.unique(fn)
        if self.exclude is not None:
            nodes = np.setdiff1d(nodes, self.exclude)
        object.__setattr__(self, "nodes", nodes)

    @classmethod
    def on(cls, kin: Kinematics, boundaries: list[str], law: PlaneLaw,
           exclude: list[str] = ()) -> "RigidPlane":
        """Candidates: the facets of the named boundaries, minus nodes on the `exclude` boundaries."""
        mesh = kin.mesh
        facets = np.unique(np.concatenate([mesh.boundaries[b] for b in boundaries]))
        excl = None
        if exclude:
            excl = np.unique(np.concatenate(
                [kin.basis.get_dofs(mesh.boundaries[b]).all() // 2 for b in exclude]))
        return cls(kin, facets, law, excl)

    # --- the state -----------------------------------------------------------------------
    def initial_state(self) -> ContactState:
        n = len(self.nodes)
        return ContactState(np.zeros(n, bool), np.zeros(n), np.zeros(n, np.int8))

    def gap(self, u: np.ndarray) -> np.ndarray:
        """Signed nodal gap g = Z + u_z [m] (negative: penetration)."""
        return self.kin.node_coordinates()[1, self.nodes] + u[2 * self.nodes + 1]

    def constraints(self, state: ContactState) -> tuple[np.ndarray, np.ndarray]:
        """Dofs held by the active set and their values (z-dofs on the plane; the sticking nodes'
        u_r at their anchors)."""
        a = np.flatnonzero(state.active)
        dofs = [2 * self.nodes[a] + 1]
        vals = [-self.kin.node_coordinates()[1, self.nodes[a]]]
        if self.law.anchored:
            stuck = a[state.slip[a] == 0]
            dofs.append(2 * self.nodes[stuck])
            vals.append(state.u_r_stick_m[stuck])
        return np.concatenate(dofs), np.concatenate(vals)

    def reactions(self, r_int: np.ndarray) -> np.ndarray:
        """Nodal normal reactions lambda_a [N] (> 0: the plane pushes up) = internal force at z-dofs."""
        return r_int[2 * self.nodes + 1]

    def held_reactions(self, step) -> tuple[np.ndarray, np.ndarray]:
        """The deformed radii [m] of the nodes the plane holds in the converged state `step` (a
        `fem.solver.StepResult`) and its reactions lambda_a [N] on them, both sorted by radius: the
        contact traction as the FEM resolves it (the lumped pressures divide it by each node's
        share of the facets)."""
        held = step.contact.active
        nodes = self.nodes[held]
        r = self.kin.node_coordinates()[0, nodes] + step.u[2 * nodes]
        lam = self.reactions(step.r_int)[held]
        order = np.argsort(r, kind="stable")
        return r[order], lam[order]

    def project(self, u: np.ndarray, u_start: np.ndarray, state: ContactState,
                on_plane: np.ndarray) -> np.ndarray:
        """The nearest admissible displacement: the `on_plane` nodes exactly on the plane (those
        held by `state` where it holds them), and every other penetrating node (g < 0) put back on
        the plane. For the sticking law such a landing node is put where it touched down,
        interpolated linearly in the load step between u_start (gap g0 > 0) and u (gap < 0); a node
        that was on the plane at the step start (g0 = 0) lands where u puts it. Coulomb: as
        sticking, but a sliding node goes where u puts it."""
        out = u.copy()
        nodes, Z = self.nodes, self.kin.node_coordinates()[1, self.nodes]
        g = self.gap(u)
        land = ~on_plane & (g < 0.0)
        out[2 * nodes[on_plane | land] + 1] = -Z[on_plane | land]
        if self.law.anchored:
            held = on_plane & state.active & (state.slip == 0)
            out[2 * nodes[held]] = state.u_r_stick_m[held]
            if np.any(land):
                g0 = self.gap(u_start)[land]
                t = np.where(g0 > 0.0, g0 / np.maximum(g0 - g[land], 1e-300), 1.0)
                ur0, ur1 = u_start[2 * nodes[land]], u[2 * nodes[land]]
                out[2 * nodes[land]] = ur0 + np.clip(t, 0.0, 1.0) * (ur1 - ur0)
        return out

    def hold(self, state: ContactState, active: np.ndarray, u: np.ndarray, u_start: np.ndarray,
             u_free: np.ndarray, released: np.ndarray) -> ContactState:
        """The state holding `active`. Sticking law: a node held anew sticks where it touched
        down, interpolated linearly in the load step between u_start (gap g0) and its free
        flight u_free (the iterate it would reach unsupported, gap g1 < 0), at t = g0 / (g0 - g1);
        so a node resting on the plane at the step start (g0 = 0, e.g. the rim corner at u = 0)
        does not slide. A node `released` in this step (its reaction turned tensile: no
        friction can hold it) lands again where u puts it: it has slipped. If its free flight
        does not reach the plane, a node lands where u puts it. Coulomb: the same anchors; a node
        held anew sticks first (`fem.friction` decides from the next iteration on)."""
        new = active & ~state.active
        stick = state.u_r_stick_m.copy()
        if self.law.anchored and np.any(new):
            nodes = self.nodes[new]
            g0, g1 = self.gap(u_start)[new], self.gap(u_free)[new]
            fly = (g1 < 0.0) & ~released[new]
            t = np.where(fly, np.clip(g0, 0.0, None) / np.maximum(g0 - g1, 1e-300), 1.0)
            r1 = np.where(fly, u_free[2 * nodes], u[2 * nodes])
            stick[new] = u_start[2 * nodes] + np.clip(t, 0.0, 1.0) * (r1 - u_start[2 * nodes])
        return ContactState(active, stick, np.where(active & ~new, state.slip, 0).astype(np.int8))

    # --- post-processing -----------------------------------------------------------------
    def _positions(self, u: np.ndarray, nodes: np.ndarray) -> np.ndarray:
        return self.kin.node_coordinates()[:, nodes] + np.stack([u[2 * nodes], u[2 * nodes + 1]])

    def largest_penetration(self, u: np.ndarray, samples: int = 9) -> float:
        """max(0, -z) over the deformed candidate facets, sampled between the nodes [m]."""
        N, _ = _shape(np.linspace(0.0, 1.0, samples))
        z = self._positions(u, self._facet_nodes.ravel())[1].reshape(3, -1)
        return float(max(0.0, -np.min(N.T @ z)))

    def pressure(self, u: np.ndarray, state: ContactState,
                 r_int: np.ndarray) -> tuple[PressureProfile, np.ndarray]:
        """Contact pressure from the nodal reactions (module docstring): the profile, and the
        lumped nodal pressure [Pa] of every mesh node (0 off contact)."""
        lam_all = np.zeros(self.kin.mesh.doflocs.shape[1])
        lam_all[self.nodes[state.active]] = self.reactions(r_int)[state.active]
        fn = self._facet_nodes
        touching = np.any(np.isin(fn, self.nodes[state.active]), axis=0)
        fn = fn[:, touching]
        p_nodes = np.zeros_like(lam_all)
        if fn.shape[1] == 0:
            e = np.zeros(0)
            return PressureProfile(e, e, e, e, e), p_nodes
        loc, inv = np.unique(fn, return_inverse=True)
        inv = inv.reshape(fn.shape)
        x = self._positions(u, fn.ravel()).reshape(2, 3, -1)         # [2, 3, nf]
        N, dN = _shape(_GAUSS_S)                                      # [3, ng]
        xg = np.einsum("ag,dan->dgn", N, x)
        ds = np.linalg.norm(np.einsum("ag,dan->dgn", dN, x), axis=0)  # [ng, nf]
        w = 2.0 * np.pi * xg[0] * ds * _GAUSS_W[:, None]
        Me = np.einsum("ag,bg,gn->nab", N, N, w)
        rows = np.repeat(inv.T, 3, axis=1).ravel()
        cols = np.tile(inv.T, (1, 3)).ravel()
        M = sp.csr_matrix((Me.ravel(), (rows, cols)), shape=(len(loc), len(loc)))
        p = spla.spsolve(M.tocsc(), lam_all[loc])
        pe = p[inv]                                                   # [3, nf]
        # lumped projection at the nodes: lambda_a / int N_a dA (>= 0, 0 off contact)
        p_nodes[loc] = lam_all[loc] / np.asarray(M.sum(axis=1)).ravel()
        r_loc = self._positions(u, loc)[0]
        order = np.argsort(r_loc, kind="stable")
        return (PressureProfile(r_loc[order], p_nodes[loc][order], xg[0].ravel(),
                                (N.T @ pe).ravel(), w.ravel()), p_nodes)
