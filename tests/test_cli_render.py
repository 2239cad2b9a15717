"""`cupcheck render`: a 3D view of a stiffness run's fields file, measured; bad input refused."""

import json

import numpy as np
import pandas as pd
import pytest
from matplotlib.image import imread

from validation.cli import main
from validation.render import probe_offscreen_rendering


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """Cup A, coarse, frictionless, pressed to 7.6 mm, every step in an .xdmf series."""
    d = tmp_path_factory.mktemp("stiffness")
    assert main(["stiffness", "--cup", "A", "--fidelity", "coarse", "--u-max-mm", "7.6",
                 "--fields-out", str(d / "f.xdmf"), "--out", str(d / "c.csv")]) == 0
    return d


def _gl():
    probe = probe_offscreen_rendering()
    if not probe.ok:
        pytest.skip(probe.message)


def test_footprint_of_a_fields_file_measures_the_curves_r_c(run, tmp_path):
    """The footprint drawn from the .xdmf's last step: the coloured pixels nearest the axis are at
    the r_c the stiffness CSV reports for that step (r_c_mm), within 2 pixels."""
    _gl()
    out = tmp_path / "fp.png"
    assert main(["render", str(run / "f.xdmf"), "--view", "footprint", "--out", str(out)]) == 0
    scale = json.loads(out.with_suffix(".json").read_text())
    img = imread(out)[..., :3]
    hi, lo = img.max(-1), img.min(-1)
    rows, cols = np.nonzero((hi - lo) / np.maximum(hi, 1e-9) > 0.25)
    cx, cy = scale["centre_px"]
    keep = np.abs(cols + 0.5 - cx) < 0.5 * img.shape[0]
    d = np.hypot(cols[keep] + 0.5 - cx, rows[keep] + 0.5 - cy)
    r_c_mm = pd.read_csv(run / "c.csv")["r_c_mm"].iloc[-1]
    assert abs(d.min() - 1e-3 * r_c_mm / scale["m_per_px"]) <= 2.0


def test_cutaway_and_squeeze_of_a_fields_file(run, tmp_path):
    _gl()
    from PIL import Image

    assert main(["render", str(run / "f.xdmf"), "--field", "von_mises", "--u-mm", "5", "--out",
                 str(tmp_path / "vm.png")]) == 0
    assert imread(tmp_path / "vm.png")[..., :3].std() > 0.05
    assert main(["render", str(run / "f.xdmf"), "--view", "squeeze", "--frames", "3", "--out",
                 str(tmp_path / "sq.gif")]) == 0
    with Image.open(tmp_path / "sq.gif") as gif:
        assert gif.n_frames == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sq.gif", "vm.png"]


@pytest.fixture
def titles(monkeypatch):
    """Every composed image saved during the test: its figure-level texts (the title) and the texts
    whose drawn box leaves the canvas (`validation.style.clipped_texts`)."""
    from validation import style

    seen, save = [], style.save_figure

    def measuring(fig, path, **kw):
        seen.append({"texts": [t.get_text() for t in fig.texts], "clipped": style.clipped_texts(fig)})
        return save(fig, path, **kw)

    monkeypatch.setattr(style, "save_figure", measuring)
    return seen


def test_the_fields_file_records_its_run_and_render_captions_with_it(run, tmp_path, titles):
    """The .xdmf of a coarse frictionless cup A run records design, law, mesh level and material
    (read back independently of the writer: the XDMF's Information element); the cut-away and
    every squeeze frame are captioned with them, the caption drawn whole inside the image."""
    _gl()
    from xml.etree import ElementTree as ET

    info = ET.parse(run / "f.xdmf").getroot().find("Domain/Information")
    record = json.loads(info.get("Value"))
    assert (record["design"], record["contact"], record["mesh"]) == ("cup A", "frictionless", "coarse")
    assert record["material"].startswith("neo-Hookean E = 4 MPa, nu = 0.49")
    assert main(["render", str(run / "f.xdmf"), "--out", str(tmp_path / "c.png")]) == 0
    assert main(["render", str(run / "f.xdmf"), "--view", "squeeze", "--frames", "2", "--out",
                 str(tmp_path / "s.gif")]) == 0
    assert [m["texts"] for m in titles] == [["cup A, frictionless, coarse mesh, u = 7.6 mm"],
                                            ["u = 0.00 mm, cup A, frictionless, coarse mesh"],
                                            ["u = 7.60 mm, cup A, frictionless, coarse mesh"]]
    assert all(m["clipped"] == [] for m in titles)


