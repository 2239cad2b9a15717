"""A new cup design end to end (issue 18): the design travels with its curve, lifetimes use it,
options mean one thing everywhere, implausible inputs are refused, CSVs read as plain tables."""

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from reduced.appendix_a import appendix_a_curve
from reduced.cup import CUP_A
from reduced.stiffness_curve import StiffnessCurve
from tests.cli import run_cli as _run
from validation.bridge.design import preset_design

DESIGNER_TOML = """r1_mm = 25
alpha_deg = 40
[thickness]
r_mm = [5, 25]
d_mm = [2.0, 0.4]
"""



def _curve_for(design: dict, path: Path) -> Path:
    """Cup A's Appendix A F0(u) samples, recorded as computed for `design` (its own h1)."""
    base = appendix_a_curve(CUP_A)
    h1 = 1e-3 * (design["r1_mm"] - design["r0_mm"]) * math.tan(math.radians(design["alpha_deg"]))
    u = np.linspace(0.0, 0.95 * min(h1, base.h1_m), 60)
    curve = StiffnessCurve(u_m=u, F0_N=base.force(base.h1_m - u), h1_m=h1,
                           provenance={"source": "test", "geometry": {**design, "h1_mm": 1e3 * h1}})
    return curve.to_csv(path)


def test_a_design_differing_only_in_r1_detaches_at_its_own_r1(capsys, tmp_path):
    # the same F0(u) recorded once for cup A and once for cup A with r1 = 21 mm
    wide = {**preset_design("A").describe(), "name": "wide rim", "r1_mm": 21.0}
    runs = {}
    for name, design in (("A", preset_design("A").describe()), ("wide", wide)):
        path = _curve_for(design, tmp_path / f"{name}.csv")
        code, out, err = _run(capsys, "lifetime", "--stiffness", path, "--force", "10", "--json",
                              "--l0-mm", "4", "--l1-mm", "0.8")
        assert code == 0, err
        runs[name] = json.loads(out)[0]
    assert runs["A"]["r_final_mm"] == pytest.approx(19.0, abs=1e-9)
    assert runs["wide"]["r_final_mm"] == pytest.approx(21.0, abs=1e-9)
    assert runs["wide"]["cup"]["label"].startswith("wide rim (r0 5 mm, r1 21 mm")
    assert runs["wide"]["cup"]["r_start_mm"] == pytest.approx(13.0)          # (r0 + r1) / 2
    assert runs["A"]["cup"]["label"] == "cup A (Table 1)" and runs["A"]["cup"]["r_start_mm"] == 12.0
    assert not math.isclose(runs["wide"]["lifetime_s"], runs["A"]["lifetime_s"], rel_tol=1e-3)


def test_the_designers_path_with_the_fem(capsys, tmp_path):
    """stiffness --geometry my_cup.toml -> lifetime --stiffness: the lifetime uses my_cup's own
    r0, r1, alpha (the rim leaves at r1 = 25 mm), every output names it."""
    design = tmp_path / "my_cup.toml"
    design.write_text(DESIGNER_TOML)
    curve = tmp_path / "my_cup.csv"
    code, _, err = _run(capsys, "stiffness", "--geometry", design, "--contact", "sticking",
                        "--fidelity", "coarse", "--out", curve)
    assert code == 0, err
    code, out, err = _run(capsys, "lifetime", "--stiffness", curve, "--force", "10",
                          "--surface", "pmma-1.89", "--out", tmp_path / "life")
    assert code == 0, err
    assert out.splitlines()[0].startswith("cup: my_cup.toml (r0 5 mm, r1 25 mm, alpha 40 deg) from "
                                          "the stiffness curve; r_start 15 mm")
    summary = json.loads((tmp_path / "life" / "summary.json").read_text())[0]
    assert summary["cup"]["r1_mm"] == 25.0 and summary["cup"]["source"] == "stiffness curve"
    if summary["reason"] == "reached_r1":
        assert summary["r_final_mm"] == pytest.approx(25.0, abs=1e-6)
    traj = pd.read_csv(tmp_path / "life" / "trajectory_F1_10N.csv")
    assert set(traj["cup"]) == {"my_cup.toml"} and traj["r_mm"].max() <= 25.0 + 1e-9
    # the FEM's own r_c, V, l: zero strip widths (a line contact) no longer refuse the curve
    code, out, err = _run(capsys, "lifetime", "--stiffness", curve, "--force", "10",
                          "--surface", "pmma-1.89", "--cup-laws", "curve", "--json")
    assert code == 0, err
    assert json.loads(out)[0]["reason"] in ("sealed", "reached_r1", "fold", "horizon")
    # an explicit cup that contradicts the curve's design is refused, naming both
    code, _, err = _run(capsys, "lifetime", "--stiffness", curve, "--cup", "a")
    assert code == 2 and err.count("\n") == 1
    assert "was computed for my_cup.toml (r0 5 mm, r1 25 mm, alpha 40 deg), but --cup A is cup A (Table 1)" in err


def test_outputs_are_plain_csv_for_pandas_and_numpy(capsys, tmp_path):
    curve = appendix_a_curve(CUP_A).to_csv(tmp_path / "F0.csv")
    for reader in (lambda p: pd.read_csv(p), lambda p: np.genfromtxt(p, delimiter=",", names=True)):
        table = reader(curve)
        assert table["F0_N"][0] == 0.0 and len(table["u_mm"]) > 10 and np.all(np.diff(table["u_mm"]) > 0)
    # the provenance travels in the sidecar, and comes back with the curve
    assert json.loads(curve.with_suffix(".json").read_text())["provenance"]["source"] == "appendix-a"
    assert StiffnessCurve.from_csv(curve).provenance["source"] == "appendix-a"
    code, _, err = _run(capsys, "lifetime", "--force", "10", "20", "--out", tmp_path / "run")
    assert code == 0, err
    for path in (tmp_path / "run").glob("*.csv"):
        frame = pd.read_csv(path)
        rec = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="utf-8")
        assert len(frame) == len(rec) > 10 and np.allclose(frame["t_s"], rec["t_s"])


