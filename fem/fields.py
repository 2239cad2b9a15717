"""Field export: displacement, Cauchy stress and contact pressure of a cup step through meshio.

The cells are the 9-node quadrilaterals (or 6-node triangles) of the reference mesh, so
ParaView's "Warp By Vector" with ``displacement`` shows the deformed cup. Point data:
``displacement`` [m] (3 components, u_theta = 0) and ``contact_pressure`` [Pa] (the projected
pressure of `fem.contact`, 0 off contact). Cell data: the element mean (over the 3x3 Gauss points,
weighted by dV) of the Cauchy stress ``sigma_rr, sigma_zz, sigma_tt, sigma_rz`` [Pa].

Formats: ``.vtu`` (or any single-step format meshio infers from the suffix) holds one step;
``.xdmf`` holds one step or the whole path as a time series whose "time" is the plate
displacement u [m] (ParaView's time slider then walks the compression). The XDMF is written with
its data inline as XML (meshio's `TimeSeriesWriter`, ``data_format="XML"``): one self-contained
file, no HDF5 library needed.

Provenance (the run that wrote the fields: design, contact law, mesh level, material; a JSON of
plain strings) rides in each format's own metadata: an XDMF ``<Information>`` of the Domain, a VTU
``<FieldData>`` array, a legacy VTK dataset ``FIELD`` array (the JSON's UTF-8 bytes, as UInt8 and as
doubles: types meshio and VTK both read). `read_provenance` reads it back.
"""

from __future__ import annotations

import json
import os
import secrets
from collections.abc import Mapping
from pathlib import Path
from typing import Protocol

import numpy as np
from skfem import Mesh

from .forms import Mechanics
from .kinematics import Kinematics
from .material import NeoHookean, cauchy_stress

__all__ = ["write_fields", "read_provenance", "element_cauchy_stress", "FieldSeries", "PROVENANCE"]

#: the name of the provenance record in a fields file
PROVENANCE = "cupcheck_provenance"


class FieldSeries(Protocol):
    """What the export reads of a path (`fem.cup.CupResponse` is one): the reference mesh, the
    material, and per step the plate displacement, the displacement and the nodal pressure."""

    mesh: Mesh
    material: NeoHookean
    u_m: np.ndarray
    displacements: tuple[np.ndarray, ...]
    nodal_pressure_Pa: tuple[np.ndarray, ...]


# scikit-fem's Q2 (P2) node order per element equals VTK's biquadratic quad (quadratic triangle)
# order: corners, then edge midpoints starting with edge 0-1, then the centre


def element_cauchy_stress(mech: Mechanics, u: np.ndarray) -> np.ndarray:
    """dV-weighted element means of (s_rr, s_zz, s_tt, s_rz) [4, nel] in Pa."""
    f = mech.kin.deformation_gradient(u)
    s = cauchy_stress(f, mech.stress(f))
    dV = mech.kin.dV
    return np.sum(s * dV, axis=2) / dV.sum(axis=1)


def write_fields(resp: FieldSeries, path: str | Path, step: int | None = -1,
                 provenance: Mapping[str, str] | None = None) -> Path:
    """Write step `step` of `resp` (None: every step, .xdmf only) to `path`, atomically, with the
    `provenance` record (if given) in the file's metadata."""
    import meshio           # here, not at import: a cup job that writes no fields does not load it

    path = Path(path)
    n_steps = len(resp.u_m)
    xdmf = path.suffix.lower() == ".xdmf"
    if step is None and not xdmf:
        raise ValueError(f"step: every step (None) needs an .xdmf time series, got '{path.name}'")
    if step is not None and not -n_steps <= step < n_steps:
        raise ValueError(f"step: must be in [{-n_steps}, {n_steps - 1}], got {step}")
    steps = range(n_steps) if step is None else [step % n_steps]
    kin = Kinematics.of(resp.mesh)
    mech = Mechanics(kin, resp.material)
    nodes = kin.dofs[0::2].T // 2            # node ids per element, in VTK's node order
    cells = [("quad9" if nodes.shape[1] == 9 else "triangle6", nodes)]
    points = np.column_stack([kin.mesh.doflocs.T, np.zeros(kin.mesh.doflocs.shape[1])])
    path.parent.mkdir(parents=True, exist_ok=True)
    # a unique sibling, created by the writer with the normal (umask) permissions (not mkstemp's 0600)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.{secrets.token_hex(4)}{path.suffix}")
    try:
        if xdmf:
            with meshio.xdmf.TimeSeriesWriter(tmp, data_format="XML") as series:
                if provenance is not None:
                    from xml.etree import ElementTree as ET
                    ET.SubElement(series.domain, "Information", Name=PROVENANCE, Value=_json(provenance))
                series.write_points_cells(points, cells)
                for k in steps:
                    series.write_data(float(resp.u_m[k]), *_step_data(resp, mech, k))
        else:
            point_data, cell_data = _step_data(resp, mech, steps[0])
            meshio.Mesh(points, cells, point_data=point_data, cell_data=cell_data).write(tmp)
            if provenance is not None:
                _add_field_data(tmp, _json(provenance).encode())
        os.replace(tmp, path)
    finally:
        Path(tmp).unlink(missing_ok=True)
    return path