def test_a_fields_file_without_provenance_renders_captioned_unknown(run, tmp_path, titles):
    """An older fields file (the same .xdmf with its provenance element removed) still renders;
    the caption says the design, contact law and mesh level are unknown, unclipped."""
    _gl()
    from xml.etree import ElementTree as ET

    tree = ET.parse(run / "f.xdmf")
    domain = tree.getroot().find("Domain")
    domain.remove(domain.find("Information"))
    old = tmp_path / "old.xdmf"
    tree.write(old)
    assert main(["render", str(old), "--view", "footprint", "--out", str(tmp_path / "fp.png")]) == 0
    assert titles[0]["texts"] == ["design unknown, contact law unknown, mesh level unknown, from below, "
                                  "u = 7.6 mm"]
    assert titles[0]["clipped"] == []


@pytest.mark.parametrize("view,out", [("cutaway", "x.png"), ("squeeze", "x.gif")])
def test_an_unreadable_provenance_record_is_refused(run, tmp_path, capsys, view, out):
    from xml.etree import ElementTree as ET

    tree = ET.parse(run / "f.xdmf")
    tree.getroot().find("Domain/Information").set("Value", "{not json")
    bad = tmp_path / "bad.xdmf"
    tree.write(bad)
    assert main(["render", str(bad), "--view", view, "--out", str(tmp_path / out)]) == 2
    err = capsys.readouterr().err
    assert "fields: cannot read the provenance of 'bad.xdmf'" in err and err.count("\n") == 1
    assert [p.name for p in tmp_path.iterdir()] == ["bad.xdmf"]


@pytest.mark.parametrize("suffix", [".vtu", ".vtk"])
def test_a_single_step_file_records_the_coulomb_law_and_vtk_reads_the_record(tmp_path, titles, suffix):
    """Cup B, coarse, Coulomb mu = 0.5, the last step as .vtu/.vtk: VTK's own reader (pyvista) finds
    the provenance in the file's field data, and the cut-away is captioned with mu, unclipped."""
    _gl()
    import pyvista as pv

    fields = tmp_path / f"f{suffix}"
    assert main(["stiffness", "--cup", "B", "--fidelity", "coarse", "--contact", "coulomb", "--friction", "0.5",
                 "--u-max-mm", "0.4", "--fields-out", str(fields), "--out", str(tmp_path / "c.csv")]) == 0
    codes = np.asarray(pv.read(fields).field_data["cupcheck_provenance"]).astype(np.uint8)
    record = json.loads(codes.tobytes().decode())
    assert (record["design"], record["contact"], record["mesh"]) == ("cup B", "coulomb mu = 0.5", "coarse")
    assert main(["render", str(fields), "--field", "min_stretch", "--out", str(tmp_path / "c.png")]) == 0
    assert titles == [{"texts": ["cup B, coulomb mu = 0.5, coarse mesh, u = 0.4 mm"], "clipped": []}]


@pytest.mark.parametrize("argv,message", [
    (["--view", "squeeze", "--out", "x.png"], "out: the squeeze view writes a .gif file"),
    (["--frames", "1", "--view", "squeeze", "--out", "x.gif"], "frames: must be in [2, 60], got 1"),
    (["--u-mm", "-1", "--out", "x.png"], "u_mm: the plate displacement must be > 0 mm, got -1"),
    (["--u-mm", "nan", "--out", "x.png"], "u_mm: the plate displacement must be > 0 mm"),
    (["--field", "stress", "--out", "x.png"], "argument --field: invalid choice: 'stress'"),
    (["--frames", "5", "--out", "x.png"], "frames: only for --view squeeze"),
])
def test_bad_render_input_exits_2_and_writes_nothing(run, tmp_path, monkeypatch, capsys, argv, message):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) if "invalid choice" in message else _no_raise() as _:
        assert main(["render", str(run / "f.xdmf"), *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and list(tmp_path.iterdir()) == []


def test_a_foreign_file_is_refused(tmp_path, capsys):
    (tmp_path / "c.csv").write_text("u_mm\n1\n")
    (tmp_path / "g.vtu").write_text("not a mesh")
    assert main(["render", str(tmp_path / "c.csv"), "--out", str(tmp_path / "x.png")]) == 2
    assert main(["render", str(tmp_path / "g.vtu"), "--out", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("cupcheck render: error: fields: expected a .vtu") and "fields: cannot read" in err[1]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.csv", "g.vtu"]


class _no_raise:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False
