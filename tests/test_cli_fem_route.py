"""`cupcheck lifetime --route fem`: the command line gives the Python call's lifetime (coarse cup A,
frictionless, 10 N, pmma-1.89) to the printed digits, writes its trajectory with unit-named columns,
and refuses every option the route does not model before any FEM work (exit 2, nothing written)."""

from __future__ import annotations

import csv
import re
import json

import numpy as np
import pytest

import reduced
from tests.cli import run_cli as _run
from validation.bridge.fem_route import FemCup
from validation.bridge.pipeline import surface_uc_table


def test_cli_lifetime_equals_the_python_call(capsys, tmp_path):
    out = tmp_path / "fem"
    code, text, err = _run(capsys, "lifetime", "--route", "fem", "--cup", "A", "--contact", "frictionless",
                           "--surface", "pmma-1.89", "--force", "10", "--out", out)
    assert code == 0, err
    head, columns, row = text.splitlines()
    assert columns.split() == ["F1_N", "lifetime_s", "reason", "u_end_mm", "p_b_end_kPa", "seal_r_mm"]
    model = reduced.reference_model(reduced.CUP_A, surface_uc_table())
    life = reduced.solve_lifetime(model, 10.0, route="fem", cup=FemCup("A", "coarse"), press=None,
                                  du_m=0.25e-3)
    largest = reduced.largest_holdable_force(model, "fem", cup=FemCup("A", "coarse"))
    d = life.details
    assert row.split() == ["10", f"{life.lifetime_s:.6g}", life.reason, f"{d['u_final_mm']:.3f}",
                           f"{d['p_b_final_Pa'] / 1e3:.4g}", f"{d['seal_r_final_mm']:.3f}"]
    assert f"largest holdable force {largest:.4g} N" in head and "coarse mesh" in head
    with open(out / "trajectory_F1_10N.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert set(rows[0]) >= {"cup", "t_s", "N", "p_b_Pa", "u_mm", "F_plate_N", "V_mm3", "seal_r_mm",
                            "N_dot_per_s"}
    t = np.array([float(r["t_s"]) for r in rows])
    assert t[-1] == pytest.approx(life.lifetime_s, rel=1e-9)
    assert np.allclose([float(r["u_mm"]) for r in rows], life.trajectory["u_mm"], rtol=1e-9)
    summary = json.loads((out / "summary.json").read_text())
    assert summary[0]["reason"] == life.reason and summary[0]["cup"]["fem_cup"]["fidelity"] == "coarse"


@pytest.mark.parametrize("extra,field", [
    (["--stiffness", "curve.csv"], "--route: .*drop --stiffness"),
    (["--suction-table", "t.json"], "--route: .*drop --suction-table"),
    (["--fluid", "water"], "--route: .*drop --fluid"),
    (["--relaxation", "default"], "--route: .*drop --relaxation"),
    (["--cup-laws", "curve"], "--route: .*drop --cup-laws"),
    (["--kappa", "2"], "--route: .*drop --kappa"),
    (["--reference-mode"], "--reference-mode: "),
    (["--contact", "coulomb"], "friction: --contact coulomb needs --friction"),
    (["--contact", "sticking", "--friction", "0.5"], "friction: "),
    (["--du-mm", "0"], "--du-mm: "),
    (["--E-MPa", "-1"], "--E-MPa: "),
    (["--force", "-3"], "--force"),
    (["--r-start-mm", "30"], "r_start_mm: "),
])
def test_bad_input_is_refused_before_any_fem_work(capsys, tmp_path, extra, field):
    out = tmp_path / "never"
    code, text, err = _run(capsys, "lifetime", "--route", "fem", "--out", out, *extra)
    assert code == 2 and text == ""
    line, = err.strip().splitlines()
    assert re.search(f"error: {field}", line), line
    assert not out.exists()


@pytest.mark.parametrize("option,value", [("--contact", "sticking"), ("--fidelity", "medium"),
                                          ("--friction", "0.5"), ("--du-mm", "0.1")])
def test_fem_options_are_refused_on_other_routes(capsys, option, value):
    code, _, err = _run(capsys, "lifetime", "--reference-mode", option, value)
    assert code == 2 and f"{option}: applies to --route fem only" in err
