"""The command line's error contract: every error is one stderr line; bad input exits 2 before any
work, a failed solve exits 1; neither leaves a file behind (common brief, review items 19-21, 23)."""

import functools
import json
from pathlib import Path

import pytest

import fem.cup
import fem.fields
from validation.cli import main


def _files(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.rglob("*"))


def _one_line(err: str) -> str:
    lines = err.splitlines()
    assert len(lines) == 1, err
    return lines[0]


@pytest.fixture
def no_solve(monkeypatch):
    """Make the solve itself an error, so that a refusal shows it came before the solve."""
    def refuse(*args, **kwargs):
        raise AssertionError("the solve started before the input was checked")
    monkeypatch.setattr(fem.cup, "compress_cup", refuse)


# --- argparse's errors: one line naming the subcommand, exit 2 ------------------------------------

@pytest.mark.parametrize("argv,message", [
    (["stiffness", "--cup", "C"],
     "cupcheck stiffness: error: argument --cup: invalid cup 'C' (choose from A, B, any case)"),
    (["stiffness", "--E-MPa", "abc"],
     "cupcheck stiffness: error: argument --E-MPa: invalid float value: 'abc'"),
    (["stiffness", "--u-max-mm"],
     "cupcheck stiffness: error: argument --u-max-mm: expected one argument"),
    (["stiffness", "--bogus", "1"], "cupcheck stiffness: error: unrecognized arguments: --bogus 1"),
    (["lifetime", "--uc-method", "exact"], "cupcheck lifetime: error: argument --uc-method: "
                                           "invalid choice: 'exact' (choose from 'emt', 'critical-junction')"),
    (["lifetime", "--force", "ten"], "cupcheck lifetime: error: argument --force: invalid float value: 'ten'"),
    (["nonsense"], "cupcheck: error: argument COMMAND: invalid choice: 'nonsense' (choose from "
                   "'example', 'lifetime', 'paper', 'render', 'run', 'stiffness', 'suction', 'sweep', 'uc', 'validate')"),
])
def test_parser_errors_are_one_line_and_exit_2(tmp_path, monkeypatch, capsys, no_solve, argv, message):
    monkeypatch.chdir(tmp_path)                 # anything written by mistake would land here
    out = ["--out", str(tmp_path / "c.csv")] if argv[0] == "stiffness" else []
    with pytest.raises(SystemExit) as exit_:
        main([*argv, *out])
    assert exit_.value.code == 2
    captured = capsys.readouterr()
    assert _one_line(captured.err) == message and captured.out == ""
    assert _files(tmp_path) == []


def test_missing_required_option_is_one_line(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_:
        main(["stiffness", "--cup", "B"])
    assert exit_.value.code == 2
    assert _one_line(capsys.readouterr().err) == \
        "cupcheck stiffness: error: the following arguments are required: --out"
    assert _files(tmp_path) == []


def test_help_keeps_the_full_usage(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["stiffness", "--help"])
    assert exit_.value.code == 0
    text = capsys.readouterr().out
    assert text.startswith("usage: cupcheck stiffness") and "--E-MPa" in text and "--formulation" in text


# --- output paths: checked before the solve ---------------------------------------------------------

@pytest.mark.parametrize("argv,message", [
    (["--out", "{d}/curve.txt"], "out: the stiffness curve must be a .csv file"),
    (["--out", "{d}/taken.csv"], "out: '{d}/taken.csv' is a directory"),
    (["--out", "{d}/curve.csv"], "out: its sidecar '{d}/curve.json' is a directory"),
    (["--out", "{d}/plain/sub/c.csv"], "out: cannot create the directory of '{d}/plain/sub/c.csv': "
                                      "'{d}/plain' is a file"),
    (["--out", "{d}/c.csv", "--fields-out", "{d}/f.obj"],
     "fields_out: must end in .vtu or .vtk (the last step) or .xdmf (every step)"),
    (["--out", "{d}/c.csv", "--fields-out", "{d}/fields.vtu"], "fields_out: '{d}/fields.vtu' is a directory"),
    (["--out", "{d}/c.csv", "--fields-out", "{d}/plain/f.xdmf"],
     "fields_out: cannot create the directory of '{d}/plain/f.xdmf': '{d}/plain' is a file"),
])
def test_unwritable_output_is_refused_before_the_solve(tmp_path, capsys, no_solve, argv, message):
    (tmp_path / "taken.csv").mkdir()
    (tmp_path / "curve.json").mkdir()
    (tmp_path / "fields.vtu").mkdir()
    (tmp_path / "plain").write_text("a file, not a directory\n")
    before = _files(tmp_path)
    d = str(tmp_path)
    assert main(["stiffness", *[a.format(d=d) for a in argv]]) == 2
    assert _one_line(capsys.readouterr().err).startswith(f"cupcheck stiffness: error: {message.format(d=d)}")
    assert _files(tmp_path) == before


# --- a failed solve: exit 1, one line saying where and why, no files -------------------------------

def test_solver_failure_exits_1_and_leaves_no_files(tmp_path, monkeypatch, capsys):
    # the real solver, allowed 2 Newton iterations and no cut-back below half the path: step 1
    # cannot converge (fem.solver.ConvergenceError, a RuntimeError)
    monkeypatch.setattr(fem.cup, "compress_cup", functools.partial(
        fem.cup.compress_cup, max_iterations=2, initial_step=0.5, min_step=0.5))
    out = tmp_path / "new" / "curve.csv"
    assert main(["stiffness", "--fidelity", "coarse", "--u-max-mm", "2", "--out", str(out),
                 "--fields-out", str(tmp_path / "fields.xdmf")]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err[-1].startswith("cupcheck stiffness: failed: load step 1 from u = 0 to ")
    assert " mm did not converge (residual " in err[-1]
    assert "likely cause" in err[-1] and len(err[-1]) < 400
    # the residual history goes to a log the line names; no curve, sidecar or fields
    log = out.with_suffix(".failure.json")
    assert str(log) in err[-1] and _files(tmp_path) == ["curve.failure.json", "new"]
    record = json.loads(log.read_text())
    assert record["step"] == 1 and 0 < record["u_to_mm"] <= 2 and len(record["residual_history"]) == 2


def test_failure_while_writing_leaves_none_of_the_files(tmp_path, monkeypatch, capsys):
    # the curve and the sidecar are written first, the fields last: a failure there must take
    # the other two with it
    def broken(resp, path, step=-1, provenance=None):
        Path(path).write_text("half a file")
        raise RuntimeError("fields: disk full")
    monkeypatch.setattr(fem.fields, "write_fields", broken)
    assert main(["stiffness", "--fidelity", "coarse", "--u-max-mm", "0.3",
                 "--out", str(tmp_path / "curve.csv"), "--fields-out", str(tmp_path / "f.vtu")]) == 1
    assert capsys.readouterr().err.splitlines()[-1] == "cupcheck stiffness: failed: fields: disk full"
    assert _files(tmp_path) == []


def test_example_solver_failure_is_one_line_in_mm_with_a_log(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(fem.cup, "compress_cup", functools.partial(
        fem.cup.compress_cup, max_iterations=2, initial_step=0.5, min_step=0.5))
    out = tmp_path / "ex"
    assert main(["example", "--fidelity", "coarse", "--out", str(out)]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err[-1].startswith("cupcheck example: failed: load step 1 from u = 0 to ") and " mm did " in err[-1]
    assert _files(tmp_path) == ["ex.failure.json"]          # the log only: no half-written output
    assert json.loads((tmp_path / "ex.failure.json").read_text())["step"] == 1
