"""The FEM curve's end, u_max, in every spelling (a scene's stiffness.u_max_mm, a sweep's
base.u_max_mm, `cupcheck example --u-max-mm`), and what `example` and scenes do with a path that
fails late: they keep its converged part, flagged partial, refuse only the lifetimes that need a
state beyond it, name the u_max that runs and exit with status 3, as `cupcheck stiffness` does.

Real failing runs, no mocks (the same two as tests/test_partial_curve.py):

* cup A, sticking, coarse mesh, pressed to u = h1: the wall folds into the plate at u = 8.847 mm,
  after 23 converged steps (partial to 8.438 mm);
* a thin 45-degree cone (0.5 -> 0.06 mm wall), coarse, frictionless, to its default 0.9 h1: the
  wall turns over at u = 2.371 mm, far short of the u its r_start needs.
"""

import json

import numpy as np
import pandas as pd
import pytest

import fem
from reduced.stiffness_curve import StiffnessCurve
from tests.cli import run_cli
from validation.scenes.outputs import run_scene
from validation.scenes.schema import scene_from_mapping
from validation.sweeps.spec import sweep_from_mapping

H1_MM = 1e3 * fem.cup_geometry("A").h1_m
STICKING = ["example", "--cup", "A", "--contact", "sticking", "--fidelity", "coarse", "--route", "paper"]
THIN = 'cup = "A"\nalpha_deg = 45\n[thickness]\nr_mm = [5, 20]\nd_mm = [0.5, 0.06]\n'


def _scene(u_max_mm=None, **tables):
    stiffness = {"fidelity": "coarse", **({"u_max_mm": u_max_mm} if u_max_mm is not None else {})}
    return {"contact": {"law": "sticking"}, "stiffness": stiffness, "loads": {"F1_N": [5, 80]},
            "outputs": [{"kind": "curve"}, {"kind": "lifetimes"}], **tables}


# ------------------------------------------------------------------ the guard, in every spelling
@pytest.mark.parametrize("value, says", [
    (8466.0, " = 8466: did you give um? (plausible: 0.01 .. 500 mm)"),                 # the curve's u in um
    (0.0085, " = 0.0085: did you give m? (plausible: 0.01 .. 500 mm)"),               # in m
    (9.2, " = 9.2 (the plate displacement must lie in (0, h1] = (0, 9.0917063] mm"),  # beyond cup A's h1
    (0.05, " = 0.05 (plausible: 0.09092 .. 9.0917063 mm, 1 % of the cup's height h1 to h1)"),
    (-1.0, ": must be > 0, got -1"),
])
def test_a_u_max_no_cup_has_is_refused_naming_the_key_as_written(value, says, tmp_path, capsys):
    with pytest.raises(ValueError) as scene:
        scene_from_mapping(_scene(value))
    assert str(scene.value).startswith(f"stiffness.u_max_mm{says}")
    code, stdout, err = run_cli(capsys, *STICKING, "--u-max-mm", value, "--out", tmp_path / "o")
    line = err.strip().splitlines()[-1]
    assert code == 2 and stdout == "" and line.startswith(f"cupcheck example: error: --u-max-mm{says}")
    assert list(tmp_path.iterdir()) == []
    if value in (8466.0, 0.0085, -1.0):                # a sweep's base: before its designs are known
        with pytest.raises(ValueError, match=r"^base\.u_max_mm"):
            sweep_from_mapping({"base": {"u_max_mm": value}})


def test_u_max_is_checked_against_each_cup_a_scene_runs():
    """Cup B is shorter than cup A (h1 5.87 mm against 9.09 mm): u_max = 8 mm fits A, not B."""
    h1_B = 1e3 * fem.cup_geometry("B").h1_m
    scene_from_mapping(_scene(8.0))
    with pytest.raises(ValueError, match=rf"^stiffness.u_max_mm = 8 \(.* \(0, {h1_B:.9g}\] mm"):
        scene_from_mapping(_scene(8.0, sweep={"key": "cup.preset", "values": ["A", "B"]}))


def test_u_max_needs_an_fem_curve(tmp_path, capsys):
    with pytest.raises(ValueError, match=r"^stiffness.u_max_mm: ends the FEM stiffness curve; Appendix A's"):
        scene_from_mapping({"stiffness": {"source": "appendix-a", "u_max_mm": 5}, "outputs": [{"kind": "lifetimes"}]})
    curve = tmp_path / "c.csv"
    assert run_cli(capsys, "stiffness", "--cup", "A", "--fidelity", "coarse", "--u-max-mm", "5", "--out", curve)[0] == 0
    code, _, err = run_cli(capsys, "example", "--stiffness", curve, "--u-max-mm", "4", "--out", tmp_path / "o")
    assert code == 2 and "--u-max-mm: the stiffness curve 'c.csv' ends where its FEM run ended" in err
    assert not (tmp_path / "o").exists()


