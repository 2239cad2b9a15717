"""`cupcheck stiffness` end to end (coarse mesh, small u, so it stays fast), and its bad-input
contract for the values (the output paths, argparse errors and solver failures: test_cli_errors.py)."""

import json
from pathlib import Path

import numpy as np
import pytest

from reduced.stiffness_curve import StiffnessCurve
from validation.cli import main

REPO = Path(__file__).resolve().parents[1]
U_MAX_MM = "0.8"     # a few steps of the coarse mesh: ~0.3 s
COARSE = ["--fidelity", "coarse"]


def _files(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.rglob("*"))


def test_writes_a_curve_the_reduced_model_reads_and_its_sidecar(tmp_path, capsys):
    out = tmp_path / "curve.csv"
    assert main(["stiffness", "--cup", "A", "--contact", "sticking", "--u-max-mm", U_MAX_MM, *COARSE,
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
    for key in ("steps", "newton_iterations", "wall_time_s", "dofs", "largest_penetration_mm"):
        assert key in side["solver"]
    # one unit per quantity: no SI length beside the mm ones
    assert not [k for k in (*side["solver"], *side["steps"]) if k.endswith("_m")]
    steps = side["steps"]
    assert np.allclose(steps["u_mm"], curve.u_m * 1e3, rtol=1e-9, atol=1e-12)
    assert np.allclose(steps["F0_N"], curve.F0_N, rtol=1e-8, atol=1e-12)
    # equilibrium: the plate reaction equals the integrated contact force (the core's check)
    assert np.allclose(steps["F0_contact_N"], steps["F0_N"], rtol=1e-3, atol=1e-6)
    # at u = 0 the undeformed cavity is the frustum of eq. (4) at h = h1
    assert curve.V_m3[0] == pytest.approx(np.pi / 3 * curve.h1_m * (25 + 95 + 361) * 1e-6, rel=1e-9)
    out_err = capsys.readouterr()
    assert "F0 =" in out_err.out
    assert " mm of " in out_err.err and "[m]" not in out_err.err      # progress in the CLI's unit
    n = len(curve.u_m)
    assert len(steps["unstable"]) == n and all(isinstance(f, bool) for f in steps["unstable"])
    assert side["solver"]["largest_penetration_mm"] == pytest.approx(max(map(abs, steps["penetration_mm"])))
    # the pressure profile p(r) per step, against the curve's r_c and F0 (the contact zone's inner
    # edge and its load): independent of how the sidecar stores it, a wrong unit fails by 1e3
    assert len(steps["pressure_r_mm"]) == len(steps["pressure_kPa"]) == n
    assert steps["pressure_r_mm"][0] == []                  # nothing touches at u = 0 ...
    for k in range(1, n):                                   # ... and the rim corner from then on
        r, p = np.array(steps["pressure_r_mm"][k]), np.array(steps["pressure_kPa"][k])
        assert r.shape == p.shape and np.all(np.diff(r) >= 0) and np.all(p >= 0) and p.max() > 0
        # r_c lies between the innermost loaded node and its free neighbour (fem.postprocess)
        loaded = np.flatnonzero(p > 0)[0]
        assert r[loaded] >= curve.r_c_m[k] * 1e3 - 1e-9
        assert loaded == 0 or r[loaded - 1] <= curve.r_c_m[k] * 1e3 + 1e-9
        # F0 = sum p_a int N_a dA <= max p times the contact facets' area, which the nodes span
        # (1 % for facets that are not quite flat on the plane at a free end)
        band_m2 = np.pi * (r[-1] ** 2 - r[0] ** 2) * 1e-6
        assert curve.F0_N[k] <= 1.01 * p.max() * 1e3 * band_m2


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
                 "--u-max-mm", "0.4", *COARSE, "--out", str(out)]) == 0
    g = StiffnessCurve.from_csv(out).provenance["geometry"]
    assert (g["alpha_deg"], g["thickness_convention"], g["d_at_r1_mm"]) == (25.0, "vertical", 0.5)


def test_cup_b_writes_every_step_as_an_xdmf_time_series_meshio_reads(tmp_path):
    import meshio

    out, fields = tmp_path / "cupB.csv", tmp_path / "fields.XDMF"      # the suffix in any case
    assert main(["stiffness", "--cup", "B", "--u-max-mm", U_MAX_MM, *COARSE,
                 "--out", str(out), "--fields-out", str(fields)]) == 0
    assert _files(tmp_path) == ["cupB.csv", "cupB.json", "fields.XDMF"]
    curve = StiffnessCurve.from_csv(out)
    assert curve.h1_m == pytest.approx(14e-3 * np.tan(np.radians(21)), rel=1e-9)
    assert curve.provenance["geometry"]["alpha_deg"] == 21
    with meshio.xdmf.TimeSeriesReader(fields) as series:
        points, cells = series.read_points_cells()
        assert [c.type for c in cells] == ["quad9"]
        assert series.num_steps == len(curve.u_m)
        # the plate's cavity-side corner (r0, h1) follows the plate: displacement (0, -u) per step
        corner = np.argmin(np.hypot(points[:, 0] - 5e-3, points[:, 1] - curve.h1_m))
        for k in (1, series.num_steps - 1):
            u_m, point_data, cell_data = series.read_data(k)
            assert u_m == pytest.approx(curve.u_m[k], rel=1e-12)
            assert point_data["displacement"][corner, :2] == pytest.approx([0.0, -u_m], abs=1e-12)
            assert set(cell_data) == {"sigma_rr", "sigma_zz", "sigma_tt", "sigma_rz"}


