"""`cupcheck lifetime` and `cupcheck example`: JSON output, trajectory files, bad input."""

import json
import math

import pytest

from reduced.critical_gap import ILLUSTRATIVE_UC_CSV, UcTable
from reduced.cup import CUP_A
from reduced.lifetime import lifetime_by_quadrature, reference_model
from tests.cli import run_cli as _run
from validation.cli import main



def test_json_reference_mode(capsys):
    code, out, _ = _run(capsys, "lifetime", "--reference-mode", "--cup", "A", "--force", "5", "40",
                        "200", "--surface", "illustrative", "--json")
    assert code == 0
    rows = json.loads(out)
    assert [r["force_N"] for r in rows] == [5.0, 40.0, 200.0]
    model = reference_model(CUP_A, UcTable.from_csv(ILLUSTRATIVE_UC_CSV))
    for r in rows[:2]:
        assert set(r) >= {"force_N", "lifetime_s", "reason", "sealed", "ballistic_share"}
        # reproducible from outside: the same conventions through the library's quadrature
        assert r["lifetime_s"] == pytest.approx(lifetime_by_quadrature(model, r["force_N"]), rel=1e-4)
    assert rows[2]["reason"] == "over_force" and rows[2]["lifetime_s"] == 0.0


def test_sealed_prints_null_lifetime(capsys, tmp_path):
    table = tmp_path / "sealed.csv"
    table.write_text("p_over_E,u_c_m\n1e-4,1e-6\n1e-3,1e-7\n2e-3,0\n")
    code, out, _ = _run(capsys, "lifetime", "--uc-table", str(table), "--force", "10", "--json")
    row = json.loads(out)[0]
    assert code == 0 and row["lifetime_s"] is None and row["sealed"] is True
    assert "NaN" not in out and "Infinity" not in out


def test_out_writes_trajectories_atomically(capsys, tmp_path):
    out = tmp_path / "run"
    code, stdout, _ = _run(capsys, "lifetime", "--force", "10", "20", "--relaxation", "default",
                           "--out", str(out))
    assert code == 0 and "reached_r1" in stdout
    files = sorted(p.name for p in out.iterdir())
    assert files == ["manifest.json", "summary.json", "trajectory_F1_10N.csv", "trajectory_F1_20N.csv"]
    lines = (out / "trajectory_F1_10N.csv").read_text().splitlines()
    assert lines[0] == "cup,t_s,r_mm,h_mm,p_b_Pa,p_Pa,u_c_nm,N,N_dot_per_s,phi_s,ballistic_share"
    assert lines[1].startswith("A,0,")
    assert len(lines) > 10
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]   # no temp dirs left


@pytest.mark.parametrize("argv,message", [
    (["--force", "-3"], "--force: pull force must be > 0 N"),
    (["--cup", "C"], "argument --cup: invalid cup 'C'"),
    (["--uc-table", "/nonexistent/uc.csv"], "uc-table: no such file"),
    (["--stiffness", "/nonexistent/F0.csv"], "--stiffness: no such file"),
    (["--relaxation", "/nonexistent/E.csv"], "relaxation: no such file"),
    (["--reference-mode", "--E-MPa", "3"], "--reference-mode: fixes --E-MPa"),
    (["--E-MPa", "0"], "--E-MPa: Young's modulus must be > 0 MPa"),
    (["--fluid", "water", "--relaxation", "default"], "fluid: the water-filled cavity"),
    (["--reference-mode", "--fluid", "water"], "--reference-mode: fixes --fluid"),
    (["--cavitation-kPa", "2.34"], "--cavitation-kPa: only with --fluid water"),
    (["--fluid", "water", "--cavitation-kPa", "100"], "--cavitation-kPa: must be in [0, p_a) = [0, 100) kPa"),
])
def test_bad_input_exits_2_with_one_line_and_no_output(capsys, tmp_path, argv, message):
    out = tmp_path / "out"
    code, stdout, err = _run(capsys, "lifetime", *argv, "--out", str(out))
    assert code == 2
    assert err.count("\n") == 1 and message in err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_help_names_every_unit(capsys):
    with pytest.raises(SystemExit):
        main(["lifetime", "--help"])
    text = capsys.readouterr().out
    for unit in ("F1_N", "in MPa", "in mm", "in K", "in Pa", "in s", "u_c in m", "in Pa s"):
        assert unit in text


