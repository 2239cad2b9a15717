"""One deformed state of the cup as plain data for the 3D views: `CupFrame`.

A frame holds the deformed node positions, the cells, the closed boundary loop, the nodal fields
(`fem.recovery.FIELDS`, SI units) and the contact zones along the plane. It comes from a FEM
response (`frame_from_response`) or from a fields file written by ``cupcheck stiffness
--fields-out`` (`frame_from_fields_file`: .vtu/.vtk one step, .xdmf a time series over u), so every
view draws both the same way.

Contact zones: runs of loaded nodes along the plane, sorted by deformed radius. The inner edge of
the innermost zone is r_c as the FEM defines it (`fem.postprocess.inner_contact_radius`, the
square-root edge between the free and the first loaded node); the other edges are the same
square-root rule mirrored, clamped between the last loaded node and its free neighbour; a zone of
one loaded node (the rim corner alone) is a line contact of zero width.
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["CupFrame", "frame_from_response", "frame_from_fields_file", "fields_file_steps", "contact_zones_of",
           "boundary_loop"]


@dataclass(frozen=True, eq=False)
class CupFrame:
    """A deformed state: positions (r, z) [m] of every node, cells (node ids, VTK/skfem order),
    the boundary loop (node ids, closed), nodal fields [SI], the contact zones [(r_in, r_out)] [m]
    and the undeformed positions (the cup's own size, for a scale fixed over all states)."""

    u_m: float
    points_m: np.ndarray
    cells: np.ndarray
    loop: np.ndarray
    fields: dict[str, np.ndarray]
    zones_m: tuple[tuple[float, float], ...]
    rest_points_m: np.ndarray | None = None

    @property
    def r_c_m(self) -> float | None:
        """The inner contact radius r_c [m] (None without contact)."""
        return self.zones_m[0][0] if self.zones_m else None

    @property
    def r_out_m(self) -> float | None:
        """The outer edge of the outermost contact zone [m] (None without contact)."""
        return self.zones_m[-1][1] if self.zones_m else None


def frame_from_response(resp, step: int = -1, fields: tuple[str, ...] | None = None) -> CupFrame:
    """The frame of step `step` of a `fem.cup.CupResponse`, with the fields named (default: all)."""
    from fem.recovery import FIELDS, nodal_field

    names = tuple(FIELDS) if fields is None else fields
    u = resp.displacements[step]
    data = {n: nodal_field(resp, n, step) for n in names}
    return _frame(resp.mesh, u, float(resp.u_m[step]), resp.nodal_pressure_Pa[step], data)


def frame_from_fields_file(path: str | Path, u_mm: float | None = None,
                           fields: tuple[str, ...] | None = None) -> CupFrame:
    """The frame of a fields file (``cupcheck stiffness --fields-out``): a .vtu/.vtk step, or the
    step of an .xdmf series nearest `u_mm` (default its last). The von Mises stress is the L2
    projection of the file's element-mean Cauchy stress, the smallest stretch that of the file's
    displacement, the contact pressure the recovery of its lumped nodal pressure."""
    from skfem import MeshQuad2, MeshTri2

    from fem.kinematics import Kinematics
    from fem.postprocess import smallest_stretch
    from fem.recovery import FIELDS, project_to_nodes, smooth_contact_pressure, von_mises

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"fields: no such file '{path}'")
    try:      # meshio prints and may sys.exit() on an unreadable file: keep both inside
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            points, cells, point_data, cell_data, t = _read(path, u_mm)
    except (Exception, SystemExit) as exc:
        raise ValueError(f"fields: cannot read '{path}': {exc}".replace("\n", " ")) from None
    block = next((c for c in cells if c.type in ("quad9", "triangle6")), None)
    missing = [k for k in ("displacement", "contact_pressure") if k not in point_data]
    if block is None or missing:
        raise ValueError(f"fields: '{path.name}' is not a cupcheck fields file (needs quad9 or triangle6 cells "
                         f"and point data displacement, contact_pressure; missing {missing or 'the cells'})")
    conn = np.asarray(block.data)
    mesh = (MeshQuad2 if block.type == "quad9" else MeshTri2)(np.asarray(points)[:, :2].T, conn.T)
    disp = np.asarray(point_data["displacement"], float)
    u = np.zeros(2 * disp.shape[0])
    u[0::2], u[1::2] = disp[:, 0], disp[:, 1]
    plate_u = float(t) if t is not None else float(-disp[np.argmax(points[:, 1]), 1])
    p_lumped = np.asarray(point_data["contact_pressure"], float)
    names = tuple(FIELDS) if fields is None else fields
    kin = Kinematics.of(mesh)
    data: dict[str, np.ndarray] = {}
    if "contact_pressure" in names:
        data["contact_pressure"] = smooth_contact_pressure(mesh, u, p_lumped)
    if "min_stretch" in names:
        data["min_stretch"] = project_to_nodes(kin, smallest_stretch(kin.deformation_gradient(u)))
    if "von_mises" in names:
        sig = np.stack([np.asarray(cell_data[f"sigma_{c}"][0], float) for c in ("rr", "zz", "tt", "rz")])
        data["von_mises"] = project_to_nodes(kin, np.repeat(von_mises(sig)[:, None], kin.dV.shape[1], axis=1))
    return _frame(mesh, u, plate_u, p_lumped, data)


