"""Faults (issue 16): a run killed while it writes leaves the previous complete output or nothing,
never a partial file; real processes, SIGKILL and SIGTERM at many moments."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]


def _complete_or_absent(out: Path) -> str:
    """'absent' or 'complete' (the curve and its sidecar both there and consistent); anything else fails."""
    csv, side = out, out.with_suffix(".json")
    if not csv.exists() and not side.exists():
        return "absent"
    frame = pd.read_csv(csv)
    steps = json.loads(side.read_text())["steps"]
    assert len(frame) == len(steps["u_mm"]) > 2 and frame["u_mm"].iloc[-1] == pytest.approx(steps["u_mm"][-1])
    return "complete"


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_a_killed_stiffness_run_leaves_no_partial_file(tmp_path, sig):
    out = tmp_path / "curve.csv"
    cmd = [sys.executable, "-m", "validation.cli", "stiffness", "--fidelity", "coarse", "--out", str(out)]
    seen = set()
    for delay in (0.5, 1.2, 2.0, 3.5):
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(delay)
        proc.send_signal(sig)
        proc.wait()
        seen.add(_complete_or_absent(out))
        # a kill inside a write can leave a hidden temporary (".curve.csv.<pid>...tmp"), never a
        # half-written curve.csv or curve.json
        assert all(p.name.startswith(".") or p.name in ("curve.csv", "curve.json") for p in tmp_path.iterdir())
    # an earlier complete output survives a later killed run: once complete, it stays complete
    if "complete" in seen:
        assert _complete_or_absent(out) == "complete"


def test_two_runs_into_the_same_output_do_not_interleave(tmp_path, capsys):
    """While one run holds an output, a second run into it is refused at once, and writes nothing."""
    from filelock import FileLock

    from validation.cli import main

    out = tmp_path / "run"
    with FileLock(str(tmp_path / ".run.lock")):          # the first run, still writing
        assert main(["lifetime", "--force", "10", "--out", str(out)]) == 2
    assert "out: '" in capsys.readouterr().err and not out.exists()
    assert main(["lifetime", "--force", "10", "--out", str(out)]) == 0       # free again
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]             # no lock file left


def test_a_full_disk_is_a_clear_error_and_leaves_nothing(tmp_path):
    """A file-size limit (RLIMIT_FSIZE, as a full disk would) while writing the trajectories: one
    line, exit 1, and the output directory is not there."""
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (2000, 2000))

    out = tmp_path / "run"
    done = subprocess.run([sys.executable, "-m", "validation.cli", "lifetime", "--force", "10", "--relaxation",
                           "default", "--out", str(out)], cwd=ROOT, capture_output=True, text=True,
                          preexec_fn=limit, timeout=120)
    assert done.returncode == 1, done.stderr
    assert done.stderr.strip().splitlines()[-1].startswith("cupcheck lifetime: failed: cannot write the output: "
                                                            "File too large")
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.name != ".run.lock"]


def test_the_finite_guard_names_the_column_and_the_stage(tmp_path):
    from validation.output import write_table

    with pytest.raises(RuntimeError, match="lifetime: column r_mm has 1 non-finite value"):
        write_table(tmp_path / "t.csv", {"t_s": [0.0, 1.0], "r_mm": [12.0, float("nan")]}, stage="lifetime")
    write_table(tmp_path / "t.csv", {"lifetime_s": [float("inf"), 3.0]})      # an infinite lifetime means sealed
    assert (tmp_path / "t.csv").read_text().splitlines()[1] == "inf"


def _manifest_complete(out: Path) -> bool:
    """The directory holds exactly what its manifest lists (and the manifest)."""
    listed = {f["path"] for f in json.loads((out / "manifest.json").read_text())["files"]}
    return {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()} == listed | {"manifest.json"}


def test_a_killed_directory_run_is_cleaned_up_by_the_next(tmp_path):
    """SIGKILL a lifetime run at several moments (a real process): the output is the previous
    complete one or absent, never a mix; the next run removes the killed run's temporaries and
    leaves only what its manifest lists."""
    out = tmp_path / "run"
    forces = [str(f) for f in range(5, 85, 5)]
    cmd = [sys.executable, "-m", "validation.cli", "lifetime", "--relaxation", "default", "--force", *forces,
           "--out", str(out)]
    leftovers = 0
    for extra in (0.0, 0.05, 0.3, 1.0):
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        while proc.poll() is None and not list(tmp_path.glob(".run.*.tmp")):   # the run is writing
            time.sleep(0.005)
        time.sleep(extra)
        proc.kill()
        proc.wait()
        assert not out.exists() or _manifest_complete(out)
        leftovers += len(list(tmp_path.glob(".run.*.tmp")))
    assert leftovers > 0                       # some kill did land while the run was writing
    done = subprocess.run(cmd[:-1] + [str(out)], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert _manifest_complete(out) and sorted(p.name for p in tmp_path.iterdir()) == ["run"]
    assert len([p for p in out.iterdir() if p.name.startswith("trajectory_")]) == len(forces)


def test_a_second_run_through_a_symlink_is_refused_while_the_first_writes(tmp_path):
    """Two real processes: while the first writes 'real', a second naming it through a symlink is
    refused at once (the lock is on the resolved path) and the first completes."""
    real, alias = tmp_path / "real", tmp_path / "alias"
    alias.symlink_to(real)
    forces = [f"{f / 2:g}" for f in range(10, 161)]          # 151 relaxed lifetimes: several seconds
    first = subprocess.Popen([sys.executable, "-m", "validation.cli", "lifetime", "--relaxation", "default", "--force",
                              *forces, "--out", str(real)], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             text=True)
    while first.poll() is None and not list(tmp_path.glob(".real.*.tmp")):       # the first is writing
        time.sleep(0.005)
    second = subprocess.run([sys.executable, "-m", "validation.cli", "lifetime", "--json", "--force", "10", "--out",
                             str(alias)], cwd=ROOT, capture_output=True, text=True, timeout=120)
    _, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    if second.returncode == 0:                 # the first had already finished: nothing to race
        pytest.skip("the first run ended before the second started")
    assert second.returncode == 2 and "is being written by another cupcheck run" in second.stderr
    assert len(second.stderr.splitlines()) == 1 and _manifest_complete(real)
    assert len([p for p in real.iterdir() if p.name.startswith("trajectory_")]) == len(forces)
