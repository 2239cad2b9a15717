"""The numbered examples in docs/examples/ run as a user runs them: each in a fresh interpreter, in
an empty directory that receives all its files; each exits 0, writes exactly the files its
docstring names and prints what it promises. Its numbers are checked against an independent
source: the closed forms of Appendix A and of the cone's height, the `cupcheck` command line on
the files the example wrote (another front end to the same models, with its own parsing), or
the example's own full-precision output.

The examples print 4 significant digits (lifetimes, forces) or 4 decimals (F0, stiffness); a
printed number is compared at that precision.
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.cli import run_cli

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "docs" / "examples"
MM = 1e-3
#: a lifetime from the in-memory FEM curve against one from its CSV (10 significant digits) read
#: back by the command line: the two integrations (rtol 1e-6) take other steps and differ by the
#: integrator's global error, up to 4e-5 on the profile route (cup A coarse, 5-40 N; at rtol 1e-9
#: the two agree to 4e-7)
REREAD = 1e-4
#: the ballistic share is a trapezoid average over the integrator's accepted steps: when the step
#: sequence changes (the curve from memory or from its CSV: 27 against 23 steps at 10 N on the profile
#: route) it moves by up to 2e-3 (0.2512 against 0.2517), the quantity's own discretisation error
BALLISTIC = 5e-3


def run_example(name: str, cwd: Path) -> list[str]:
    """Run docs/examples/<name> in `cwd` with this repository first on the path; its stdout lines.
    Fails unless it exits 0 with nothing on stderr."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
           "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, str(EXAMPLES / name)], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    return done.stdout.splitlines()


def rows(lines: list[str], columns: int) -> list[list[str]]:
    """The table rows of an example's output: lines of `columns` fields whose first is a number."""
    out = []
    for line in lines:
        fields = line.split()
        if len(fields) == columns and re.fullmatch(r"[-+]?\d+(\.\d*)?", fields[0]):
            out.append(fields)
    return out


def number_after(text: str, label: str) -> str:
    """The number following `label` in `text`, as printed."""
    match = re.search(re.escape(label) + r"\s*([-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)", text)
    assert match, f"{label!r} not in {text!r}"
    return match.group(1)


def shows(text: str, value: float, rel: float = 1e-9) -> bool:
    """True if the printed number `text` is `value` to the last digit printed (within half a unit
    of it, and `rel` of the value for a model run twice through another front end)."""
    mantissa = text.lower().split("e")[0]
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    exponent = int(text.lower().split("e")[1]) if "e" in text.lower() else 0
    return abs(float(text) - value) <= 0.5 * 10.0 ** (exponent - decimals) + rel * abs(value)


def appendix_a_force(u_m: float, alpha_deg: float, E_Pa: float, d0_m: float, x0_m: float, x1_m: float) -> float:
    """Appendix A's F0(u) [N], written out here (the wall thins linearly from d0 at x0 to 0 at x1):
    pi (1 - cos a)^2 (cos a / sin a) E (a x + b x^2), x = x1 - u / sin a."""
    s, c = math.sin(math.radians(alpha_deg)), math.cos(math.radians(alpha_deg))
    a, b = d0_m * x1_m / (x1_m - x0_m), -d0_m / (x1_m - x0_m)
    x = x1_m - u_m / s
    return math.pi * (1 - c) ** 2 * (c / s) * E_Pa * (a * x + b * x * x)


def cli_lifetimes(capsys, *argv) -> list[dict]:
    code, out, err = run_cli(capsys, "lifetime", "--surface", "pmma-1.89", "--json", *argv)
    assert code == 0, err
    return json.loads(out)


def files(path: Path) -> set[str]:
    return {p.name for p in path.iterdir()}


def test_every_example_is_tested():
    tested = {"ex01_stiffness_curve.py", "ex02_paper_route.py", "ex03_profile_route.py",
              "ex04_coupled_route.py", "ex05_sweep.py"}
    assert {p.name for p in EXAMPLES.glob("ex*.py")} == tested
    for path in EXAMPLES.glob("ex*.py"):      # each says what it shows and what it prints
        doc = path.read_text().split('"""')[1]
        assert doc.startswith(path.name[2:4] + " ") and "Prints" in doc


