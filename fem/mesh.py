"""Structured quadratic meshes of the cup's cross-section, their boundary tags and checks.

Element choice: **9-node quadratic quadrilaterals** (`skfem.MeshQuad2`, element `ElementQuad2`) by
default; 6-node quadratic triangles (`skfem.MeshTri2`) with ``element="tri"``. Mesh coordinates
are in metres, x = r (radius) and y = z (height above the substrate plane z = 0).

The mesh is mapped: a tensor grid in the wall coordinates (s, t) in [0, 1]^2 (s along the wall
from the top plate to the rim, t through the thickness from the cavity face to the outer face)
is pushed through `CupGeometry.point`. Mid-side nodes sit at the (s, t) midpoints, so they lie
on the exact curved surface for a non-linear thickness profile, and for a linear one the
elements are straight-sided with centred mid-side nodes. Grading:

- along the wall the element length is proportional to 1 / rho(s) with the density

      rho(s) = d(s)^-along_grading (1 + A_p exp(-s / w_p) + A_r exp(-(1 - s) / w_r)),

  A_p, w_p = `plate_refinement`, `plate_width` and A_r, w_r = `rim_refinement`, `rim_width`.
  The power of d sets the background (1: the elements keep the local thickness-to-length
  ratio; 0: uniform in s; negative, as in the fidelity levels (-1/2): finer where the wall is
  thick, which governs the steep end of F0(u)); the two end zones put (1 + A) times more
  elements into a boundary layer of width ~w (a fraction of the wall length) at the plate,
  where the clamped edge meets the outer face in a stress-concentrating corner, and at the rim,
  where contact starts (for sticking contact the stuck rim corner is singular);
- through the thickness the uniform grid eta is first clustered towards both faces,
  c = (1 - beta) eta + beta (1 - cos(pi eta)) / 2 with beta = `through_clustering` (the
  cosine spacing of beta = 1 has its thinnest layers at the contact face and at the outer face,
  where the bending stresses peak), and then mapped geometrically, t = (q^c - 1)/(q - 1) with
  q = `through_ratio`: each layer q^(1/n_through) times thicker than the one below it, from the
  cavity face (where the contact pressure acts) to the outer face.

Both gradings are smooth maps of a uniform grid, so doubling the counts gives nested vertices
(what a Richardson convergence study needs).

Boundary tags (skfem named boundaries, ``mesh.boundaries[name]`` = facet indices):

==============  =====================================================================
``top_plate``   the edge at r0 (s = 0), clamped to the rigid top plate
``cavity``      the cavity-facing (lower) surface (t = 0)
``outer``       the outer (upper) surface (t = 1)
``rim``         the edge at r1 (s = 1)
==============  =====================================================================

Reading and writing mesh files (a user's own Gmsh cross-section too): `fem.mesh_files`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from skfem import Mesh, MeshQuad1, MeshQuad2, MeshTri1, MeshTri2

from fem.geometry import CupGeometry

__all__ = ["MeshSpec", "FIDELITIES", "DEFAULT_FIDELITY", "BOUNDARY_NAMES", "REQUIRED_BOUNDARIES", "mesh_spec",
           "cup_mesh", "check_cup_mesh", "boundary_path", "signed_areas"]

BOUNDARY_NAMES = ("top_plate", "cavity", "outer", "rim")
REQUIRED_BOUNDARIES = ("top_plate", "cavity")
ElementKind = Literal["quad", "tri"]


@dataclass(frozen=True)
class MeshSpec:
    """Element counts and grading of a mapped cup mesh (see the module docstring).

    n_along : elements along the wall (>= 1); n_through : elements through the thickness (>= 1);
    along_grading : background element length proportional to d^along_grading, in [-1, 2];
    plate_refinement, rim_refinement : extra element density A >= 0 (at most 100) at the plate
        edge and at the rim (1 + A times the background there), decaying over
    plate_width, rim_width : w in (0, 1], the e-folding length of the end zones as a fraction of
        the wall length;
    through_clustering : beta in [0, 1], the blend of uniform (0) and cosine (1) layer spacing,
        which makes the layers at both faces thinnest;
    through_ratio : q of the geometric through-thickness map t = (q^c - 1)/(q - 1): the layers
        grow by q^(1/n_through) each from the cavity face outwards, in [1/20, 20];
    element : "quad" (MeshQuad2) or "tri" (MeshTri2, two triangles per quad).

    The grading is a fixed smooth map of a uniform grid, independent of the element counts, so
    `refined` meshes nest (Richardson extrapolation needs that).
    """

    n_along: int
    n_through: int
    along_grading: float = 1.0
    through_ratio: float = 1.0
    element: ElementKind = "quad"
    plate_refinement: float = 0.0
    plate_width: float = 0.02
    rim_refinement: float = 0.0
    rim_width: float = 0.05
    through_clustering: float = 0.0

    def __post_init__(self) -> None:
        for name in ("n_along", "n_through"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ValueError(f"{name}: element count must be an integer >= 1, got {value!r}")
        if not -1.0 <= self.along_grading <= 2.0:
            raise ValueError(f"along_grading: must be in [-1, 2], got {self.along_grading:g}")
        if not 1 / 20 <= self.through_ratio <= 20:
            raise ValueError(f"through_ratio: must be in [0.05, 20], got {self.through_ratio:g}")
        if self.element not in ("quad", "tri"):
            raise ValueError(f"element: must be 'quad' or 'tri', got {self.element!r}")
        for name in ("plate_refinement", "rim_refinement"):
            if not 0.0 <= getattr(self, name) <= 100.0:
                raise ValueError(f"{name}: extra end-zone density must be in [0, 100], got {getattr(self, name):g}")
        for name in ("plate_width", "rim_width"):
            if not 0.0 < getattr(self, name) <= 1.0:
                raise ValueError(f"{name}: end-zone width must be in (0, 1] of the wall length, "
                                 f"got {getattr(self, name):g}")
        if not 0.0 <= self.through_clustering <= 1.0:
            raise ValueError(f"through_clustering: must be in [0, 1], got {self.through_clustering:g}")

    def refined(self, factor: int = 2) -> MeshSpec:
        """The same grading with `factor` times the element counts (nested vertices)."""
        return replace(self, n_along=factor * self.n_along, n_through=factor * self.n_through)


#: fidelity levels; each doubles the counts of the previous one (constant refinement ratio 2,
#: the same grading, nested vertices). Designed with benchmarks/bench_mesh_levels.py on cup A. The
#: coarse level's F0 error concentrates (i) at the steep end (u -> 0.9 h1) in the first element at
#: the plate and the outermost layer, the corner where the clamped edge meets the outer face
#: (plate zone: 11 times the background density at the plate, and layers clustered half-way to
#: cosine spacing, thinnest at both faces), and (ii) for sticking contact at the stuck rim corner
#: and the rim rolling over it (rim zone: 4 times the density at the rim). The background grading
#: d^-1/2 keeps the thick inner wall finer than the thin rim (a stronger grading, d^-1, made the
#: rim elements so long that the quadratic edges between contact nodes dipped 10 um into the
#: plane). Full cosine clustering was as accurate but made the medium level's sticking active set
#: cycle at 0.67 h1. Measured (tests/test_fem_convergence.py, against Richardson extrapolations):
#: frictionless, the coarse F0 within 0.8 % up to 0.85 h1 (1.7 % at 0.9 h1), the medium within
#: 0.3 % (1.0 %); sticking, the coarse 1-3 % off, the medium within 0.8 % up to the folding
#: stretch (~0.83 h1, `CupResponse.folding_u_m`; beyond it the fine level follows a fold the
#: coarser ones cannot); the frictionless strip width (`postprocess.quartile_width`) of the
#: medium level within 2 % from 0.7 h1 on (the sticking strip converges at first order only:
#: README, stiffness section).
_GRADING = dict(along_grading=-0.5, plate_refinement=10.0, plate_width=0.02, rim_refinement=3.0,
                rim_width=0.05, through_clustering=0.5, through_ratio=1.0)
FIDELITIES: dict[str, MeshSpec] = {
    "coarse": MeshSpec(n_along=36, n_through=4, **_GRADING),
    "medium": MeshSpec(n_along=72, n_through=8, **_GRADING),
    "fine": MeshSpec(n_along=144, n_through=16, **_GRADING),
}

#: the level that keeps F0 within 1 % of the converged curve for both contact laws (up to 0.9 h1
#: frictionless, up to the folding stretch ~0.83 h1 sticking; benchmarks/bench_mesh_levels.py);
#: coarse is the sweep level (~2 %, four times cheaper)
DEFAULT_FIDELITY = "medium"


def mesh_spec(fidelity: str | MeshSpec = DEFAULT_FIDELITY, **overrides) -> MeshSpec:
    """The `MeshSpec` of a fidelity level ("coarse", "medium", "fine"), with fields overridden."""
    if isinstance(fidelity, MeshSpec):
        return replace(fidelity, **overrides)
    if fidelity not in FIDELITIES:
        raise ValueError(f"fidelity: must be one of {', '.join(FIDELITIES)}, got {fidelity!r}")
    return replace(FIDELITIES[fidelity], **overrides)


def cup_mesh(geometry: CupGeometry, fidelity: str | MeshSpec = DEFAULT_FIDELITY, **overrides) -> Mesh:
    """A structured quadratic mesh of the cup wall in metres, with the four boundary tags."""
    spec = mesh_spec(fidelity, **overrides)
    s = _along_wall_nodes(geometry, spec)
    t = _through_thickness_nodes(spec)
    linear = (MeshQuad1 if spec.element == "quad" else MeshTri1).init_tensor(s, t)
    quadratic = (MeshQuad2 if spec.element == "quad" else MeshTri2).from_mesh(_counter_clockwise(linear))
    eps = 0.25 * min(np.diff(s).min(), np.diff(t).min())
    tagged = quadratic.with_boundaries({
        "top_plate": lambda x: x[0] < eps,
        "cavity": lambda x: x[1] < eps,
        "outer": lambda x: x[1] > 1 - eps,
        "rim": lambda x: x[0] > 1 - eps,
    })
    return replace(tagged, doflocs=geometry.point(tagged.doflocs[0], tagged.doflocs[1]))


def _along_wall_nodes(geometry: CupGeometry, spec: MeshSpec) -> np.ndarray:
    """s-coordinates equidistributing the density rho(s) (module docstring) over n_along elements."""
    fine = np.linspace(0.0, 1.0, 8193)     # independent of n_along, so refinement nests
    density = geometry.thickness_at(fine) ** (-spec.along_grading) * (
        1.0 + spec.plate_refinement * np.exp(-fine / spec.plate_width)
        + spec.rim_refinement * np.exp(-(1.0 - fine) / spec.rim_width))
    cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(fine))])
    s = np.interp(np.linspace(0.0, 1.0, spec.n_along + 1), cumulative / cumulative[-1], fine)
    s[0], s[-1] = 0.0, 1.0
    return s


def _counter_clockwise(linear: Mesh) -> Mesh:
    """The linear mesh with every cell's corners counter-clockwise (MeshTri1 sorts them)."""
    t = linear.t.copy()
    cw = signed_areas(linear.p.T, t[:3].T) < 0
    t[1:, cw] = t[:0:-1, cw]          # reverse 1..n-1: (0, 2, 1) or (0, 3, 2, 1)
    return type(linear)(linear.p, t, sort_t=False)


