"""`cupcheck example --stiffness CURVE.csv`: a derived curve's design, contact law, mesh level and
material carry into the example, an option that contradicts them is refused in one line (exit 2,
nothing written), and the lifetimes equal those of the example run on that design and law."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from reduced.stiffness_curve import StiffnessCurve
from tests.cli import run_cli


@pytest.fixture(scope="module")
def sticking_curve(tmp_path_factory):
    """Cup A's coarse sticking curve, as `cupcheck stiffness` derives it."""
    import subprocess
    import sys

    path = tmp_path_factory.mktemp("curve") / "a_sticking.csv"
    done = subprocess.run([sys.executable, "-m", "validation.cli", "stiffness", "--cup", "A", "--contact", "sticking",
                           "--fidelity", "coarse", "--out", str(path)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return path


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_the_curves_law_level_and_design_carry_into_example(sticking_curve, capsys, tmp_path):
    code, out, err = run_cli(capsys, "example", "--stiffness", sticking_curve, "--route", "paper",
                             "--out", tmp_path / "ex")
    assert code == 0, err
    rows = _rows(tmp_path / "ex" / "lifetime_vs_force.csv")
    assert {(r["cup"], r["contact"], r["mesh"]) for r in rows} == {("A", "sticking", "coarse")}
    written, given = StiffnessCurve.from_csv(tmp_path / "ex" / "stiffness_fem.csv"), StiffnessCurve.from_csv(sticking_curve)
    np.testing.assert_array_equal(written.F0_N, given.F0_N)          # the curve itself, no FEM rerun
    study = json.loads((tmp_path / "ex" / "manifest.json").read_text())["study"]
    assert study["contact"]["law"] == "sticking" and study["fidelity"] == "coarse"
    assert "stiffness curve a_sticking.csv" in study["contact"]["source"]


@pytest.mark.parametrize("argv,message", [
    (["--contact", "frictionless"], "--contact: the stiffness curve 'a_sticking.csv' was computed with sticking "
                                    "contact; drop --contact frictionless"),
    (["--friction", "0.5"], "--friction: the stiffness curve 'a_sticking.csv' was computed with sticking contact"),
    (["--cup", "B"], "cup: the stiffness curve 'a_sticking.csv' was computed for cup A (Table 1), but --cup B"),
    (["--fidelity", "medium"], "--fidelity: the stiffness curve 'a_sticking.csv' was computed at the coarse level"),
])
def test_an_option_that_contradicts_the_curve_is_refused(sticking_curve, capsys, tmp_path, argv, message):
    code, _, err = run_cli(capsys, "example", "--stiffness", sticking_curve, *argv, "--out", tmp_path / "ex")
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "ex").exists()


def test_a_curve_without_a_design_is_refused(capsys, tmp_path):
    measured = tmp_path / "measured.csv"
    measured.write_text("u_mm,h_mm,F0_N\n0,9,0\n1,8,1\n2,7,2.5\n")
    code, _, err = run_cli(capsys, "example", "--stiffness", measured, "--out", tmp_path / "ex")
    assert code == 2 and "--stiffness: 'measured.csv' records no FEM design" in err
    assert not (tmp_path / "ex").exists()


def test_the_curve_gives_the_lifetimes_of_its_design_and_law(sticking_curve, capsys, tmp_path):
    """Two paths to one answer: the given curve, and the FEM run again on its design and law."""
    code, _, err = run_cli(capsys, "example", "--stiffness", sticking_curve, "--route", "paper", "--out", tmp_path / "a")
    assert code == 0, err
    code, _, err = run_cli(capsys, "example", "--cup", "A", "--contact", "sticking", "--fidelity", "coarse",
                           "--route", "paper", "--out", tmp_path / "b")
    assert code == 0, err
    a, b = _rows(tmp_path / "a" / "lifetime_vs_force.csv"), _rows(tmp_path / "b" / "lifetime_vs_force.csv")
    assert [r["reason"] for r in a] == [r["reason"] for r in b]
    # the curve's CSV keeps 10 significant digits of the FEM's F0, u, r_c, l, V
    np.testing.assert_allclose([float(r["lifetime_s"]) for r in a], [float(r["lifetime_s"]) for r in b], rtol=1e-5)
