"""The shared guards refuse slips (tests/catalogue) but never a real cup: the presets, a thickness
table in mm, a curve used with the modulus it was computed at. One sweep per store at a time;
Ctrl-C at any moment is one line and exit 130; library warnings never reach the user."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest

from validation import guards
from validation.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _as_a_terminal_starts_it() -> None:
    """Ctrl-C at its default in the child, as an interactive shell starts a command: a test run
    started in the background (`pytest ... &` from a script) inherits SIGINT ignored, and Python
    keeps an ignored SIGINT ignored."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
CURVE = "u_mm,F0_N\n0,0\n1,2.5\n2,4\n4,5.5\n8,14\n"


@pytest.mark.parametrize("cup", ["A", "B"])
def test_table1_cups_pass(cup):
    from fem.geometry import cup_geometry

    guards.check_design(cup_geometry(cup).describe())


def test_a_design_file_in_mm_passes(tmp_path):
    path = tmp_path / "g.toml"
    path.write_text("r1_mm = 22\n[thickness]\nr_mm = [5, 12, 22]\nd_mm = [2.5, 1.2, 0.45]\n")
    design = guards.load_design(path, field="cup.geometry")
    assert design.geometry.describe()["r1_mm"] == pytest.approx(22.0)


@pytest.mark.parametrize("value,slip", [(4e6, "Pa"), (4e3, "kPa"), (0.004, "GPa")])
def test_modulus_slip_is_named(value, slip):
    with pytest.raises(guards.ImplausibleInput, match=f"material.E_MPa = .*did you give {slip}"):
        guards.check_modulus(value, "material.E_MPa")


def test_forces_at_the_edges():
    assert guards.check_forces([1e-6, 1e5], "loads.F1_N") == [1e-6, 1e5]
    with pytest.raises(guards.ImplausibleInput, match=r"loads.F1_N\[1\] = 2e\+05: did you give mN"):
        guards.check_forces([5, 2e5], "loads.F1_N")


def test_a_curve_at_its_own_modulus_runs(tmp_path, capsys):
    """The sidecar's E equal to --E-MPa (to round-off) is not refused; the curve's u within h1 passes."""
    (tmp_path / "c.csv").write_text(CURVE)
    (tmp_path / "c.json").write_text(json.dumps({"provenance": {"material": {"E_Pa": 4e6 * (1 + 1e-9)}}}))
    code = main(["lifetime", "--cup", "A", "--stiffness", str(tmp_path / "c.csv"), "--force", "1", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert json.loads(out)[0]["lifetime_s"] > 0


def test_one_sweep_per_store(tmp_path, capsys):
    """While one sweep holds a store, a second is refused at once (exit 2, one line) and computes
    nothing; once released, the store is free again."""
    from validation.sweeps.spec import lock_store

    sweep = tmp_path / "s.toml"
    sweep.write_text("[base]\nF1_N = [10]\n[[axes]]\nname = \"alpha_deg\"\nvalues = [30]\n")
    held = lock_store(tmp_path / "out")
    code = main(["sweep", str(sweep), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.splitlines()) == 1
    assert "is being computed by another cupcheck sweep" in err
    assert not (tmp_path / "out" / "designs").exists()
    held.release()
    lock_store(tmp_path / "out").release()


def test_library_warnings_do_not_reach_the_user(monkeypatch, capsys):
    import validation.commands.uc as uc

    def noisy(args):
        warnings.warn("divide by zero encountered in log", RuntimeWarning)
        warnings.warn("Persisting input arguments took 0.6s", UserWarning)
        return 0

    monkeypatch.setattr(uc, "run", noisy)
    assert main(["uc", "--surface", "pmma-1.89"]) == 0
    assert capsys.readouterr().err == ""


def test_ctrl_c_at_any_moment_is_one_line(tmp_path):
    """A real `cupcheck run` interrupted (SIGINT, as Ctrl-C) at several moments from the start of
    cupcheck's own code (its imports, the parser, the scene, the solve): one line, and exit status
    130; an interrupt that lands after the command has returned (in the interpreter's exit) leaves
    the finished run's status, 0. Python's own start-up
    before cupcheck's `main` (site.py, then importing validation.cli: a few ms) is not cupcheck's
    to quiet; everything after, imports of numpy, scipy and fem included, is."""
    (tmp_path / "s.toml").write_text('[stiffness]\nsource = "appendix-a"\n[[outputs]]\nkind = "lifetimes"\n'
                                     '[[outputs]]\nkind = "trajectories"\n')
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg"}
    start = ("import sys; import validation.cli as cli; print('ready', flush=True); "
             "sys.exit(cli.main())")
    codes = []
    for i, delay in enumerate((0.0, 0.1, 0.2, 0.25, 0.3, 0.35, 0.8, 1.5)):
        proc = subprocess.Popen([sys.executable, "-c", start, "run", str(tmp_path / "s.toml"),
                                 "--out", str(tmp_path / f"out{i}"), "--no-cache"], env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                preexec_fn=_as_a_terminal_starts_it)
        assert proc.stdout.readline() == "ready\n"
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=120)
        codes.append(proc.returncode)
        assert "Traceback" not in err
        done = (tmp_path / f"out{i}" / "manifest.json").is_file()
        if proc.returncode == 130:
            assert err.splitlines() in (["cupcheck run: interrupted"], ["cupcheck: interrupted"]), err
            assert not (tmp_path / f"out{i}").exists()
        else:                       # finished (the interrupt, if any, landed after the command returned)
            assert done and proc.returncode == 0 and err == "", err
    assert 0 not in codes[:2]


def test_ctrl_c_on_a_sweep_is_one_line(tmp_path):
    """Ctrl-C in a terminal reaches the whole process group: the sweep and its dask workers. The
    workers (validation.sweeps.worker, a dask preload) leave it to the sweep: one line, exit 130."""
    (tmp_path / "s.toml").write_text('[base]\nF1_N = [10]\n[[axes]]\nname = "alpha_deg"\nvalues = [30, 33, 36]\n')
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg"}
    proc = subprocess.Popen([sys.executable, "-m", "validation.cli", "sweep", str(tmp_path / "s.toml"), "--out",
                             str(tmp_path / "out"), "--workers", "1", "--quiet"], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_as_a_terminal_starts_it)
    deadline = time.monotonic() + 120
    while not (tmp_path / "out" / "designs").is_dir() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)                         # the sweep checked its file and took its store
    time.sleep(2.0)                              # the cluster up, the worker on its first design
    os.killpg(proc.pid, signal.SIGINT)           # as a terminal does: the whole group
    out, err = proc.communicate(timeout=120)
    lines = [ln for ln in err.splitlines() if not ln.startswith("sweep: ")]
    assert proc.returncode == 130 and lines == ["cupcheck sweep: interrupted"], err


def test_messages_carry_no_terminal_escapes(capsys, tmp_path):
    """A file name with a terminal escape in it is named, escaped, in the one-line error: the
    message never acts on the user's terminal."""
    from tests.cli import run_cli

    bad = tmp_path / "curve\x1b[31mred.csv"
    code, out, err = run_cli(capsys, "lifetime", "--stiffness", bad, "--force", "10")
    assert code == 2 and "\x1b" not in err and "\\x1b" in err and len(err.strip().splitlines()) == 1
