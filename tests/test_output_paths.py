"""Outputs never destroy (issue 26) and own their folder (issue 25): a special file, an input of
the run or another output of it is refused before any work, exit 2, one line naming both; a
rerun into an output directory leaves only what its manifest lists."""

import json
import os
import stat
from pathlib import Path

import pytest
from filelock import FileLock

from tests.cli import run_cli
from validation.output import atomic_directory, atomic_file, check_outputs

UC = ["uc", "--surface", "pmma-1.89", "--E-MPa", "4", "--p-kPa", "10", "20"]
GOOD_UC = "p_over_E,u_c_m\n1e-4,2e-6\n1e-3,1e-6\n1e-2,5e-7\n1e-1,1e-7\n"


def _tree(directory: Path) -> dict[str, bytes | None]:
    return {p.relative_to(directory).as_posix(): (p.read_bytes() if p.is_file() and not p.is_fifo() else None)
            for p in directory.rglob("*")}


def _refused(capsys, argv, *names) -> str:
    code, _, err = run_cli(capsys, *argv)
    assert code == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for name in names:
        assert str(name) in err, err
    return err


def test_dev_null_is_refused_and_not_touched(capsys):
    before = os.stat("/dev/null")
    err = _refused(capsys, UC + ["--out", "/dev/null"], "--out", "'/dev/null'", "character device")
    after = os.stat("/dev/null")
    assert stat.S_ISCHR(after.st_mode) and (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev), err


def test_a_fifo_and_a_symlink_to_it_are_refused(tmp_path, capsys):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    (tmp_path / "link.csv").symlink_to(fifo)
    before = _tree(tmp_path)
    _refused(capsys, UC + ["--out", fifo], "FIFO")
    _refused(capsys, UC + ["--out", tmp_path / "link.csv"], "FIFO")
    _refused(capsys, ["lifetime", "--out", fifo], "--out", "is a FIFO, not a directory")
    assert _tree(tmp_path) == before and stat.S_ISFIFO(os.stat(fifo).st_mode)


@pytest.mark.parametrize("argv", [["uc", "--surface", "pmma-1.89", "--E-MPa", "4", "--out", ""],
                                  ["uc", "--surface", "pmma-1.89", "--E-MPa", "4", "--out="],
                                  ["lifetime", "--out", ""], ["stiffness", "--out", ""],
                                  ["run", "s.toml", "--out", ""]])