def test_a_sweep_carries_u_max_to_its_designs_and_keeps_old_design_hashes():
    from validation.sweeps.evaluate import geometry_of, study_of
    from validation.sweeps.spec import design_hash

    plain = sweep_from_mapping({"base": {}}).designs()[0]
    assert "u_max_mm" not in plain                      # absent unless given: a store's hashes stay
    design = sweep_from_mapping({"base": {"u_max_mm": 5}}).designs()[0]
    assert design_hash(design) != design_hash(plain)
    assert study_of(design, geometry_of(design)).u_max_mm == 5.0


def test_a_warm_rerun_redraws_the_curve_and_tables_of_another_u_max_only():
    from validation.scenes.outputs import made_from

    scene = {"outputs": [{"kind": "curve"}, {"kind": "lifetimes"}, {"kind": "render", "u_mm": 2}]}
    plain, ended = (scene_from_mapping({**scene, **extra}) for extra in ({}, {"stiffness": {"u_max_mm": 5}}))
    keys = [[made_from(o, s.study())["key"] for o in s.outputs] for s in (plain, ended)]
    assert keys[0][:2] != keys[1][:2] and keys[0][2] == keys[1][2]      # the render ends at its own u


# ------------------------------------------------------------------ real runs
def test_example_keeps_a_late_failures_converged_part_and_names_the_u_max_that_runs(tmp_path, capsys):
    out, record = tmp_path / "ex", tmp_path / "ex.failure.json"
    code, stdout, err = run_cli(capsys, *STICKING, "--u-max-mm", f"{H1_MM:.9g}", "--out", out)
    assert code == 3, err
    line = err.strip().splitlines()[-1]
    assert line.startswith("cupcheck example: partial: the FEM path stopped at u = 8.847 mm (the wall folds")
    assert line.endswith(f"the stiffness curve is its converged part, u = 0 to 8.438 mm (flagged partial); "
                         f"--u-max-mm 8.438 runs; the record is in {record}")
    assert "F0(8.438 mm) = " in stdout
    curve = StiffnessCurve.from_csv(out / "stiffness_fem.csv")
    prov = curve.provenance
    assert prov["partial"] is True and "folds onto itself" in prov["failure_reason"]
    assert 1e3 * curve.u_m[-1] == pytest.approx(prov["u_max_mm_that_runs"], rel=1e-9)     # the CSV's 10 digits
    table = pd.read_csv(out / "lifetime_vs_force.csv")
    assert table["curve_partial_to_u_mm"].to_numpy() == pytest.approx(prov["u_max_mm_that_runs"], rel=1e-9)
    # r_start = 12 mm needs u = 4.5 mm, inside the converged part: every force is computed
    assert len(table) == 16 and set(table["reason"]) == {"reached_r1"}
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["partial"]["u_max_mm_that_runs"] == prov["u_max_mm_that_runs"]
    assert manifest["partial"]["refused"] == [] and manifest["study"]["u_max_mm"] == pytest.approx(H1_MM)
    assert json.loads(record.read_text())["u_to_mm"] == pytest.approx(prov["failed_at_u_mm"])

    # the u_max it names runs to the end; that complete run removes the stale failure record
    code, stdout, err = run_cli(capsys, *STICKING, "--u-max-mm", "8.438", "--out", out)
    assert code == 0 and not record.exists() and "F0(8.438 mm) = " in stdout
    complete = pd.read_csv(out / "lifetime_vs_force.csv")
    assert "curve_partial_to_u_mm" not in complete and "partial" not in json.loads((out / "manifest.json").read_text())
    # the same cup states by the same load steps (a path beyond 0.9 h1 takes the default path's):
    # where the lifetimes read the curves (u <= 4.5 mm) F0 and the lifetimes agree
    u = np.linspace(0.5e-3, 4.5e-3, 9)
    steps = StiffnessCurve.from_csv(out / "stiffness_fem.csv")                  # the complete curve
    assert curve.force(curve.h1_m - u) == pytest.approx(steps.force(steps.h1_m - u), rel=1e-2)
    assert table["lifetime_s"].to_numpy() == pytest.approx(complete["lifetime_s"].to_numpy(), rel=1e-2)


def test_example_at_the_default_u_max_is_complete(tmp_path, capsys):
    """Cup A sticking coarse to its default 0.9 h1 = 8.183 mm: below the fold, complete, exit 0."""
    code, stdout, err = run_cli(capsys, *STICKING, "--out", tmp_path / "ex")
    assert code == 0 and "F0(0.9 h1) = " in stdout and "partial" not in err
    assert "partial" not in StiffnessCurve.from_csv(tmp_path / "ex" / "stiffness_fem.csv").provenance
    assert not (tmp_path / "ex.failure.json").exists()