def test_01_stiffness_curve_of_a_new_design(tmp_path, capsys):
    from reduced import StiffnessCurve

    lines = run_example("ex01_stiffness_curve.py", tmp_path)
    assert files(tmp_path) == {"new_cup.csv", "new_cup.json"}
    text = "\n".join(lines)
    assert shows(number_after(text, "h1 ="), 20 * math.tan(math.radians(40)))     # (r1 - r0) tan(alpha)
    side = json.loads((tmp_path / "new_cup.json").read_text())["provenance"]
    assert side["geometry"]["thickness_profile"] == {"kind": "table", "r_mm": [5.0, 15.0, 25.0],
                                                     "d_mm": [2.2, 1.0, 0.4]}
    assert side["contact"] == "frictionless" and side["fidelity"] == "coarse"

    # the same design as a design file, through `cupcheck stiffness`: the same curve
    (tmp_path / "cli").mkdir()
    design = tmp_path / "cli" / "new_cup.toml"
    design.write_text('name = "new cup"\nr0_mm = 5\nr1_mm = 25\nalpha_deg = 40\n[thickness]\n'
                      'r_mm = [5, 15, 25]\nd_mm = [2.2, 1.0, 0.4]\n[contact]\nlaw = "frictionless"\n')
    code, _, err = run_cli(capsys, "stiffness", "--geometry", design, "--fidelity", "coarse",
                           "--out", tmp_path / "cli" / "curve.csv")
    assert code == 0, err
    cli = StiffnessCurve.from_csv(tmp_path / "cli" / "curve.csv")
    table = rows(lines, 2)
    assert [float(u) for u, _ in table] == [0.5, 1.0, 2.0, 4.0]
    for u_mm, F0 in table:
        assert shows(F0, float(cli.force(cli.h1_m - float(u_mm) * MM)))

    # Appendix A's small-u stiffness of the same cone, from the closed form
    k_app = appendix_a_force(0.5 * MM, 40.0, 4e6, 2.2 * MM, 5 * MM, 25 * MM) / 0.5
    assert shows(number_after(text, "Appendix A"), k_app)
    k_fem = float(cli.force(cli.h1_m - 0.5 * MM)) / 0.5
    assert shows(number_after(text, "FEM"), k_fem)
    assert shows(number_after(text, "ratio"), k_fem / k_app)


def test_02_paper_route(tmp_path, capsys):
    lines = run_example("ex02_paper_route.py", tmp_path)
    assert files(tmp_path) == {"cupA_coarse.csv", "cupA_coarse.json"}
    table = rows(lines, 5)
    forces = [float(r[0]) for r in table]
    assert forces == [5.0, 10.0, 20.0, 40.0]
    appendix = cli_lifetimes(capsys, "--reference-mode", "--force", *forces)
    fem_fed = cli_lifetimes(capsys, "--stiffness", tmp_path / "cupA_coarse.csv", "--force", *forces)
    for (_, t_app, end_app, t_fem, end_fem), a, f in zip(table, appendix, fem_fed):
        assert shows(t_app, a["lifetime_s"]) and end_app == a["reason"]
        assert shows(t_fem, f["lifetime_s"], REREAD) and end_fem == f["reason"]
    held = [line for line in lines if line.startswith("largest holdable force")][0]
    assert shows(number_after(held, "Appendix A"), appendix[0]["largest_force_N"])
    assert shows(number_after(held, "FEM coarse"), fem_fed[0]["largest_force_N"], REREAD)


def test_03_profile_route(tmp_path, capsys):
    lines = run_example("ex03_profile_route.py", tmp_path)
    assert files(tmp_path) == {"cupA_coarse.csv", "cupA_coarse.json"}
    assert "patch length 202 um" in lines[0]          # pmma-1.89's (docs/lifetime.md)
    table = rows(lines, 4)
    forces = [float(r[0]) for r in table]
    assert forces == [5.0, 10.0, 20.0, 40.0]
    cli = cli_lifetimes(capsys, "--route", "profile", "--stiffness", tmp_path / "cupA_coarse.csv", "--force", *forces)
    for (_, t, end, ballistic), c in zip(table, cli):
        assert shows(t, c["lifetime_s"], REREAD) and end == c["reason"]
        assert shows(ballistic, c["ballistic_share"], BALLISTIC)
    assert shows(number_after(lines[-2], "largest holdable force:"), cli[0]["largest_force_N"], REREAD)


