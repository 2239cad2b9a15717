"""Structured quadratic meshes of mapped blocks for the verification problems of the FEM core.

`mapped_block` maps a tensor grid of the unit square, (s, t) in [0, 1]^2, through any smooth map
x(s, t); every Q2 node (vertices, edge midpoints, centres) is placed by the map itself, so curved
edges are represented to the element's order. Boundaries are tagged 'left' (s = 0), 'right'
(s = 1), 'bottom' (t = 0) and 'top' (t = 1) of the parameter square.

The cup meshes of the toolkit are made by `fem.mesh`; these blocks serve the verification
problems of the FEM core (patch tests, Lame's cylinder, Hertz's contact).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from skfem import MeshQuad1, MeshQuad2

__all__ = ["mapped_block", "graded"]


def graded(n: int, ratio: float = 1.0) -> np.ndarray:
    """n + 1 points on [0, 1] in geometric progression; the last cell is `ratio` times the first."""
    if n < 1:
        raise ValueError(f"n: number of cells must be >= 1, got {n}")
    if ratio == 1.0:
        return np.linspace(0.0, 1.0, n + 1)
    q = ratio ** (1.0 / max(n - 1, 1))
    w = q ** np.arange(n)
    return np.concatenate([[0.0], np.cumsum(w) / w.sum()])


def mapped_block(s: np.ndarray, t: np.ndarray,
                 x: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]) -> MeshQuad2:
    """Q2 mesh of the image of the grid s x t (increasing, in [0, 1]) under x(s, t) -> (r, z)."""
    m1 = MeshQuad1.init_tensor(np.asarray(s, float), np.asarray(t, float))
    m2 = MeshQuad2.from_mesh(m1)
    S, T = m2.doflocs
    R, Z = x(S, T)
    mesh = MeshQuad2(doflocs=np.vstack([R, Z]), t=m2.t)
    # tag the parameter-square sides through the facet midpoints in (s, t)
    mid = 0.5 * (m2.doflocs[:, m2.facets[0]] + m2.doflocs[:, m2.facets[1]])
    bnd = m2.boundary_facets()
    tol = 1e-12
    tags = {"left": mid[0] < tol, "right": mid[0] > 1 - tol,
            "bottom": mid[1] < tol, "top": mid[1] > 1 - tol}
    return mesh.with_boundaries({k: np.intersect1d(np.flatnonzero(v), bnd) for k, v in tags.items()})
