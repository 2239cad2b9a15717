"""Is a converged state admissible? Contact with the plane between the nodes, and self-contact.

Contact with the plane is node-based (`fem.contact`): the solver keeps every boundary node at
z >= 0, but a quadratic facet between two nodes on the plane whose third node lifts off dips
below it, by h/8 when one end vertex is h up and the mid-side node and the other vertex are
down. That happens where the contact edge lies inside a facet and the wall leaves the plane
steeply within it: the wall bends off the plane over a length shorter than the element (a wall
thin against its elements, or one that has turned over so that its rim lifts while its middle
lies on the plane). A finer mesh along the wall shrinks the dip; the node-based contact cannot. And nothing keeps the wall from passing through itself (no self-contact is
modelled): where it folds, its deformed outline crosses itself.

`check_state` finds both in a converged state and raises `StateRejected` (a
`fem.solver.ConvergenceError`) that says at which u, where on the wall, and why. The plane's
tolerance is `PENETRATION_TOL` of the wall's thickness at the rim (the 'rim' edge; without one, no
plane check): that of the validation report's extremes. Nothing is accepted silently: a state
that violates the contact conditions beyond it ends the path.
"""

from __future__ import annotations

import weakref

import numpy as np
from skfem import Mesh

from .solver import ConvergenceError

__all__ = ["PENETRATION_TOL", "StateRejected", "rim_thickness", "check_state", "outline_crossing",
           "facet_dip"]

PENETRATION_TOL = 0.05      # largest dip below the plane / the wall's thickness at the rim

_S = np.linspace(0.0, 1.0, 33)
_N = np.stack([(1 - _S) * (1 - 2 * _S), _S * (2 * _S - 1), 4 * _S * (1 - _S)])   # vertex, vertex, mid


class StateRejected(ConvergenceError):
    """A converged state that violates the contact conditions (the message says where and why)."""


def _facet_nodes(mesh: Mesh, name: str) -> np.ndarray:
    f = np.asarray(mesh.boundaries[name])
    nv = int(mesh.t.max()) + 1
    return np.vstack([mesh.facets[:, f], nv + f[None, :]])        # [3, nf]: vertices, midpoint


def rim_thickness(mesh: Mesh) -> float | None:
    """The undeformed length of the 'rim' edge [m] (None if the mesh has no 'rim' tag)."""
    if "rim" not in (mesh.boundaries or {}):
        return None
    fn = _facet_nodes(mesh, "rim")
    x = mesh.doflocs
    return float(np.sum(np.linalg.norm(x[:, fn[1]] - x[:, fn[0]], axis=0)))


def facet_dip(mesh: Mesh, x: np.ndarray, names=("cavity", "rim", "outer")) -> tuple[float, str, int]:
    """The deepest point of the deformed boundary facets below z = 0: (depth [m] >= 0, the
    boundary's name, the facet's column in it)."""
    best = (0.0, "", -1)
    for name in names:
        if name not in (mesh.boundaries or {}):
            continue
        z = _N.T @ x[1][_facet_nodes(mesh, name)]                    # [33, nf]
        j = int(np.argmin(np.min(z, axis=0)))
        depth = -float(np.min(z[:, j]))
        if depth > best[0]:
            best = (depth, name, j)
    return best


def outline_crossing(points: np.ndarray) -> tuple[int, int] | None:
    """The first pair (i, j), i < j - 1, of crossing segments of the closed polyline `points`
    [2, n] (segment k joins points k and k+1 mod n), or None if it does not cross itself.
    Only the pairs whose extents in r overlap can cross: they are found by sorting the segments
    by their smallest r (a sweep), so the cost grows with the overlaps, not with n^2."""
    p, q = points, np.roll(points, -1, axis=1)
    n = p.shape[1]
    d = q - p
    lo, hi = np.minimum(p[0], q[0]), np.maximum(p[0], q[0])
    order = np.argsort(lo, kind="stable")
    # for each segment a, the segments b that start within its extent (lo_a <= lo_b <= hi_a)
    first = np.arange(n) + 1
    last = np.searchsorted(lo[order], hi[order], side="right")
    counts = np.maximum(last - first, 0)
    a = np.repeat(order, counts)
    b = order[np.repeat(last - counts, counts) + np.arange(counts.sum())
              - np.repeat(np.cumsum(counts) - counts, counts)]
    i, j = np.minimum(a, b), np.maximum(a, b)
    keep = (j - i >= 2) & ~((i == 0) & (j == n - 1))                # neighbours across the seam
    i, j = i[keep], j[keep]
    denom = d[0, i] * d[1, j] - d[1, i] * d[0, j]
    w = p[:, j] - p[:, i]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (w[0] * d[1, j] - w[1] * d[0, j]) / denom
        t = (w[0] * d[1, i] - w[1] * d[0, i]) / denom
    hit = (denom != 0) & (s > 0) & (s < 1) & (t > 0) & (t < 1)
    if not hit.any():
        return None
    k = np.flatnonzero(hit)
    k = k[np.lexsort((j[k], i[k]))[0]]                                # the first in (i, j) order
    return int(i[k]), int(j[k])