def test_the_former_in_csv_provenance_is_still_read(tmp_path):
    path = tmp_path / "old.csv"
    path.write_text('# provenance: {"source": "fem", "contact": "sticking"}\nu_mm,h_mm,F0_N\n0,9,0\n1,8,2\n')
    curve = StiffnessCurve.from_csv(path)
    assert curve.provenance["contact"] == "sticking" and curve.h1_m == pytest.approx(9e-3)


@pytest.mark.parametrize("argv,message", [
    (["stiffness", "--E-MPa", "4e6"], "E_MPa = 4e+06: did you give Pa? (plausible: 0.01 .. 1000 MPa)"),
    (["lifetime", "--E-MPa", "4000"], "--E-MPa = 4000: did you give kPa? (plausible: 0.01 .. 1000 MPa)"),
    (["lifetime", "--geometry", "cone"], "argument --geometry: 'cone' is not a geometry file: the "
                                         "cone/curve choice is --cup-laws cone"),
    (["example", "--geometry", "curve"], "argument --geometry: 'curve' is not a geometry file"),
    (["stiffness", "--cup", "c"], "argument --cup: invalid cup 'c' (choose from A, B, any case)"),
])
def test_guards_refuse_in_one_line(capsys, tmp_path, argv, message):
    out = ["--out", tmp_path / ("c.csv" if argv[0] == "stiffness" else "o")]
    code, stdout, err = _run(capsys, *argv, *out)
    assert code == 2 and err.count("\n") == 1 and message in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("toml,message", [
    ("r1_mm = 50\nalpha_deg = 85\n[thickness]\nr_mm = [5, 50]\nd_mm = [0.05, 0.05]\n",
     "alpha_deg = 85 is outside 5 .. 80 deg (a tube"),
    ("r1_mm = 50\nalpha_deg = 45\n[thickness]\nr_mm = [5, 50]\nd_mm = [0.1, 0.1]\n",
     "the wall is 63.64 mm long and 0.1 mm thin (slenderness 636, plausible <= 400)"),
    ("r0_mm = 5000\nr1_mm = 19000\n[thickness]\nr_mm = [5000, 19000]\nd_mm = [2500, 450]\n",
     "r0_mm = 5000: did you give um? (plausible: 0.5 .. 500 mm)"),
])
def test_implausible_designs_are_refused_before_the_solve(capsys, tmp_path, toml, message):
    design = tmp_path / "d.toml"
    design.write_text(toml)
    code, _, err = _run(capsys, "stiffness", "--geometry", design, "--out", tmp_path / "o" / "c.csv")
    assert code == 2 and err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "o").exists()
    if "r1_mm = 19000" not in toml:        # a steep or slender design a user means: the override
        from validation.commands import stiffness
        from validation.cli import build_parser
        args = build_parser().parse_args(["stiffness", "--geometry", str(design), "--fidelity", "coarse",
                                          "--allow-unusual-design", "--out", str(tmp_path / "c.csv")])
        assert stiffness._prepare(args)["u_max_m"] > 0


def test_a_uc_table_in_micrometres_is_refused(capsys, tmp_path):
    table = tmp_path / "uc_um.csv"
    table.write_text("p_over_E,u_c_m\n0.01,1.2\n0.025,0.68\n0.05,0.3\n")
    code, _, err = _run(capsys, "lifetime", "--uc-table", table, "--force", "10")
    assert code == 2 and err.count("\n") == 1
    assert "u_c_m at p_over_E = 0.01 = 1.2: did you give um or nm? (plausible: 0 .. 0.001 m)" in err


def test_a_psd_in_micrometre_units_is_refused(capsys, tmp_path):
    from reduced.roughness.surfaces import preset
    spec = preset("pmma-1.89").spectrum()
    psd = tmp_path / "psd_um.csv"
    # q in 1/um and C in um^4 written under the SI column names
    np.savetxt(psd, np.column_stack([spec.q_per_m * 1e-6, spec.C_m4 * 1e24]), delimiter=",",
               header="q_per_m,C_m4", comments="")
    code, _, err = _run(capsys, "lifetime", "--psd", psd, "--force", "10")
    assert code == 2 and err.count("\n") == 1
    assert "surface: rms roughness h_rms_m = 1.89: did you give um (C in um^4, q in 1/um) or nm?" in err


def test_a_custom_design_without_strip_widths_asks_for_them(capsys, tmp_path):
    design = tmp_path / "my_cup.toml"
    design.write_text(DESIGNER_TOML)
    code, _, err = _run(capsys, "lifetime", "--geometry", design, "--force", "10")
    assert code == 2 and "l0_mm, l1_mm: my_cup.toml (r0 5 mm, r1 25 mm, alpha 40 deg) is not a " \
                         "Table 1 cup, so eq (5)'s strip widths are unknown: give --l0-mm and --l1-mm" in err
    code, out, err = _run(capsys, "lifetime", "--geometry", design, "--force", "10", "--l0-mm", "4",
                          "--l1-mm", "0.8", "--json")
    assert code == 0, err
    row = json.loads(out)[0]
    assert row["cup"]["source"] == "geometry file" and row["cup"]["l_source"] == "given"