def test_example_writes_table_and_figure(capsys, tmp_path):
    code, stdout, _ = _run(capsys, "example", "--out", str(tmp_path / "ex"))
    assert code == 0
    lines = (tmp_path / "ex" / "lifetime_vs_force.csv").read_text().splitlines()
    assert lines[0].startswith("cup,route,contact,mesh,surface,force_N,lifetime_s,reason")
    assert len(lines) == 17                                   # 5, 10, ..., 80 N
    # the default route, contact law, mesh level and surface, named on every row
    assert all(l.startswith("A,profile,frictionless,medium,pmma-1.89,") for l in lines[1:])
    lives = [float(l.split(",")[6]) for l in lines[1:]]
    assert all(math.isfinite(t) and t > 0 for t in lives)
    png = (tmp_path / "ex" / "lifetime_vs_force.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_stiffness_csv_is_the_same_mechanism_as_appendix_a(capsys, tmp_path):
    from reduced.appendix_a import appendix_a_curve
    path = appendix_a_curve(CUP_A).to_csv(tmp_path / "F0.csv")
    code, out, _ = _run(capsys, "lifetime", "--stiffness", str(path), "--force", "20", "--json")
    code_ref, out_ref, _ = _run(capsys, "lifetime", "--reference-mode", "--force", "20", "--json")
    assert code == code_ref == 0
    # the CSV holds the same samples to 10 digits: the same lifetime to ~1e-9
    assert json.loads(out)[0]["lifetime_s"] == pytest.approx(json.loads(out_ref)[0]["lifetime_s"], rel=1e-7)
    code, _, err = _run(capsys, "lifetime", "--stiffness", str(path), "--cup-laws", "curve", "--force", "20")
    assert code == 2 and "geometry: 'curve' needs" in err


def test_water_json(capsys):
    code, out, _ = _run(capsys, "lifetime", "--fluid", "water", "--force", "10", "--json")
    row = json.loads(out)[0]
    assert code == 0 and row["reason"] == "reached_r1" and row["largest_force_N"] is None
    _, out_air, _ = _run(capsys, "lifetime", "--force", "10", "--json")
    # "the much higher viscosity of water than of air results in a longer failure time" (Sec. 5.4)
    assert row["lifetime_s"] > 10 * json.loads(out_air)[0]["lifetime_s"]


@pytest.mark.parametrize("argv,message", [
    (["--cup", "Z"], "argument --cup: invalid cup 'Z'"),
    (["--uc-table", "/nonexistent/uc.csv"], "uc-table: no such file"),
])
def test_example_bad_input_exits_2_without_output(capsys, tmp_path, argv, message):
    code, _, err = _run(capsys, "example", "--out", str(tmp_path / "ex"), *argv)
    assert code == 2 and err.count("\n") == 1 and message in err
    assert list(tmp_path.iterdir()) == []


def test_kappa_scales_the_stiffness_as_a_scaled_curve(capsys):
    """--kappa k is the same model as a stiffness curve with F0 scaled by k (the paper's Fig.
    1stiffnessFactor); a stiffer cup presses the strip harder and holds longer at 10 N."""
    from reduced.appendix_a import appendix_a_curve
    from reduced.lifetime import reference_model, solve_lifetime

    code, out, _ = _run(capsys, "lifetime", "--kappa", "2", "--force", "10", "--surface", "illustrative", "--json")
    assert code == 0
    base = reference_model(CUP_A, UcTable.from_csv(ILLUSTRATIVE_UC_CSV))
    import dataclasses
    scaled = dataclasses.replace(base, stiffness=appendix_a_curve(CUP_A).scaled(2.0))
    assert json.loads(out)[0]["lifetime_s"] == pytest.approx(solve_lifetime(scaled, 10.0, route="paper").lifetime_s,
                                                                     rel=1e-9)
    assert json.loads(out)[0]["lifetime_s"] > solve_lifetime(base, 10.0, route="paper").lifetime_s
    code, _, err = _run(capsys, "lifetime", "--kappa", "0")
    assert code == 2 and "--kappa: stiffness factor must be > 0" in err


def test_lifetimes_study_flags_are_the_fields():
    """The options of `lifetime` that are study fields are the schema's flags: the same attribute,
    choices and command-line default as `example` and the scenes (`validation.study_schema`)."""
    import argparse

    from validation.cli import build_parser
    from validation.commands.lifetime import KEYS
    from validation.study_schema import field_of

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    actions = {a.option_strings[-1]: a for a in sub.choices["lifetime"]._actions if a.option_strings}
    for key in KEYS:
        f = field_of(key)
        action = actions[f.flag]
        assert action.dest == f.dest, key
        if key == "stiffness.route":                      # lifetime's own default route: paper
            assert action.default == "paper" and tuple(action.choices) == f.choices_in("cli")
            continue
        assert action.default == f.default_in("cli"), key
        if key == "material.relaxation":                  # a relaxation CSV besides the field's choices
            assert action.choices is None
        elif f.type == "choice" and action.choices is not None:
            assert tuple(action.choices) == f.choices_in("cli"), key
