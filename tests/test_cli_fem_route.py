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
                           "--surface", "pmma-1.89", "--force", "10", "--fidelity", "coarse", "--out", out)
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
    (["--fluid", "water", "--cavitation-kPa", "2.34"], "--route: .*drop --cavitation-kPa"),
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
    (["--press-u-mm", "0"], "--press-u-mm: must be > 0, got 0$"),
    (["--press-force-N", "-5"], "--press-force-N: must be > 0, got -5$"),
    (["--r-start-mm", "12", "--press-u-mm", "6"], "--press-u-mm: the cup is pressed one way: give one of "
                                                  "--r-start-mm, --press-u-mm$"),
    (["--press-u-mm", "6", "--press-force-N", "5"], "--press-force-N: the cup is pressed one way"),
])
def test_bad_input_is_refused_before_any_fem_work(capsys, tmp_path, extra, field):
    out = tmp_path / "never"
    code, text, err = _run(capsys, "lifetime", "--route", "fem", "--out", out, *extra)
    assert code == 2 and text == ""
    line, = err.strip().splitlines()
    assert re.search(f"error: {field}", line), line
    assert not out.exists()


@pytest.mark.parametrize("option,value", [("--contact", "sticking"), ("--fidelity", "medium"),
                                          ("--friction", "0.5"), ("--du-mm", "0.1"),
                                          ("--press-u-mm", "6"), ("--press-force-N", "5")])
def test_fem_options_are_refused_on_other_routes(capsys, option, value):
    code, _, err = _run(capsys, "lifetime", "--reference-mode", option, value)
    assert code == 2 and f"{option}: applies to --route fem only" in err


def test_pressing_to_the_u_that_r_start_reached_seals_the_same_cup(capsys):
    """--press-u-mm at the plate displacement the default press (to r_start) ended at gives the same
    sealed state and lifetime: two ways to press, one cup (to the FEM's Newton tolerance)."""
    code, text, err = _run(capsys, "lifetime", "--route", "fem", "--force", "10", "--fidelity", "coarse", "--json")
    assert code == 0, err
    by_r, = json.loads(text)
    code, text, err = _run(capsys, "lifetime", "--route", "fem", "--force", "10", "--fidelity", "coarse", "--json",
                           "--press-u-mm", repr(by_r["u_sealed_mm"]))
    assert code == 0, err
    by_u, = json.loads(text)
    assert by_u["cup"]["press"] == {"kind": "u_m", "value": pytest.approx(1e-3 * by_r["u_sealed_mm"], rel=1e-15)}
    assert "press" not in by_r["cup"]
    assert by_u["r_start_mm"] == pytest.approx(by_r["r_start_mm"], rel=1e-7)
    for key in ("N0", "lifetime_s", "largest_force_N"):
        assert by_u[key] == pytest.approx(by_r[key], rel=1e-8), key
    assert by_u["reason"] == by_r["reason"]


def test_press_force_reaches_the_route_as_a_press():
    """--press-force-N is the fem route's `Press("force_N", F)`, --press-u-mm its `Press("u_m", u)`;
    no flag keeps the route's own press to r_start (None). No FEM is solved."""
    from validation.bridge.fem_route import Press
    from validation.cli import build_parser
    from validation.commands._fem_route import fem_route_case

    def press(*extra):
        args = build_parser().parse_args(["lifetime", "--route", "fem", *extra])
        return fem_route_case(args)[1]["press"]

    assert press("--press-force-N", "5") == Press("force_N", 5.0)
    assert press("--press-u-mm", "6.5") == Press("u_m", 1e-3 * 6.5)
    assert press() is None