def _outline(mesh: Mesh) -> tuple[np.ndarray, list[str]]:
    """Node indices of the closed outline cavity -> rim -> outer -> top_plate and, per segment,
    the boundary it belongs to; kept for the last mesh asked (a path checks every state)."""
    key = tuple((name, id(f)) for name, f in (mesh.boundaries or {}).items())
    ref, last_key, outline = _LAST_OUTLINE
    if ref is None or ref() is not mesh or last_key != key:
        outline = _mesh_outline(mesh)
        _LAST_OUTLINE[:] = [weakref.ref(mesh), key, outline]
    return outline


_LAST_OUTLINE: list = [None, None, None]


def _mesh_outline(mesh: Mesh) -> tuple[np.ndarray, list[str]]:
    """`_outline` computed from the boundary tags."""
    from .mesh import boundary_path

    nodes: list[int] = []
    names: list[str] = []
    for name in ("cavity", "rim", "outer", "top_plate"):
        if name not in (mesh.boundaries or {}):
            continue
        path = list(boundary_path(mesh, name))
        if nodes and path[-1] == nodes[-1]:
            path = path[::-1]
        if nodes and path[0] != nodes[-1]:
            return np.zeros(0, int), []                              # not one closed loop
        new = path if not nodes else path[1:]
        nodes += new
        names += [name] * len(new)
    if len(nodes) < 4 or nodes[-1] != nodes[0]:
        return np.zeros(0, int), []
    return np.asarray(nodes[:-1]), names[1:]          # segment k ends at node k + 1: its boundary


def check_state(mesh: Mesh, u: np.ndarray, t: float, step: int, u_prev: float) -> None:
    """Raise `StateRejected` if the converged displacement `u` at plate displacement t [m] lets a
    boundary facet dip below the plane by more than PENETRATION_TOL of the rim's thickness, or
    the wall's outline cross itself (module docstring)."""
    x = mesh.doflocs + np.stack([u[0::2], u[1::2]])
    rim = rim_thickness(mesh)
    where = f"at u = {t * 1e3:.4g} mm (step {step})"
    if rim is not None:
        depth, name, j = facet_dip(mesh, x)
        if depth > PENETRATION_TOL * rim:
            raise StateRejected(f"{where}: {_dip_cause(mesh, x, name, j, depth, rim)}", step=step,
                                t_from=u_prev, t_to=t, cause=_dip_cause(mesh, x, name, j, depth, rim))
    loop, names = _outline(mesh)
    if loop.size:
        hit = outline_crossing(x[:, loop])
        if hit is not None:
            a, b = hit
            pa = x[:, loop[a]]
            plate = "top_plate" in (names[a], names[b])
            cause = (f"the wall folds onto itself: its {names[a]} face crosses its {names[b]} face "
                     f"near r = {pa[0] * 1e3:.3g} mm, z = {pa[1] * 1e3:.3g} mm ("
                     + ("it folds into the clamped end face, i.e. into the plate; " if plate else "")
                     + "self-contact is not modelled, so the path beyond is not physical)")
            raise StateRejected(f"{where}: {cause}", step=step, t_from=u_prev, t_to=t, cause=cause)


def _dip_cause(mesh: Mesh, x: np.ndarray, name: str, j: int, depth: float, rim: float) -> str:
    fn = _facet_nodes(mesh, name)[:, j]
    z = x[1, fn]
    length = float(np.linalg.norm(x[:, fn[1]] - x[:, fn[0]]))
    text = (f"the {name} face dips {depth * 1e6:.3g} um ({depth / rim:.2g} of the rim's thickness, "
            f"tolerance {PENETRATION_TOL:g}) below the plane between the nodes of its facet at r = "
            f"{x[0, fn[2]] * 1e3:.3g} mm: contact holds the nodes (z = {', '.join(f'{v * 1e6:.3g}' for v in z)} um), "
            f"and the contact edge lies inside this {length * 1e3:.2g} mm facet, whose wall leaves "
            f"the plane within it (it bends off the plane over less than an element)")
    rim_z = float(np.min(x[1, _facet_nodes(mesh, "rim")])) if "rim" in mesh.boundaries else 0.0
    if rim_z > PENETRATION_TOL * rim:
        text += (f"; the wall has turned over: its rim is lifted {rim_z * 1e3:.3g} mm off the plane "
                 f"while the wall lies on it further in")
    return text + ("; likely cause: elements too long for the bend where the wall leaves the plane "
                   "(refine along the wall)")