def test_04_coupled_route(tmp_path, capsys):
    from reduced import CUP_A, SuctionTable

    lines = run_example("ex04_coupled_route.py", tmp_path)
    assert files(tmp_path) == {"suction_table.json"}
    table = SuctionTable.from_json(tmp_path / "suction_table.json")
    assert table.F1_N.shape == (9, 8) and "9 u x 8 dp" in lines[0]
    assert shows(number_after(lines[0], "u_start ="), 1e3 * (table.h1_m - CUP_A.h_start_m))
    result = rows(lines, 4)
    forces = [float(r[0]) for r in result]
    assert forces == [5.0, 10.0, 20.0]
    cli = cli_lifetimes(capsys, "--route", "coupled", "--suction-table", tmp_path / "suction_table.json",
                        "--force", *forces)
    for (_, t, end, u_end), c in zip(result, cli):
        assert shows(t, c["lifetime_s"], REREAD) and end == c["reason"]
        assert shows(u_end, c["u_final_mm"], REREAD)
    code, out, err = run_cli(capsys, "lifetime", "--surface", "pmma-1.89", "--route", "coupled",
                             "--suction-table", tmp_path / "suction_table.json")     # (its --json has no largest force)
    assert code == 0, err
    assert shows(number_after(lines[-2], "largest holdable force:"),
                 float(number_after(out, "largest holdable force")), REREAD)
    # pulled harder, the cup lets go sooner
    assert [float(r[1]) for r in result] == sorted((float(r[1]) for r in result), reverse=True)


def test_05_sweep_on_a_dask_cluster(tmp_path, capsys):
    from reduced import StiffnessCurve

    lines = run_example("ex05_sweep.py", tmp_path)
    assert files(tmp_path) == {"alpha_30.csv", "alpha_30.json", "alpha_36.csv", "alpha_36.json", "sweep.csv"}
    with open(tmp_path / "sweep.csv", newline="") as f:
        sweep = list(csv.DictReader(f))
    table = rows(lines, 7)
    assert [float(r[0]) for r in table] == [float(s["alpha_deg"]) for s in sweep] == [30.0, 36.0]
    for r, s in zip(table, sweep):
        alpha = float(s["alpha_deg"])
        assert shows(r[1], 14 * math.tan(math.radians(alpha)))        # h1 = (r1 - r0) tan(alpha)
        curve = StiffnessCurve.from_csv(tmp_path / f"alpha_{alpha:g}.csv")
        k = float(curve.force(curve.h1_m - 1 * MM))
        assert float(s["small_u_stiffness_N_per_mm"]) == pytest.approx(k, rel=1e-8)    # the CSV: 10 digits
        # Appendix A for the cone: cup A's wall at r0 (2.5 mm) thinning to 0 at r1, E = 4 MPa
        k_app = appendix_a_force(1 * MM, alpha, 4e6, 2.5 * MM, 5 * MM, 19 * MM)
        # (the example reads it off `reduced.appendix_a_curve`, 401 samples: ~1e-7 of the closed form)
        assert float(s["appendix_a_ratio"]) == pytest.approx(k / k_app, rel=1e-7)
        # the lifetime through the command line, on the curve the worker wrote (REREAD)
        cli = cli_lifetimes(capsys, "--route", "profile", "--stiffness", tmp_path / f"alpha_{alpha:g}.csv",
                            "--force", 10)[0]
        assert float(s["lifetime_s"]) == pytest.approx(cli["lifetime_s"], rel=REREAD)
        assert s["reason"] == cli["reason"]
        assert float(s["largest_force_N"]) == pytest.approx(cli["largest_force_N"], rel=REREAD)
        for shown, key in zip(r[2:5], ("small_u_stiffness_N_per_mm", "appendix_a_ratio", "lifetime_s")):
            assert shows(shown, float(s[key]))
        assert r[5] == s["reason"] and shows(r[6], float(s["largest_force_N"]))