def _step_data(resp: FieldSeries, mech: Mechanics, k: int) -> tuple[dict, dict]:
    """Point data (displacement, contact pressure) and cell data (Cauchy stress) of step k."""
    u = resp.displacements[k]
    disp = np.zeros((mech.kin.mesh.doflocs.shape[1], 3))
    disp[:, 0], disp[:, 1] = u[0::2], u[1::2]
    sig = element_cauchy_stress(mech, u)
    return ({"displacement": disp, "contact_pressure": resp.nodal_pressure_Pa[k]},
            {name: [sig[i]] for i, name in enumerate(("sigma_rr", "sigma_zz", "sigma_tt", "sigma_rz"))})



def read_provenance(path: str | Path) -> dict[str, str]:
    """The provenance record of a fields file written by `write_fields` ({} if it has none)."""
    path = Path(path)
    if path.suffix.lower() == ".xdmf":
        from xml.etree import ElementTree as ET
        info = ET.parse(path).getroot().find(f"Domain/Information[@Name='{PROVENANCE}']")
        text = None if info is None else info.get("Value")
    elif path.suffix.lower() == ".vtk":         # meshio drops a dataset's FIELD: read the record itself
        text = _vtk_field(path.read_bytes())
    else:
        import meshio
        data = meshio.read(path).field_data.get(PROVENANCE)
        text = None if data is None else np.asarray(data, np.uint8).tobytes().decode()
    if not text:
        return {}
    record = json.loads(text)
    return {str(k): str(v) for k, v in record.items()} if isinstance(record, dict) else {}


def _vtk_field(text: bytes) -> str | None:
    """The provenance record of a legacy .vtk's dataset FIELD (binary bytes or ASCII numbers)."""
    head = f"DATASET UNSTRUCTURED_GRID\nFIELD FieldData 1\n{PROVENANCE} 1 ".encode()
    start = text.find(head)
    if start < 0:
        return None
    count, rest = text[start + len(head):].split(b" double\n", 1)
    n = int(count)
    binary = b"\nBINARY\n" in text[:start + 1]
    codes = np.frombuffer(rest[:8 * n], ">f8") if binary else np.array(rest.split(b"\n", 1)[0].split(), float)
    return codes.astype(np.uint8).tobytes().decode()


def _json(provenance: Mapping[str, str]) -> str:
    return json.dumps({str(k): str(v) for k, v in provenance.items()}, ensure_ascii=False)


def _add_field_data(path: Path, record: bytes) -> None:
    """Add the provenance bytes to a meshio-written .vtu (a FieldData array) or legacy .vtk (a
    dataset FIELD array); meshio's writers take no field data of their own."""
    suffix = path.suffix.lower()
    if suffix == ".vtu":
        from xml.etree import ElementTree as ET
        tree = ET.parse(path)
        grid = tree.getroot().find("UnstructuredGrid")
        field = ET.Element("FieldData")
        ET.SubElement(field, "DataArray", type="UInt8", Name=PROVENANCE, NumberOfTuples=str(len(record)),
                      format="ascii").text = " ".join(str(b) for b in record)
        grid.insert(0, field)
        tree.write(path, encoding="utf-8", xml_declaration=True)
    elif suffix == ".vtk":
        text = path.read_bytes()
        head = b"DATASET UNSTRUCTURED_GRID\n"
        if head not in text:
            raise ValueError(f"path: cannot add the provenance to '{path.name}' (no unstructured grid)")
        binary = b"\nBINARY\n" in text.split(head, 1)[0]
        codes = np.frombuffer(record, np.uint8)       # as doubles: the one type VTK and meshio both read
        values = codes.astype(">f8").tobytes() if binary else " ".join(str(b) for b in codes).encode()
        field = b"FIELD FieldData 1\n" + f"{PROVENANCE} 1 {len(record)} double\n".encode() + values + b"\n"
        path.write_bytes(text.replace(head, head + field, 1))
    else:
        raise ValueError(f"path: a provenance record needs a .vtu, .vtk or .xdmf file, got '{path.name}'")