def _through_thickness_nodes(spec: MeshSpec) -> np.ndarray:
    """t-coordinates of a uniform eta grid: clustered, c = (1 - beta) eta + beta (1 - cos pi eta)/2,
    then mapped geometrically, t = (q^c - 1)/(q - 1) (beta = `through_clustering`, q =
    `through_ratio`). Without clustering each layer is q^(1/n_through) times thicker than the
    one below it, so the outermost layer is q^(1 - 1/n_through) times the cavity-facing one."""
    eta = np.linspace(0.0, 1.0, spec.n_through + 1)
    beta = spec.through_clustering
    c = (1.0 - beta) * eta + beta * 0.5 * (1.0 - np.cos(np.pi * eta))
    c[0], c[-1] = 0.0, 1.0
    q = spec.through_ratio
    return c if abs(q - 1.0) < 1e-12 else np.expm1(c * np.log(q)) / (q - 1.0)


# ------------------------------------------------------------------ queries
def boundary_path(mesh: Mesh, name: str) -> np.ndarray:
    """Node indices along the tagged boundary `name`, vertices and mid-side nodes interleaved.

    The chain starts at the end shared with ``top_plate`` (for ``cavity``: plate -> rim) or,
    if there is none, at the end with the larger z. The boundary must be one open chain.
    """
    facets = _facets(mesh, name)
    ends = mesh.facets[:, facets]
    verts, counts = np.unique(ends, return_counts=True)
    tips = verts[counts == 1]
    if len(tips) != 2 or np.any(counts > 2):
        raise ValueError(f"mesh: boundary '{name}' is not one open chain of edges")
    plate = set(mesh.facets[:, _facets(mesh, "top_plate")].ravel()) \
        if name != "top_plate" and "top_plate" in (mesh.boundaries or {}) else set()
    start = tips[0] if tips[0] in plate else tips[1] if tips[1] in plate \
        else tips[np.argmax(mesh.doflocs[1, tips])]
    mid = mesh.dofs.facet_dofs[0] if mesh.dofs.facet_dofs.size else None
    by_vertex: dict[int, list[int]] = {}
    for k, f in enumerate(facets):
        for v in ends[:, k]:
            by_vertex.setdefault(int(v), []).append(int(f))
    path, used, v = [int(start)], set(), int(start)
    for _ in range(len(facets)):
        f = next(f for f in by_vertex[v] if f not in used)
        used.add(f)
        a, b = mesh.facets[:, f]
        v = int(b if a == v else a)
        path += ([int(mid[f])] if mid is not None else []) + [v]
    return np.asarray(path)