def test_a_scene_keeps_the_converged_part_and_exits_3_also_when_up_to_date(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(f'[contact]\nlaw = "sticking"\n[stiffness]\nfidelity = "coarse"\nu_max_mm = {H1_MM:.10g}\n'
                     '[loads]\nF1_N = [5, 80]\n[[outputs]]\nkind = "curve"\n[[outputs]]\nkind = "lifetimes"\n')
    out = tmp_path / "out"
    for rerun in (False, True):
        code, stdout, err = run_cli(capsys, "run", scene, "--out", out)
        assert code == 3
        assert ("up to date" in stdout) == rerun
        line = err.strip().splitlines()[-1]
        assert line.startswith("run: partial: the FEM path stopped at u = 8.847 mm (the wall folds")
        assert line.endswith("u = 0 to 8.438 mm (flagged partial); stiffness.u_max_mm = 8.438 runs")
    side = json.loads((out / "curve.json").read_text())
    assert side["provenance"]["partial"] is True
    table = pd.read_csv(out / "lifetimes.csv")
    assert list(table["reason"]) == ["reached_r1"] * 2
    assert table["curve_partial_to_u_mm"].to_numpy() == pytest.approx(side["provenance"]["u_max_mm_that_runs"])
    assert json.loads((out / "manifest.json").read_text())["partial"]["study"]["failed_at_u_mm"] == \
        pytest.approx(side["provenance"]["failed_at_u_mm"])


def test_a_scene_refuses_the_lifetimes_beyond_a_partial_curve_for_their_forces(tmp_path, capsys):
    """The thin cone stops at u = 2.371 mm, its r_start needs h = 7 mm: every force is refused by
    name (reason beyond_partial_curve), the table and figure are still written, exit 3."""
    (tmp_path / "thin.toml").write_text(THIN)
    scene = tmp_path / "s.toml"
    scene.write_text('[cup]\ngeometry = "thin.toml"\n[stiffness]\nfidelity = "coarse"\n[loads]\nF1_N = [5, 80]\n'
                     '[[outputs]]\nkind = "lifetimes"\n[[outputs]]\nkind = "figure"\nfigure = "lifetime_vs_force"\n')
    code, _, err = run_cli(capsys, "run", scene, "--out", tmp_path / "out")
    line = err.strip().splitlines()[-1]
    assert code == 3 and "stiffness.u_max_mm = 2.349 runs; lifetimes refused at F1 = 5, 80 N, beyond the curve: " \
                         "stiffness curve: r_start needs h = 7 mm, outside the curve's range" in line
    table = pd.read_csv(tmp_path / "out" / "lifetimes.csv")
    assert list(table["force_N"]) == [5, 80] and list(table["reason"]) == ["beyond_partial_curve"] * 2
    assert table["lifetime_s"].isna().all()
    refused = json.loads((tmp_path / "out" / "manifest.json").read_text())["partial"]["study"]["refused"]
    assert [r["force_N"] for r in refused] == [5, 80]
    # without keep_partial (a sweep's designs) the failure is raised, as before
    from fem.solver import ConvergenceError
    from validation.bridge.products import Products
    study = scene_from_mapping({"cup": {"geometry": str(tmp_path / "thin.toml")}, "stiffness": {"fidelity": "coarse"},
                                "outputs": [{"kind": "lifetimes"}]}).study()
    with pytest.raises(ConvergenceError):
        Products(study, cache_dir=tmp_path / "cache").curve()


def test_the_footprints_scale_file_names_what_it_shows(tmp_path):
    """The footprint's JSON repeats the view's provenance with a fields file's keys: its caption
    is the image's, and the material is the one the FEM ran."""
    from validation.render import probe_offscreen_rendering
    from validation.render.caption import provenance_caption

    probe = probe_offscreen_rendering()
    if not probe.ok:
        pytest.skip(probe.message)
    run_scene({"material": {"E_MPa": 5.0}, "contact": {"law": "coulomb", "friction": 0.5},
               "outputs": [{"kind": "footprint", "name": "fp", "u_mm": 3}]}, tmp_path / "out")
    scale = json.loads((tmp_path / "out" / "fp.json").read_text())
    assert provenance_caption(scale) == "cup A, coulomb mu = 0.5, coarse mesh"
    assert scale["material"] == "neo-Hookean E = 5 MPa, nu = 0.49 (displacement)"
    assert scale["u_m"] == pytest.approx(3e-3) and scale["m_per_px"] > 0
