"""`cupcheck stiffness` end to end (small u so it stays fast), and its bad-input contract."""

import json
from pathlib import Path

import numpy as np
import pytest

from reduced.stiffness_curve import StiffnessCurve
from validation.cli import main

REPO = Path(__file__).resolve().parents[1]
U_MAX_MM = "0.8"     # a few steps of the coarse mesh: ~0.3 s


def _files(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.rglob("*"))


def test_writes_a_curve_the_reduced_model_reads_and_its_sidecar(tmp_path, capsys):
    out = tmp_path / "curve.csv"
    assert main(["stiffness", "--cup", "A", "--contact", "sticking", "--u-max-mm", U_MAX_MM,
                 "--out", str(out), "--fields-out", str(tmp_path / "fields.vtu")]) == 0
    assert _files(tmp_path) == ["curve.csv", "curve.json", "fields.vtu"]
    header = [line for line in out.read_text().splitlines() if not line.startswith("#")][0]
    assert header == "u_mm,h_mm,F0_N,r_c_mm,l_mm,V_mm3"
    curve = StiffnessCurve.from_csv(out)
    assert curve.h1_m == pytest.approx(14e-3 * np.tan(np.radians(33)), rel=1e-9)
    assert curve.u_range_m == pytest.approx((0.0, 0.8e-3))
    assert curve.provenance["source"] == "fem" and curve.provenance["contact"] == "sticking"
    assert curve.provenance["material"]["E_Pa"] == 4e6
    side = json.loads((tmp_path / "curve.json").read_text())
    assert side["provenance"] == curve.provenance
    for key in ("steps", "newton_iterations", "wall_time_s", "dofs", "largest_penetration_m"):
        assert key in side["solver"]
    steps = side["steps"]
    assert np.allclose(steps["u_mm"], curve.u_m * 1e3, rtol=1e-9, atol=1e-12)
    assert np.allclose(steps["F0_N"], curve.F0_N, rtol=1e-8, atol=1e-12)
    # equilibrium: the plate reaction equals the integrated contact force (the core's check)
    assert np.allclose(steps["F0_contact_N"], steps["F0_N"], rtol=1e-3, atol=1e-6)
    # at u = 0 the undeformed cavity is the frustum of eq. (4) at h = h1
    assert curve.V_m3[0] == pytest.approx(np.pi / 3 * curve.h1_m * (25 + 95 + 361) * 1e-6, rel=1e-9)
    assert "F0 =" in capsys.readouterr().out


def test_user_mesh_and_geometry_file(tmp_path):
    out = tmp_path / "lip.csv"
    assert main(["stiffness", "--mesh", str(REPO / "meshes" / "user_lip.msh"),
                 "--u-max-mm", "0.5", "--out", str(out)]) == 0
    prov = StiffnessCurve.from_csv(out).provenance
    assert prov["mesh"]["file"].endswith("user_lip.msh") and prov["fidelity"] is None
    geo = tmp_path / "cup.toml"
    geo.write_text('cup = "B"\nalpha_deg = 25\n[thickness]\nr_mm = [5, 19]\nd_mm = [1.5, 0.5]\n')
    out = tmp_path / "geo.csv"
    assert main(["stiffness", "--geometry", str(geo), "--thickness-convention", "vertical",
                 "--u-max-mm", "0.4", "--out", str(out)]) == 0
    g = StiffnessCurve.from_csv(out).provenance["geometry"]
    assert (g["alpha_deg"], g["thickness_convention"], g["d_at_r1_mm"]) == (25.0, "vertical", 0.5)


@pytest.mark.parametrize("argv,field", [
    (["--E-MPa", "-4"], "E_MPa"),
    (["--nu", "0.5"], "nu"),
    (["--u-max-mm", "50"], "u_max_mm"),
    (["--u-max-mm", "9.2"], "u_max_mm"),          # just beyond h1 = 9.09 mm of cup A
    (["--u-max-mm", "0"], "u_max_mm"),
    (["--geometry", "missing.toml"], "geometry"),
    (["--mesh", "missing.msh"], "mesh"),
    (["--mesh", "meshes/user_lip.msh", "--fidelity", "fine"], "mesh"),
    (["--mesh", "meshes/user_lip.msh", "--mesh-unit", "m"], "mesh"),
    (["--fields-out", "f.vtk"], "fields_out"),
])
def test_bad_input_exits_2_with_one_line_and_no_output(tmp_path, capsys, monkeypatch, argv, field):
    monkeypatch.chdir(REPO)
    out = tmp_path / "curve.csv"
    assert main(["stiffness", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"cupcheck stiffness: error: {field}") and "\n" not in err
    assert _files(tmp_path) == []


def test_output_must_be_a_csv_file(tmp_path, capsys):
    assert main(["stiffness", "--out", str(tmp_path / "curve.txt")]) == 2
    assert "out:" in capsys.readouterr().err
    assert _files(tmp_path) == []


def test_h1_typed_in_mm_is_full_flattening_not_an_error():
    # 1e3 h1 in full precision, times 1e-3, can land one ulp above h1: that is h1, not "beyond h1"
    import argparse

    from fem.geometry import cup_geometry
    from validation.commands import stiffness
    h1 = cup_geometry("B").h1_m
    parser = argparse.ArgumentParser()
    stiffness.add_arguments(parser)
    args = parser.parse_args(["--cup", "B", "--u-max-mm", repr(1e3 * h1), "--out", "c.csv"])
    assert stiffness._prepare(args)["u_max_m"] == h1
    args = parser.parse_args(["--cup", "B", "--u-max-mm", repr(1e3 * h1 * (1 + 1e-6)), "--out", "c.csv"])
    with pytest.raises(ValueError, match=r"u_max_mm: .* \(0, 5.37409649\] mm, got 5.37410186"):
        stiffness._prepare(args)