def _facets(mesh: Mesh, name: str) -> np.ndarray:
    boundaries = mesh.boundaries or {}
    if name not in boundaries:
        raise ValueError(f"mesh: no boundary named '{name}'; the mesh has {sorted(boundaries)}")
    return np.asarray(boundaries[name])


def check_cup_mesh(mesh: Mesh) -> None:
    """Raise `ValueError` unless `mesh` is a usable cup cross-section.

    Checks: the required tags are present and non-empty, every element has a positive Jacobian
    at its nodes (no inverted or folded element), no point lies left of the axis r = 0 or below
    the substrate plane z = 0.
    """
    if not isinstance(mesh, (MeshQuad2, MeshTri2)):
        raise ValueError(f"mesh: must be a quadratic MeshQuad2 or MeshTri2, got {type(mesh).__name__}")
    for name in REQUIRED_BOUNDARIES:
        if len(_facets(mesh, name)) == 0:
            raise ValueError(f"mesh: boundary '{name}' is empty")
    x = mesh.doflocs
    extent = float(np.ptp(x, axis=1).max())
    if x[0].min() < -1e-9 * extent:
        raise ValueError(f"mesh: points left of the axis (r down to {x[0].min() * 1e3:.4g} mm)")
    if x[1].min() < -1e-9 * extent:
        raise ValueError(f"mesh: points below the substrate plane z = 0 (z down to "
                         f"{x[1].min() * 1e3:.4g} mm); the undeformed cup may only touch it")
    det = mesh._mapping().detDF(mesh.elem.doflocs.T)
    if np.any(det <= 0):
        bad = int(np.argmax(np.any(det <= 0, axis=1)))
        raise ValueError(f"mesh: element {bad} is inverted or folded (Jacobian <= 0 at a node, "
                         f"near r = {x[0, mesh.t[0, bad]] * 1e3:.4g} mm, z = {x[1, mesh.t[0, bad]] * 1e3:.4g} mm)")


def signed_areas(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Twice the signed area of the triangle of each cell's first three corners (> 0: counter-clockwise)."""
    a, b, c = (points[cells[:, k]] for k in range(3))
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