def test_mixed_formulation_runs_nearly_incompressible(tmp_path, capsys):
    out = tmp_path / "mixed.csv"
    assert main(["stiffness", "--formulation", "mixed", "--nu", "0.4999", "--u-max-mm", "0.5",
                 *COARSE, "--out", str(out)]) == 0
    curve = StiffnessCurve.from_csv(out)
    assert curve.provenance["material"] == {"law": "compressible neo-Hookean", "E_Pa": 4e6,
                                            "nu": 0.4999, "formulation": "mixed"}
    assert np.all(np.diff(curve.F0_N) > 0)                  # frictionless, small u: F0 rises


def test_displacement_formulation_refuses_nu_where_it_locks(tmp_path, capsys):
    out = tmp_path / "c.csv"
    assert main(["stiffness", "--formulation", "displacement", "--nu", "0.4999", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("cupcheck stiffness: error: nu: ") and "--formulation mixed" in err
    assert "\n" not in err and _files(tmp_path) == []
    # the bound itself is allowed (cup A, medium, frictionless, to 0.9 h1: F0 +0.74 % above the
    # mixed formulation at nu = 0.495, +0.60 % at the default 0.49, +1.6 % at 0.4999)
    assert stiffness_prepare(["--nu", "0.495", "--out", str(out)])["material"].nu == 0.495


def test_formulation_follows_nu_unless_given(tmp_path):
    # one rule for the command line, scenes and sweeps (validation.bridge.pipeline.neo_hookean): not
    # given, nu above 0.495 takes the mixed formulation, where the displacement elements lock
    out = str(tmp_path / "c.csv")
    assert stiffness_prepare(["--nu", "0.495", "--out", out])["material"].formulation == "displacement"
    assert stiffness_prepare(["--nu", "0.4999", "--out", out])["material"].formulation == "mixed"
    assert stiffness_prepare(["--nu", "0.3", "--formulation", "mixed", "--out", out])["material"].formulation == "mixed"
    from validation.bridge.pipeline import neo_hookean
    assert neo_hookean(4e6, 0.4999).formulation == "mixed" and neo_hookean(4e6, 0.49).formulation == "displacement"


def test_output_suffixes_in_any_case_and_a_directory_to_create_are_accepted(tmp_path):
    job = stiffness_prepare(["--out", str(tmp_path / "new" / "CURVE.CSV"),
                             "--fields-out", str(tmp_path / "new" / "F.VTU"), "--fidelity", "coarse"])
    assert job["sidecar"] == tmp_path / "new" / "CURVE.json"
    assert _files(tmp_path) == []               # the check creates nothing; the writers create new/


def stiffness_prepare(argv: list[str]) -> dict:
    """The checks and the cheap set-up of `cupcheck stiffness`, without the solve."""
    import argparse

    from validation.commands import stiffness
    parser = argparse.ArgumentParser()
    stiffness.add_arguments(parser)
    return stiffness._prepare(parser.parse_args(argv))


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
    (["--formulation", "displacement", "--nu", "0.496"], "nu"),
])
def test_bad_input_exits_2_with_one_line_and_no_output(tmp_path, capsys, monkeypatch, argv, field):
    monkeypatch.chdir(REPO)
    out = tmp_path / "curve.csv"
    assert main(["stiffness", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"cupcheck stiffness: error: {field}") and "\n" not in err
    assert _files(tmp_path) == []


def test_h1_typed_in_mm_is_full_flattening_not_an_error():
    # 1e3 h1 in full precision, times 1e-3, can land one ulp above h1: that is h1, not "beyond h1"
    from fem.geometry import cup_geometry
    h1 = cup_geometry("B").h1_m
    assert stiffness_prepare(["--cup", "B", "--u-max-mm", repr(1e3 * h1), "--out", "c.csv"])["u_max_m"] == h1
    with pytest.raises(ValueError, match=r"u_max_mm: .* \(0, 5.37409649\] mm, got 5.37410186"):
        stiffness_prepare(["--cup", "B", "--u-max-mm", repr(1e3 * h1 * (1 + 1e-6)), "--out", "c.csv"])