def test_an_empty_out_is_refused(tmp_path, capsys, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    _refused(capsys, argv, "--out: the value is empty")
    assert list(tmp_path.iterdir()) == []


def test_the_design_sidecar_would_overwrite_the_design(tmp_path, capsys):
    """`stiffness --geometry mycup.json --out mycup.csv`: the curve's sidecar is the design file."""
    design = tmp_path / "mycup.json"
    design.write_text("r1_mm = 25\n")
    before = _tree(tmp_path)
    _refused(capsys, ["stiffness", "--geometry", design, "--out", tmp_path / "mycup.csv"],
             "--out's sidecar", f"'{design}'", "--geometry")
    assert _tree(tmp_path) == before


def test_a_companion_file_replaces_only_its_own_kind(tmp_path, capsys):
    """The curve's sidecar and the footprint's scale are files the user did not name: an existing
    file there is replaced only if cupcheck wrote one of that kind before."""
    design = tmp_path / "mycup.json"
    design.write_text('{"r1_mm": 25}')
    sidecar = tmp_path / "curve.json"
    sidecar.write_text('{"provenance": {"source": "fem"}}')
    (tmp_path / "f.vtu").write_text("fields")
    before = _tree(tmp_path)
    _refused(capsys, ["stiffness", "--out", tmp_path / "mycup.csv"],
             f"--out's sidecar: '{design}' exists and is not what cupcheck writes there")
    _refused(capsys, ["render", tmp_path / "f.vtu", "--view", "footprint", "--out", tmp_path / "curve.png"],
             f"--out's scale: '{sidecar}' exists and is not what cupcheck writes there (a JSON object with 'm_per_px')")
    assert _tree(tmp_path) == before
    check_outputs(files={"--out": tmp_path / "curve.csv"}, companions={"--out's sidecar": (sidecar, "provenance")})


def test_an_input_is_not_an_output(tmp_path, capsys):
    psd = tmp_path / "p.csv"
    psd.write_text("q_per_m,C_m4\n1e3,1e-28\n1e4,1e-31\n1e5,1e-34\n")
    (tmp_path / "hard.csv").hardlink_to(psd)             # the same file under another name
    (tmp_path / "sym.csv").symlink_to(psd)
    before = _tree(tmp_path)
    for out in ("p.csv", "hard.csv", "sym.csv"):
        _refused(capsys, UC[:1] + ["--psd", psd, "--E-MPa", "4", "--out", tmp_path / out], "--out", "--psd")
    assert _tree(tmp_path) == before


def test_an_input_inside_the_output_directory_is_refused(tmp_path, capsys):
    """The output directory is replaced as a whole: an input inside it would be lost."""
    out = tmp_path / "run"
    out.mkdir()
    (out / "manifest.json").write_text('{"files": []}\n')
    (out / "u.csv").write_text(GOOD_UC)
    before = _tree(tmp_path)
    _refused(capsys, ["lifetime", "--uc-table", out / "u.csv", "--out", out], "--out", "holds the input --uc-table")
    assert _tree(tmp_path) == before


def test_a_cache_inside_the_output_is_refused(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text('[stiffness]\nsource = "appendix-a"\n[[outputs]]\nkind = "lifetimes"\n')
    _refused(capsys, ["run", scene, "--out", tmp_path / "out", "--cache-dir", tmp_path / "out" / "c"],
             "--out", "--cache-dir", "are one output")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_two_outputs_that_are_one_file_are_refused(tmp_path):
    (tmp_path / "a.csv").write_text("x\n")
    (tmp_path / "b.csv").symlink_to(tmp_path / "a.csv")
    with pytest.raises(ValueError, match="--out: .* and --fields-out .* are one output"):
        check_outputs(files={"--out": tmp_path / "a.csv", "--fields-out": tmp_path / "b.csv"})
    with pytest.raises(ValueError, match="are one output"):
        check_outputs(files={"x": tmp_path / "d" / "f.csv"}, directories={"y": tmp_path / "d"})
    check_outputs(files={"--out": tmp_path / "a.csv", "--fields-out": tmp_path / "c.csv"})


def test_a_directory_cupcheck_did_not_write_is_not_replaced(tmp_path, capsys):
    notes = tmp_path / "notes"
    notes.mkdir()
    (notes / "thesis.tex").write_text("months of work\n")
    before = _tree(tmp_path)
    _refused(capsys, ["lifetime", "--force", "10", "--out", notes], "--out", "holds files cupcheck did not write")
    assert _tree(tmp_path) == before


def test_a_rerun_leaves_only_what_its_manifest_lists(tmp_path, capsys):
    out = tmp_path / "run"
    assert run_cli(capsys, "lifetime", "--force", "10", "20", "--out", out)[0] == 0
    assert {"trajectory_F1_10N.csv", "trajectory_F1_20N.csv"} <= set(os.listdir(out))
    assert run_cli(capsys, "lifetime", "--force", "30", "--out", out)[0] == 0
    listed = {f["path"] for f in json.loads((out / "manifest.json").read_text())["files"]}
    assert set(os.listdir(out)) == listed | {"manifest.json"}
    assert listed == {"summary.json", "trajectory_F1_30N.csv"}
    assert sorted(os.listdir(tmp_path)) == ["run"]               # no temporaries, no lock


def test_a_later_success_removes_a_stale_failure_record(tmp_path, capsys):
    record = tmp_path / "run.failure.json"
    record.write_text(json.dumps({"error": "did not converge", "residual_history": [1.0]}))
    other = tmp_path / "other.failure.json"                      # not cupcheck's record: kept
    other.write_text("{}")
    assert run_cli(capsys, "lifetime", "--force", "10", "--out", tmp_path / "run")[0] == 0
    assert not record.exists() and other.exists()
    curve = tmp_path / "uc.csv"
    (tmp_path / "uc.failure.json").write_text(record.read_text() if record.exists() else
                                              json.dumps({"error": "x", "residual_history": []}))
    assert run_cli(capsys, *UC, "--out", curve)[0] == 0
    assert curve.is_file() and not (tmp_path / "uc.failure.json").exists()


def test_a_lock_through_a_symlink_is_the_same_lock(tmp_path, capsys):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "alias").symlink_to(real)
    with FileLock(str(tmp_path / ".real.lock")):                 # a first run writing 'real'
        _refused(capsys, ["lifetime", "--json", "--force", "10", "--out", tmp_path / "alias"], "another cupcheck run")
    assert list(real.iterdir()) == []


def test_leftovers_of_a_killed_run_are_removed_by_the_next(tmp_path):
    out = tmp_path / "run"
    stale_dir = tmp_path / ".run.4242.0badcafe.tmp"
    stale_dir.mkdir()
    (stale_dir / "big.csv").write_text("1\n" * 1000)
    old = tmp_path / ".run.4243.deadbeef.old"
    old.mkdir()
    stale_file = tmp_path / ".c.csv.77.12345678.tmp.csv"
    stale_file.write_text("half")
    keep = tmp_path / ".run.user-notes"                            # not cupcheck's name pattern
    keep.write_text("mine")
    with atomic_directory(out) as tmp:
        (tmp / "a.txt").write_text("a")
    assert not stale_dir.exists() and not old.exists() and keep.exists() and stale_file.exists()
    with atomic_file(tmp_path / "c.csv") as tmp:
        tmp.write_text("x\n")
    assert not stale_file.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [".run.user-notes", "c.csv", "run"]


def test_a_refused_run_leaves_no_empty_directories(tmp_path):
    with pytest.raises(ValueError, match="refused inside"):
        with atomic_directory(tmp_path / "a" / "b" / "out"):
            raise ValueError("refused inside the run")
    with pytest.raises(ValueError, match="refused inside"):
        with atomic_file(tmp_path / "c" / "d.csv"):
            raise ValueError("refused inside the run")
    assert list(tmp_path.iterdir()) == []


def test_the_output_directory_gets_the_umask_permissions(tmp_path):
    with atomic_directory(tmp_path / "out") as tmp:
        (tmp / "a.txt").write_text("a")
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(os.stat(tmp_path / "out").st_mode) == 0o777 & ~mask


def test_forces_equal_after_formatting_are_refused(tmp_path, capsys):
    _refused(capsys, ["lifetime", "--force", "10", "10.0000001", "--out", tmp_path / "run"],
             "--force 10.0000001: its file 'trajectory_F1_10N.csv' is also written by --force 10.0")
    assert list(tmp_path.iterdir()) == []


APPENDIX = '[stiffness]\nsource = "appendix-a"\n'


@pytest.mark.parametrize("scene,message", [
    (APPENDIX + '[loads]\nF1_N = [10, 10.0000001]\n[[outputs]]\nkind = "trajectories"\nname = "t"\n',
     "at F1 = 10.0000001 N: its file 't_F1_10N.csv' is also written by outputs[0] (trajectories 't') at F1 = 10.0 N"),
    (APPENDIX + '[[outputs]]\nkind = "curve"\nname = "manifest"\n',
     "outputs[0] (curve 'manifest'): its file 'manifest.json' is also written by the scene's manifest"),
    ('[[outputs]]\nkind = "curve"\nname = "x"\n[[outputs]]\nkind = "footprint"\nname = "x"\nu_mm = 3\n',
     "outputs[1] (footprint 'x'): its file 'x.json' is also written by outputs[0] (curve 'x')"),
    ('[[outputs]]\nkind = "squeeze"\nname = "s"\nu_mm = 3\n[[outputs]]\nkind = "figure"\nfigure = "F0_vs_u"\n'
     'name = "s_00"\n', "outputs[1] (figure 's_00'): its file 's_00.png' is also written by outputs[0] (squeeze 's')"),
])
def test_two_scene_outputs_writing_one_file_are_refused_before_any_work(tmp_path, capsys, scene, message):
    (tmp_path / "s.toml").write_text(scene)
    _refused(capsys, ["run", tmp_path / "s.toml", "--out", tmp_path / "out", "--no-cache"], message)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_the_planned_files_are_the_files_a_scene_writes(tmp_path):
    """The plan the collision check reads is what the scene writes (a real run, reduced model)."""
    from validation.scenes.outputs import planned_files, run_scene
    from validation.scenes.schema import load_scene

    scene = load_scene(Path(__file__).resolve().parents[1] / "scenes" / "trajectories_cupA.toml")
    run_scene(scene, tmp_path / "out")
    planned = {name for names in planned_files(scene).values() for name in names}
    assert set(os.listdir(tmp_path / "out")) == planned | {"manifest.json"}


# --- property: random file systems and output sets --------------------------------------------------

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

#: what a name in the test's directory is: nothing, a file, a directory (with one file), a FIFO, or
#: a symlink to another name
ENTRY = st.sampled_from(["missing", "file", "dir", "fifo", "link0", "link1"])


def _build(root: Path, kinds: list[str]) -> list[Path]:
    paths = [root / f"e{i}" for i in range(len(kinds))]
    for path, kind in zip(paths, kinds):
        if kind == "file":
            path.write_text("x")
        elif kind == "dir":
            path.mkdir()
            (path / "inner.csv").write_text("y")
        elif kind == "fifo":
            os.mkfifo(path)
    for path, kind in zip(paths, kinds):
        if kind.startswith("link"):
            path.symlink_to(paths[int(kind[-1])])
    return paths


@settings(max_examples=80, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(kinds=st.lists(ENTRY, min_size=2, max_size=5),
       outs=st.lists(st.tuples(st.integers(0, 4), st.sampled_from(["file", "directory"]), st.booleans()),
                     min_size=1, max_size=3),
       ins=st.lists(st.tuples(st.integers(0, 4), st.booleans()), max_size=2))
def test_accepted_outputs_destroy_nothing(tmp_path_factory, kinds, outs, ins):
    """Whatever the file system, check_outputs raises only ValueError; what it accepts is no
    special file, no existing directory for a file or file for a directory, no directory
    cupcheck did not write, no two outputs on one path and no input at or inside an output."""
    root = tmp_path_factory.mktemp("fs")
    paths = _build(root, kinds)
    pick = lambda i, inner: paths[i % len(paths)] / "inner.csv" if inner else paths[i % len(paths)]  # noqa: E731
    files = {f"out{k}": pick(i, inner) for k, (i, kind, inner) in enumerate(outs) if kind == "file"}
    dirs = {f"out{k}": pick(i, inner) for k, (i, kind, inner) in enumerate(outs) if kind == "directory"}
    inputs = {f"in{k}": pick(i, inner) for k, (i, inner) in enumerate(ins)}
    try:
        check_outputs(files=files, directories=dirs, inputs=inputs)
    except ValueError as exc:
        assert "\n" not in str(exc)
        return
    real = {label: Path(os.path.realpath(p)) for label, p in {**files, **dirs}.items()}
    for label, path in real.items():
        if path.exists():
            mode = os.stat(path).st_mode
            assert stat.S_ISREG(mode) if label in files else stat.S_ISDIR(mode)
            if label in dirs:
                assert not os.listdir(path) or (path / "manifest.json").exists()
    assert len(set(real.values())) == len(real)
    for p in inputs.values():
        r = Path(os.path.realpath(p))
        assert all(r != o and not (label in dirs and o in r.parents) for label, o in real.items())
