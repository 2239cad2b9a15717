"""A path that fails late keeps its converged part: the pipeline returns it as a curve flagged
partial, `cupcheck stiffness` writes it with exit status 3 and says which --u-max-mm runs, a later
complete run removes the failure record, and `cupcheck lifetime` uses a partial curve within its
range only. Real failing runs, no mocks:

* cup A, sticking, coarse mesh, pressed to u = h1: the wall folds into the plate at u = 8.85 mm
  (`fem.integrity.StateRejected`, self-contact is not modelled), after 23 converged steps;
* a thin 45-degree cone (0.5 -> 0.06 mm wall), coarse, frictionless: the wall turns over at
  u = 2.37 mm, far short of the u its r_start needs.
"""

import json
import tomllib

import numpy as np
import pytest

import fem
from fem.design_file import design_from_mapping
from fem.solver import ConvergenceError
from reduced.stiffness_curve import StiffnessCurve
from tests.cli import run_cli
from validation.bridge.pipeline import fem_stiffness, neo_hookean

H1_MM = 1e3 * fem.cup_geometry("A").h1_m
STICKING_TO_H1 = ["stiffness", "--cup", "A", "--contact", "sticking", "--fidelity", "coarse"]
THIN = 'cup = "A"\nalpha_deg = 45\n[thickness]\nr_mm = [5, 20]\nd_mm = [0.5, 0.06]\n'


def test_a_late_failure_writes_the_converged_part_flagged_partial_with_exit_3(tmp_path, capsys):
    out = tmp_path / "c.csv"
    code, stdout, err = run_cli(capsys, *STICKING_TO_H1, "--u-max-mm", f"{H1_MM:.9g}", "--out", out)
    assert code == 3 and stdout == ""
    line = err.strip().splitlines()[-1]
    assert line.startswith("cupcheck stiffness: partial: the path stopped at u = 8.847 mm (the wall folds")
    assert f"to {out} and c.json (flagged partial); --u-max-mm 8.438 runs; the record is in " in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.csv", "c.failure.json", "c.json"]
    curve = StiffnessCurve.from_csv(out)
    prov = curve.provenance
    assert prov["partial"] is True and "folds onto itself" in prov["failure_reason"]
    # the curve ends at the last converged u, short of the failed step's u and of h1
    assert 1e3 * curve.u_m[-1] == pytest.approx(prov["u_max_mm_that_runs"], rel=1e-9)
    assert 8.0 < prov["u_max_mm_that_runs"] < prov["failed_at_u_mm"] < H1_MM
    side = json.loads(out.with_suffix(".json").read_text())
    assert side["provenance"] == prov and len(side["steps"]["u_mm"]) == len(curve.u_m) == side["solver"]["steps"] + 1
    record = json.loads(out.with_suffix(".failure.json").read_text())
    assert record["u_to_mm"] == pytest.approx(prov["failed_at_u_mm"]) and record["residual_history"] == []
    partial_F0 = float(curve.F0_N[-1])

    # the u_max it names runs; that complete run removes the stale failure record
    code, stdout, err = run_cli(capsys, *STICKING_TO_H1, "--u-max-mm", "8.438", "--out", out)
    assert code == 0 and stdout.startswith(f"cupcheck stiffness: wrote {out}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.csv", "c.json"]
    complete = StiffnessCurve.from_csv(out)
    assert "partial" not in complete.provenance and 1e3 * complete.u_m[-1] == pytest.approx(8.438)
    # the same load steps (a path beyond 0.9 h1 takes the default path's) but the last, which ends
    # at 8.438 instead of 8.43824 mm (measured 0.02 %, beyond the fold of Biot's stretch at 7.9 mm)
    assert complete.F0_N[-1] == pytest.approx(partial_F0, rel=0.02)


def test_lifetime_uses_a_partial_curve_within_its_range(tmp_path, capsys):
    partial, complete = tmp_path / "partial.csv", tmp_path / "complete.csv"
    assert run_cli(capsys, *STICKING_TO_H1, "--u-max-mm", f"{H1_MM:.9g}", "--out", partial)[0] == 3
    assert run_cli(capsys, *STICKING_TO_H1, "--out", complete)[0] == 0         # to 0.9 h1
    lives = {}
    for name, path in (("partial", partial), ("complete", complete)):
        code, stdout, err = run_cli(capsys, "lifetime", "--stiffness", path, "--force", "5", "80", "--json")
        assert code == 0
        lives[name] = [r["lifetime_s"] for r in json.loads(stdout)]
        assert ("is a partial curve: converged to u = 8.438 mm" in err) == (name == "partial")
    # a lifetime reads the curve between u = 0 and r_start's u = 4.5 mm, inside both: the two
    # differ by their load steps only (measured 0.02 % at 5 N, 0.09 % at 80 N)
    assert lives["partial"] == pytest.approx(lives["complete"], rel=3e-3)


def test_lifetime_refuses_a_partial_curve_that_stops_short_of_r_start(tmp_path, capsys):
    design = tmp_path / "thin.toml"
    design.write_text(THIN)
    curve = tmp_path / "thin.csv"
    code, _, err = run_cli(capsys, "stiffness", "--geometry", design, "--fidelity", "coarse", "--out", curve)
    assert code == 3 and "wall has turned over" in err
    for route in ("paper", "profile"):
        code, stdout, err = run_cli(capsys, "lifetime", "--stiffness", curve, "--force", "10", "--route", route,
                                    "--out", tmp_path / "life")
        line = err.strip().splitlines()[-1]
        assert code == 2 and stdout == ""
        assert line.startswith(f"cupcheck lifetime: error: --stiffness: '{curve}' is a partial curve: "
                               "converged to u = 2.35 mm, its FEM path stopped at 2.371 mm, and this "
                               "lifetime needs a state beyond it: ")
        assert not (tmp_path / "life").exists()


def test_the_pipeline_keeps_the_converged_part_when_asked():
    """`fem_stiffness` raises on a failed path; with keep_partial it returns the converged part,
    whose states are the failed path's own (the error's partial response) and whose provenance
    says where and why it stopped."""
    geometry = design_from_mapping(tomllib.loads(THIN)).geometry
    material = neo_hookean(4e6, 0.49)
    with pytest.raises(ConvergenceError) as info:
        fem_stiffness(geometry, material, fem.ContactLaw(), "coarse")
    exc = info.value
    assert exc.partial.partial and exc.partial.stats.steps == len(exc.partial.u_m) - 1
    response, curve = fem_stiffness(geometry, material, fem.ContactLaw(), "coarse", keep_partial=True)
    assert response.partial and np.array_equal(response.u_m, exc.partial.u_m)
    assert np.array_equal(curve.F0_N, exc.partial.F0_N)
    prov = curve.provenance
    assert prov["partial"] is True and prov["failed_at_u_mm"] == pytest.approx(1e3 * exc.t_to)
    assert prov["u_max_mm_that_runs"] == pytest.approx(1e3 * exc.t_from) == pytest.approx(1e3 * response.u_m[-1])
    assert prov["failure_reason"] == exc.cause
