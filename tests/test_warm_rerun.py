"""A scene rerun into the same directory draws only what changed, with real files: a rerun of an
unchanged scene writes nothing (every file keeps its inode and mtime, the manifest too); an
edited input file redraws the outputs made from it and keeps the others; a deleted or edited
output is drawn again, alone; --no-cache draws everything afresh. A file "kept" is the same
inode with the same mtime; a file "redrawn" is a new inode."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reduced.critical_gap import ILLUSTRATIVE_UC_CSV
from validation.bridge import products as pipeline
from validation.cli import main

#: the reduced model alone (Appendix A): a lifetime table and trajectories on a u_c table file
SCENE = """
[stiffness]
source = "appendix-a"
[surface]
uc_table = "uc.csv"
[loads]
F1_N = [10, 40]
[[outputs]]
kind = "lifetimes"
[[outputs]]
kind = "trajectories"
name = "trajectory"
"""


def _stamps(directory: Path) -> dict[str, tuple[int, int]]:
    """(inode, mtime in ns) of every file in `directory`."""
    return {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in directory.iterdir()}


def _run(tmp_path: Path, capsys, *extra: str) -> str:
    argv = ["run", str(tmp_path / "scene.toml"), "--out", str(tmp_path / "out"),
            "--cache-dir", str(tmp_path / "cache"), "--quiet", *extra]
    assert main(argv) == 0
    return capsys.readouterr().out


def _double_the_gaps(table: Path) -> None:
    rows = table.read_text().splitlines()
    head = [r for r in rows if not r[:1].isdigit()]
    body = [f"{p},{2 * float(u)!r}" for p, u in (r.split(",") for r in rows if r[:1].isdigit())]
    table.write_text("\n".join(head + body) + "\n")


@pytest.fixture
def scene(tmp_path: Path) -> Path:
    (tmp_path / "uc.csv").write_text(Path(ILLUSTRATIVE_UC_CSV).read_text())
    (tmp_path / "scene.toml").write_text(SCENE)
    return tmp_path


def test_an_unchanged_rerun_writes_nothing(scene, capsys):
    out = scene / "out"
    _run(scene, capsys)
    first = _stamps(out)
    assert set(first) == {"lifetimes.csv", "trajectory_F1_10N.csv", "trajectory_F1_40N.csv", "manifest.json"}
    pipeline.COMPUTED.clear()
    said = _run(scene, capsys)
    assert _stamps(out) == first                     # not one file touched, the manifest neither
    assert "up to date (nothing written)" in said and not pipeline.COMPUTED
    manifest = json.loads((out / "manifest.json").read_text())
    for entry in manifest["files"]:                   # what each file was made from, and its bytes
        assert len(entry["key"]) == 32 and len(entry["sha256"]) == 64


def test_a_rerun_leaves_no_file_its_manifest_does_not_list(scene, capsys):
    """A file put into the output directory after a run (an old figure) is not part of the run: the
    unchanged rerun is then not up to date, keeps its intact outputs (same inodes) and replaces
    the directory, so only what the manifest lists stays."""
    out = scene / "out"
    _run(scene, capsys)
    first = _stamps(out)
    (out / "old_figure.png").write_bytes(b"not this run's")
    pipeline.COMPUTED.clear()
    said = _run(scene, capsys)
    assert "up to date" not in said and "3 unchanged kept" in said and not pipeline.COMPUTED
    assert set(_stamps(out)) == set(first)
    assert all(_stamps(out)[name][0] == first[name][0] for name in first if name != "manifest.json")
    listed = {f["path"] for f in json.loads((out / "manifest.json").read_text())["files"]}
    assert {p.name for p in out.iterdir()} == listed | {"manifest.json"}


def test_an_edited_input_file_redraws_what_is_made_from_it(scene, capsys):
    out = scene / "out"
    _run(scene, capsys)
    before, table = _stamps(out), (out / "lifetimes.csv").read_text()
    _double_the_gaps(scene / "uc.csv")                # the same path, other bytes
    _run(scene, capsys)
    after = _stamps(out)
    assert all(after[name][0] != before[name][0] for name in before)     # every output is made from it
    assert (out / "lifetimes.csv").read_text() != table                  # wider gaps: shorter lives


def test_a_deleted_output_is_drawn_again_alone(scene, capsys):
    out = scene / "out"
    _run(scene, capsys)
    before, table = _stamps(out), (out / "lifetimes.csv").read_bytes()
    (out / "lifetimes.csv").unlink()
    said = _run(scene, capsys)
    after = _stamps(out)
    assert (out / "lifetimes.csv").read_bytes() == table
    assert after["trajectory_F1_10N.csv"] == before["trajectory_F1_10N.csv"]
    assert after["trajectory_F1_40N.csv"] == before["trajectory_F1_40N.csv"]
    assert after["lifetimes.csv"][0] != before["lifetimes.csv"][0]
    assert "wrote 1 files, 2 unchanged kept" in said


def test_an_edited_output_is_drawn_again(scene, capsys):
    out = scene / "out"
    _run(scene, capsys)
    before = _stamps(out)
    good = (out / "trajectory_F1_40N.csv").read_bytes()
    (out / "trajectory_F1_40N.csv").write_bytes(good.replace(b"4", b"5"))     # same name, other bytes
    _run(scene, capsys)
    after = _stamps(out)
    assert (out / "trajectory_F1_40N.csv").read_bytes() == good
    assert after["lifetimes.csv"] == before["lifetimes.csv"]
    assert after["trajectory_F1_10N.csv"][0] != before["trajectory_F1_10N.csv"][0]   # one output, both its files


def test_no_cache_draws_everything_afresh(scene, capsys):
    out = scene / "out"
    _run(scene, capsys)
    before = _stamps(out)
    _run(scene, capsys, "--no-cache")
    after = _stamps(out)
    assert all(after[name][0] != before[name][0] for name in before)


def test_an_input_a_fem_curve_is_not_made_from_keeps_the_curve(tmp_path, capsys):
    """The FEM curve is made from the design, material, contact and mesh: a new u_c table redraws
    the lifetimes and keeps the curve's files as they are."""
    (tmp_path / "uc.csv").write_text(Path(ILLUSTRATIVE_UC_CSV).read_text())
    (tmp_path / "scene.toml").write_text('[surface]\nuc_table = "uc.csv"\n[loads]\nF1_N = [10]\n'
                                         '[[outputs]]\nkind = "curve"\n[[outputs]]\nkind = "lifetimes"\n')
    out = tmp_path / "out"
    _run(tmp_path, capsys)
    before = _stamps(out)
    _double_the_gaps(tmp_path / "uc.csv")
    _run(tmp_path, capsys)
    after = _stamps(out)
    assert after["curve.csv"] == before["curve.csv"] and after["curve.json"] == before["curve.json"]
    assert after["lifetimes.csv"][0] != before["lifetimes.csv"][0]
    assert set(after) == set(before)
    made = {f["path"]: f["made_from"] for f in json.loads((out / "manifest.json").read_text())["files"]}
    assert "surface" not in made["curve.csv"] and "surface" in made["lifetimes.csv"]
