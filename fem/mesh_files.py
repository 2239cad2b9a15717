"""Cup cross-section meshes in files: `write_mesh` and `read_mesh` through meshio.

VTU, Gmsh ``.msh`` in format 2.2 and anything meshio reads, with coordinates in millimetres by
default. A file carries its tags as line cells (``line`` or ``line3``) named either by Gmsh
physical groups (``gmsh:physical`` + the group names) or by per-name 0/1 cell-data arrays
``boundary:<name>`` (VTU has no field data). A user's own Gmsh cross-section works if it has
physical curves named ``top_plate`` and ``cavity`` (``outer`` and ``rim`` are optional: contact is
checked on every boundary facet except ``top_plate``) and a 2D physical surface of
``triangle6``, ``quad9``, ``quad8``, or linear ``triangle``/``quad`` cells (linear cells get
straight-sided mid-side nodes). What is read is checked as a generated mesh is
(`fem.mesh.check_cup_mesh`).
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import replace
from pathlib import Path

import meshio
import numpy as np
from scipy.spatial import cKDTree
from skfem import Mesh, MeshQuad1, MeshQuad2, MeshTri1, MeshTri2

from .mesh import BOUNDARY_NAMES, check_cup_mesh, signed_areas

__all__ = ["write_mesh", "read_mesh"]

_UNITS = {"m": 1.0, "mm": 1e-3}
_MESHIO_CELL = {MeshQuad2: "quad9", MeshTri2: "triangle6"}


def write_mesh(mesh: Mesh, path: str | Path, unit: str = "mm") -> Path:
    """Write the mesh and its boundary tags through meshio (VTU, Gmsh 2.2 ``.msh``, ...).

    Each tagged boundary facet becomes a ``line3`` cell; the tags are stored as Gmsh physical
    groups (``.msh``: ``gmsh:physical`` and the group names) or as 0/1 cell-data arrays
    ``boundary:<name>`` (every other format). Coordinates are written in `unit` ("mm" or "m").
    """
    scale = _unit_scale(unit)
    path = Path(path)
    names = list((mesh.boundaries or {}).keys())
    facets = [np.asarray(mesh.boundaries[n]) for n in names]
    all_facets = np.concatenate(facets) if facets else np.zeros(0, int)
    lines = np.column_stack([mesh.facets[:, all_facets].T, mesh.dofs.facet_dofs[0, all_facets]])
    tag_of_line = np.concatenate([np.full(len(f), k + 1) for k, f in enumerate(facets)]) \
        if facets else np.zeros(0, int)
    n_cells = mesh.t.shape[1]
    surface_tag = len(names) + 1
    gmsh = path.suffix.lower() == ".msh"
    if gmsh:     # Gmsh physical groups: a tag per cell and the group names as field data
        cell_data = {key: [np.full(n_cells, surface_tag), tag_of_line]
                     for key in ("gmsh:physical", "gmsh:geometrical")}
        field_data = {name: np.array([k + 1, 1]) for k, name in enumerate(names)}
        field_data["wall"] = np.array([surface_tag, 2])
    else:        # formats without field data: one 0/1 indicator array per name
        cell_data = {f"boundary:{name}": [np.zeros(n_cells, int), (tag_of_line == k + 1).astype(int)]
                     for k, name in enumerate(names)}
        field_data = {}
    out = meshio.Mesh(
        np.column_stack([mesh.doflocs.T / scale, np.zeros(mesh.doflocs.shape[1])]),
        [(_MESHIO_CELL[type(mesh)], mesh.dofs.element_dofs.T), ("line3", lines)],
        cell_data=cell_data, field_data=field_data)
    path.parent.mkdir(parents=True, exist_ok=True)
    if gmsh:
        meshio.write(path, out, file_format="gmsh22", binary=False)
    else:
        meshio.write(path, out)
    return path


def read_mesh(path: str | Path, unit: str = "mm") -> Mesh:
    """Read a cup cross-section written by `write_mesh` or drawn in Gmsh (see the module docstring).

    Coordinates are multiplied by the unit's size in metres. Returns a checked `MeshQuad2` or
    `MeshTri2` in metres whose ``boundaries`` hold every tagged name (the four standard names
    always, possibly empty for ``outer`` and ``rim``).
    """
    scale = _unit_scale(unit)
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"mesh: no such file '{path}'")
    fmt = {".msh": "gmsh", ".vtu": "vtu", ".vtk": "vtk", ".xdmf": "xdmf"}.get(path.suffix.lower())
    try:   # meshio prints and may sys.exit() on an unreadable file: keep both inside
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            m = meshio.read(path, file_format=fmt)
    except (Exception, SystemExit) as exc:
        raise ValueError(f"mesh: cannot read '{path}': {exc}".replace("\n", " ")) from None
    mesh = _volume_mesh(m, scale, path)
    extent = float(np.ptp(mesh.doflocs, axis=1).max())
    if not 1e-4 <= extent <= 10.0:
        raise ValueError(f"mesh: '{path}' spans {extent:.3g} m with unit '{unit}'; "
                         f"give the file's length unit (mm or m)")
    boundaries = _tagged_boundaries(m, mesh, scale, path)
    for name in BOUNDARY_NAMES:
        boundaries.setdefault(name, np.zeros(0, dtype=np.int64))
    mesh = replace(mesh, _boundaries=boundaries)
    check_cup_mesh(mesh)
    return mesh


def _unit_scale(unit: str) -> float:
    if unit not in _UNITS:
        raise ValueError(f"mesh unit: must be one of {', '.join(_UNITS)}, got {unit!r}")
    return _UNITS[unit]


def _volume_mesh(m: meshio.Mesh, scale: float, path: Path) -> Mesh:
    kinds = [c.type for c in m.cells if c.type in ("triangle", "triangle6", "quad", "quad8", "quad9")]
    if len(set(kinds)) != 1:
        raise ValueError(f"mesh: '{path}' must hold one kind of 2D cell (triangle[6] or quad[8|9]), "
                         f"found {sorted(set(kinds)) or 'none'}")
    kind = kinds[0]
    cells = np.concatenate([c.data for c in m.cells if c.type == kind])
    _check_cells(cells, len(m.points), path, "element")
    if m.points.shape[1] > 2 and np.ptp(m.points[:, 2]) > 1e-9 * np.ptp(m.points[:, :2]):
        raise ValueError(f"mesh: '{path}' is not planar; draw the (r, z) cross-section in the x-y plane")
    points = np.asarray(m.points[:, :2], dtype=float) * scale
    if np.median(signed_areas(points, cells[:, :3])) < 0:
        cells = _reverse_orientation(cells, kind)   # drawn clockwise: make it counter-clockwise
    if kind in ("triangle", "quad"):
        linear = (MeshTri1 if kind == "triangle" else MeshQuad1)(points.T, cells.T, sort_t=False)
        return (MeshTri2 if kind == "triangle" else MeshQuad2).from_mesh(linear)
    if kind == "quad8":   # add the centre node of the serendipity quad
        centre = -0.25 * points[cells[:, :4]].sum(1) + 0.5 * points[cells[:, 4:8]].sum(1)
        cells = np.column_stack([cells, len(points) + np.arange(len(cells))])
        points = np.vstack([points, centre])
    return (MeshTri2 if kind == "triangle6" else MeshQuad2)(points.T, cells.T)


def _check_cells(cells: np.ndarray, n_points: int, path: Path, what: str, repeats: bool = True) -> None:
    """Every cell names existing nodes, each once, and (`repeats`) no cell is given twice: a
    ValueError naming the file and the cell (counted from 1 in its kind), never an IndexError."""
    cells = np.asarray(cells)
    outside = np.flatnonzero(((cells < 0) | (cells >= n_points)).any(axis=1))
    if outside.size:
        k = int(outside[0])
        node = int(cells[k][(cells[k] < 0) | (cells[k] >= n_points)][0])
        raise ValueError(f"mesh: '{path}': {what} {k + 1} refers to node {node + 1}, but the file "
                         f"has nodes 1 .. {n_points}")
    ordered = np.sort(cells, axis=1)
    twice = np.flatnonzero((ordered[:, 1:] == ordered[:, :-1]).any(axis=1))
    if twice.size:
        raise ValueError(f"mesh: '{path}': {what} {int(twice[0]) + 1} names one node twice")
    if repeats:
        seen: dict[bytes, int] = {}
        for k, row in enumerate(ordered):
            first = seen.setdefault(row.tobytes(), k)
            if first != k:
                raise ValueError(f"mesh: '{path}': {what} {k + 1} repeats {what} {first + 1} (the same nodes)")


def _reverse_orientation(cells: np.ndarray, kind: str) -> np.ndarray:
    """Cells with their corner order reversed (mid-side nodes follow their edges)."""
    order = {"triangle": [0, 2, 1], "quad": [0, 3, 2, 1], "triangle6": [0, 2, 1, 5, 4, 3],
             "quad8": [0, 3, 2, 1, 7, 6, 5, 4], "quad9": [0, 3, 2, 1, 7, 6, 5, 4, 8]}[kind]
    return cells[:, order]


def _tagged_boundaries(m: meshio.Mesh, mesh: Mesh, scale: float, path: Path) -> dict[str, np.ndarray]:
    """Facet indices of every named boundary in the file, matched by edge midpoint."""
    vertex_pairs: dict[str, list[np.ndarray]] = {}
    names_by_tag = {int(v[0]): k for k, v in m.field_data.items() if len(v) >= 2 and int(v[1]) == 1}
    for i, block in enumerate(m.cells):
        if block.type not in ("line", "line3"):
            continue
        _check_cells(block.data, len(m.points), path, "boundary edge", repeats=False)
        ends = block.data[:, :2]
        for key, arrays in m.cell_data.items():
            data = np.asarray(arrays[i]).astype(int)
            if key == "gmsh:physical":
                for tag in np.unique(data):
                    if tag in names_by_tag:
                        vertex_pairs.setdefault(names_by_tag[tag], []).append(ends[data == tag])
            elif key.startswith("boundary:"):
                vertex_pairs.setdefault(key.split(":", 1)[1], []).append(ends[data != 0])
        for name, sets in m.cell_sets.items():
            if i < len(sets) and sets[i] is not None and len(sets[i]) and not name.startswith("gmsh:"):
                vertex_pairs.setdefault(name, []).append(ends[np.asarray(sets[i], int)])
    if not vertex_pairs:
        raise ValueError(f"mesh: '{path}' has no named boundary; tag the curves "
                         f"{', '.join(BOUNDARY_NAMES)} (Gmsh physical groups)")
    points = np.asarray(m.points[:, :2], dtype=float) * scale
    facet_mid = 0.5 * (mesh.doflocs[:, mesh.facets[0]] + mesh.doflocs[:, mesh.facets[1]]).T
    extent = np.ptp(mesh.doflocs, axis=1).max()
    tree = cKDTree(facet_mid / extent)
    out: dict[str, np.ndarray] = {}
    for name, pairs in vertex_pairs.items():
        ends = np.unique(np.concatenate(pairs), axis=0)
        mids = 0.5 * (points[ends[:, 0]] + points[ends[:, 1]])
        dist, idx = tree.query(mids / extent)
        if np.any(dist > 1e-8):
            raise ValueError(f"mesh: {int(np.sum(dist > 1e-8))} edge(s) tagged '{name}' in '{path}' "
                             f"are not edges of the 2D cells")
        out[name] = np.unique(idx).astype(np.int64)
    return out
