"""Readers that never crash (issue 26): suction tables and stiffness sidecars that are valid JSON
with wrong types, meshes with an out-of-range node or a repeated element, each answered by one
ValueError naming the file and the field, never another exception."""

import json
from pathlib import Path

import meshio
import numpy as np
import pytest

from fem.mesh_files import read_mesh
from reduced.design import ContactRecord, CupShape
from reduced.stiffness_curve import StiffnessCurve
from reduced.suction_table import SuctionTable
from tests.catalogue.bad_inputs import GOOD_CURVE, GOOD_TABLE

ROOT = Path(__file__).resolve().parents[1]
#: values of every wrong JSON type (and a ragged list) to put where the reader expects another
WRONG = ["text", None, True, 7, {"a": 1}, [[1, 2], [3]], ["a", "b"], [[None, None], [None, None]]]


def _good_profile_table() -> dict:
    return {**GOOD_TABLE, "profiles": [[{"r_mm": [10, 11], "p_kPa": [5, 6]}, None], [None, None]]}


def test_a_good_table_reads_back():
    table = SuctionTable.from_json(_write(_good_profile_table()))
    assert table.F1_N.shape == (2, 2) and table.profiles[0][0].p_Pa[1] == pytest.approx(6e3)
    assert table.h1_m == pytest.approx(9.09e-3)


def _write(data, name="t.json") -> Path:
    path = Path(pytest.tmp) / name
    path.write_text(json.dumps(data))
    return path


@pytest.fixture(autouse=True)
def _tmp(tmp_path):
    pytest.tmp = tmp_path


def _paths(data, prefix=()):
    """Every key path of nested dicts and lists (lists of rows: their first item)."""
    yield prefix
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(data, list) and data:
        yield from _paths(data[0], prefix + (0,))


def _replaced(data, path, value):
    if not path:
        return value
    copy = json.loads(json.dumps(data))
    node = copy
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return copy


def _cases(base):
    return [(path, value) for path in _paths(base) for value in WRONG]


@pytest.mark.parametrize("path,value", _cases(_good_profile_table()))
def test_a_suction_table_with_a_wrong_type_is_one_line_naming_the_file(path, value):
    data = _replaced(_good_profile_table(), path, value)
    where = _write(data)
    try:
        SuctionTable.from_json(where)
    except ValueError as exc:
        message = str(exc)
        assert f"{where}" in message and "\n" not in message
        if path:                                       # the field is named as the file spells it
            assert any(str(k) in message for k in path if isinstance(k, str)), message
    # a wrong value that is still meaningful (a profile set to null) reads: no other exception


SIDECAR = {"provenance": {"geometry": {"r0_mm": 5, "r1_mm": 19, "alpha_deg": 33, "h1_mm": 9}, "contact": "coulomb",
                          "friction": 0.3, "source": "fem"},
           "steps": {"pressure_r_mm": [[10, 11]] * 9, "pressure_kPa": [[5, 6]] * 9}}


def test_a_good_sidecar_reads_back():
    (Path(pytest.tmp) / "c.csv").write_text(GOOD_CURVE)
    _write(SIDECAR, "c.json")
    curve = StiffnessCurve.from_csv(Path(pytest.tmp) / "c.csv")
    assert curve.contact == ContactRecord("coulomb", 0.3, None)
    assert curve.design.same_cup(CupShape(r0_m=5e-3, r1_m=19e-3, alpha_deg=33.0, h1_m=9e-3))
    assert curve.design.h1_m == pytest.approx(9e-3) and curve.design.name is None


@pytest.mark.parametrize("path,value", [c for c in _cases(SIDECAR) if c[0]])
def test_a_sidecar_with_a_wrong_type_is_one_line_naming_the_file(path, value):
    (Path(pytest.tmp) / "c.csv").write_text(GOOD_CURVE)
    side = _write(_replaced(SIDECAR, path, value), "c.json")
    try:
        curve = StiffnessCurve.from_csv(Path(pytest.tmp) / "c.csv")
    except ValueError as exc:
        assert f"'{side}'" in str(exc) and "\n" not in str(exc)
        return
    curve.design, curve.contact                      # what the curve reads from it works


def _shipped_mesh() -> meshio.Mesh:
    return meshio.read(ROOT / "meshes" / "cupA_coarse.msh")


@pytest.mark.parametrize("suffix", [".vtu", ".msh"])
def test_a_mesh_with_a_node_out_of_range(suffix):
    m = _shipped_mesh()
    block = next(c for c in m.cells if c.dim == 2)
    block.data[3, 2] = len(m.points) + 5
    path = Path(pytest.tmp) / f"m{suffix}"
    meshio.write(path, m, file_format="gmsh22" if suffix == ".msh" else None, binary=False)
    with pytest.raises(ValueError, match=r"mesh: .*(element 4 refers to node \d+, but the file has nodes 1 \.\. 657"
                                         r"|cannot read .* out of bounds)"):
        read_mesh(path)


def test_a_mesh_with_a_repeated_element():
    m = _shipped_mesh()
    i = next(k for k, c in enumerate(m.cells) if c.dim == 2)
    block = m.cells[i]
    m.cells[i] = meshio.CellBlock(block.type, np.vstack([block.data, block.data[7:8]]))
    for key in m.cell_data:
        m.cell_data[key][i] = np.append(m.cell_data[key][i], m.cell_data[key][i][7])
    path = Path(pytest.tmp) / "m.vtu"
    meshio.write(path, m)
    with pytest.raises(ValueError, match=rf"mesh: '{path}': element {len(block.data) + 1} repeats element 8"):
        read_mesh(path)