def _read(path: Path, u_mm: float | None):
    """(points, cells, point data, cell data, u [m] or None) of a fields file's step."""
    import meshio

    if path.suffix.lower() == ".xdmf":
        with meshio.xdmf.TimeSeriesReader(str(path)) as series:
            points, cells = series.read_points_cells()
            times = [series.read_data(k)[0] for k in range(series.num_steps)]
            k = len(times) - 1 if u_mm is None else int(np.argmin(np.abs(np.array(times) - 1e-3 * u_mm)))
            t, point_data, cell_data = series.read_data(k)
        return points, cells, point_data, cell_data, t
    m = meshio.read(str(path))
    return m.points, m.cells, m.point_data, m.cell_data, None


def fields_file_steps(path: str | Path) -> list[float]:
    """The plate displacements u [m] of the steps in a fields file (one, unknown, for .vtu/.vtk: [nan])."""
    import meshio

    path = Path(path)
    if path.suffix.lower() != ".xdmf":
        return [float("nan")]
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()), \
                meshio.xdmf.TimeSeriesReader(str(path)) as series:
            series.read_points_cells()
            return [float(series.read_data(k)[0]) for k in range(series.num_steps)]
    except (Exception, SystemExit) as exc:
        raise ValueError(f"fields: cannot read '{path}': {exc}".replace("\n", " ")) from None


def _frame(mesh, u: np.ndarray, u_plate_m: float, p_lumped: np.ndarray, data: dict) -> CupFrame:
    x = mesh.doflocs + np.stack([u[0::2], u[1::2]])
    from fem.kinematics import Kinematics
    cells = Kinematics.of(mesh).dofs[0::2].T // 2     # node ids per element, VTK's order
    return CupFrame(u_m=u_plate_m, points_m=x.T.copy(), cells=np.asarray(cells), loop=boundary_loop(mesh),
                    fields=data, zones_m=contact_zones_of(mesh, x, p_lumped), rest_points_m=mesh.doflocs.T.copy())


def boundary_loop(mesh) -> np.ndarray:
    """The node ids around the whole boundary of the cross-section, vertices and midpoints, closed
    (the first node is not repeated)."""
    nv = int(mesh.t.max()) + 1                     # vertices first, then one midpoint per facet
    bf = mesh.boundary_facets()
    ends = mesh.facets[:, bf]
    by_vertex: dict[int, list[int]] = {}
    for k in range(ends.shape[1]):
        for v in ends[:, k]:
            by_vertex.setdefault(int(v), []).append(k)
    start = int(ends[0, 0])
    loop, used, v = [start], set(), start
    for _ in range(ends.shape[1]):
        k = next((k for k in by_vertex[v] if k not in used), None)
        if k is None:
            break
        used.add(k)
        a, b = ends[:, k]
        v = int(b if a == v else a)
        loop += [nv + int(bf[k]), v]
    return np.asarray(loop[:-1])


def contact_zones_of(mesh, x: np.ndarray, p_lumped: np.ndarray) -> tuple[tuple[float, float], ...]:
    """The contact zones [(r_in, r_out)] [m] of a state (module docstring)."""
    from fem.postprocess import inner_contact_radius

    nv = int(mesh.t.max()) + 1
    bf = mesh.boundary_facets()
    fn = np.vstack([mesh.facets[:, bf], nv + bf])
    fn = fn[:, np.any(p_lumped[fn] > 0, axis=0)]
    if fn.shape[1] == 0:
        return ()
    nodes = np.unique(fn)
    order = np.argsort(x[0, nodes], kind="stable")
    r, p = x[0, nodes][order], p_lumped[nodes][order]
    keep = np.concatenate([[True], np.diff(r) > 0])            # as `fem.cup` does
    r, p = r[keep], p[keep]
    loaded = p > 0
    zones, k = [], 0
    while k < r.size:
        if not loaded[k]:
            k += 1
            continue
        j = k
        while j + 1 < r.size and loaded[j + 1]:
            j += 1
        lo, hi = max(k - 1, 0), min(j + 1, r.size - 1)
        r_in = inner_contact_radius(r[lo:j + 1], p[lo:j + 1]) if j + 1 - lo >= 2 else float(r[k])
        r_out = -inner_contact_radius(-r[k:hi + 1][::-1], p[k:hi + 1][::-1]) if hi + 1 - k >= 2 else float(r[j])
        zones.append((float(min(r_in, r[k])), float(max(r_out, r[j]))))
        k = j + 1
    return tuple(zones)
