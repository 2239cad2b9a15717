"""Design sweeps (issue 15): the sweep file, sampling, a real dask LocalCluster, failure isolation,
resume after SIGKILL, a worker that dies, and the tidy table."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from validation.cli import main
from validation.sweeps.execute import run_sweep
from validation.sweeps.spec import design_hash, sweep_from_mapping

ROOT = Path(__file__).resolve().parents[1]


# ------------------------------------------------------------------------------ the sweep file
@pytest.mark.parametrize("data,message", [
    ({"bsae": {}}, "bsae: unknown key; allowed: scene, base, sampling, axes"),
    ({"base": {"E_Mpa": 4}}, "base.E_Mpa: unknown key"),
    ({"base": {"contact": "glued"}}, "base.contact: expected one of frictionless, sticking, coulomb, got 'glued'"),
    ({"base": {"contact": "coulomb"}}, 'base.friction: base.contact = "coulomb" needs base.friction'),
    ({"base": {"contact": "sticking", "friction": 0.3}}, "base.friction: applies to base.contact = \"coulomb\" only"),
    ({"base": {"contact": "coulomb", "friction": -1}}, "base.friction: Coulomb's friction coefficient must be in [0, 100]"),
    ({"base": {"contact": "sticking"}, "axes": [{"name": "friction", "values": [0.1, 0.5]}]},
     'axes[0].name: a friction axis varies Coulomb\'s mu: it needs base.contact = "coulomb"'),
    ({"base": {"contact": "coulomb", "friction": 0.2}, "axes": [{"name": "friction", "values": [0.1, -0.5]}]},
     "axes[0]: Coulomb's friction coefficient must be in [0, 100], got -0.5"),
    ({"axes": [{"name": "contact", "values": ["sticking", "coulomb"]}]}, "base.friction: base.contact = \"coulomb\" needs"),
    ({"axes": [{"name": "alpha_deg", "values": [30]}, {"name": "angle", "values": [1]}]},
     "axes[1].name: expected one of alpha_deg"),
    ({"sampling": {"method": "lhs", "n": 4}, "axes": [{"name": "alpha_deg", "values": [30, 40]}]},
     "axes[0].values: lhs sampling takes low and high, not values"),
    ({"sampling": {"method": "sobol", "n": 0}, "axes": [{"name": "nu", "low": 0.3, "high": 0.49}]},
     "sampling.n: sobol needs a number of designs in [1, 100000], got 0"),
    ({"axes": [{"name": "alpha_deg", "values": [30, "steep"]}]}, "axes[0].values[1]: expected a finite number"),
    ({"sampling": {"method": "lhs", "n": 4}, "axes": [{"name": "E_MPa", "low": 5, "high": 2}]},
     "axes[0].high: must exceed low = 5, got 2"),
])
def test_bad_sweep_files_are_refused_with_the_key_path(data, message):
    with pytest.raises(ValueError, match=None) as exc:
        sweep_from_mapping(data)
    assert message in str(exc.value) and "\n" not in str(exc.value)


def test_a_friction_axis_sweeps_coulombs_mu_between_the_limits():
    """Coulomb designs evaluate with their own mu: the small-u stiffness rises with mu, from the
    frictionless design's (mu = 0; the two paths take different load steps and F0(1 mm) is
    interpolated between them, ~3e-4 apart, while their end states agree to 2e-5,
    tests/test_fem_friction.py) towards the sticking one's."""
    from validation.sweeps.evaluate import evaluate_design

    def stiffness(contact, **extra):
        spec = sweep_from_mapping({"base": {"contact": contact, "F1_N": [10], **extra}})
        return evaluate_design(spec.designs()[0])[0]["small_u_stiffness_N_per_mm"]

    spec = sweep_from_mapping({"base": {"contact": "coulomb", "friction": 0.0, "F1_N": [10]},
                               "axes": [{"name": "friction", "values": [0.0, 1.0]}]})
    k0, k1 = (evaluate_design(d)[0]["small_u_stiffness_N_per_mm"] for d in spec.designs())
    free, stuck = stiffness("frictionless"), stiffness("sticking")
    assert k0 == pytest.approx(free, rel=1e-3)
    assert free < k1 < stuck


def test_bad_sweep_file_exits_2_and_writes_nothing(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text('[base]\nfidelity = "ultra"\n')
    assert main(["sweep", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "base.fidelity: expected one of coarse, medium, fine" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("method", ["lhs", "sobol"])
def test_samples_fill_their_bounds(method):
    spec = sweep_from_mapping({"sampling": {"method": method, "n": 16, "seed": 3},
                               "axes": [{"name": "alpha_deg", "low": 20, "high": 45},
                                        {"name": "d0_mm", "low": 1.0, "high": 3.0}]})
    designs = spec.designs()
    a = np.array([d["alpha_deg"] for d in designs])
    d0 = np.array([d["d0_mm"] for d in designs])
    assert len(designs) == 16 and len({design_hash(d) for d in designs}) == 16
    assert a.min() >= 20 and a.max() <= 45 and d0.min() >= 1 and d0.max() <= 3
    # one sample per sixteenth of each axis: Latin hypercube by construction, Sobol (2^4 points) too
    for x, lo, hi in ((a, 20, 45), (d0, 1, 3)):
        assert sorted(np.floor(16 * (x - lo) / (hi - lo)).astype(int)) == list(range(16))
    assert spec.designs() == designs                       # the seed makes it reproducible


def test_grid_is_every_combination():
    spec = sweep_from_mapping({"axes": [{"name": "alpha_deg", "values": [25, 33, 40]},
                                        {"name": "contact", "values": ["sticking", "frictionless"]}]})
    pairs = [(d["alpha_deg"], d["contact"]) for d in spec.designs()]
    assert len(pairs) == 6 and len(set(pairs)) == 6


# ------------------------------------------------------------------------------ on a real cluster
def test_local_cluster_sweep_end_to_end(tmp_path):
    """Three coarse designs on a 2-worker LocalCluster, one of them invalid (a tube, refused by the
    plausibility guard): two evaluated, one a row with its reason; the table is tidy."""
    spec = sweep_from_mapping({"base": {"F1_N": [10, 40], "F0_at_u_mm": [1]},
                               "axes": [{"name": "alpha_deg", "values": [33, 40, 85]}]})
    result = run_sweep(spec, tmp_path, workers=2)
    assert (result.designs, result.computed, result.reused, result.failed) == (3, 3, 0, 1)
    frame = pd.read_csv(tmp_path / "results.csv")
    arrow = pq.read_table(tmp_path / "results.parquet").to_pandas()
    assert len(frame) == len(arrow) == 6 and list(frame.columns) == list(arrow.columns)
    assert frame.groupby("design_hash").size().tolist() == [2, 2, 2]
    bad = frame[frame["alpha_deg"] == 85]
    assert bad["failure"].str.startswith("geometry: ImplausibleInput: design: alpha_deg = 85").all()
    good = frame[frame["alpha_deg"] != 85]
    assert good["failure"].isna().all() and (good["lifetime_s"] > 0).all()
    # the FEM quantity is the one a single stiffness run gives: F0(1 mm) = the secant stiffness
    assert np.allclose(good["F0_at_1mm_N"], good["small_u_stiffness_N_per_mm"])
    # a second run computes nothing
    again = run_sweep(spec, tmp_path, workers=1)
    assert (again.computed, again.reused) == (0, 3)


def _worker_killer(marker_dir: str, always: bool):
    """A unit of work that kills its worker process (the first time, or always)."""
    def evaluate(design):
        marker = Path(marker_dir) / design_hash(design)
        if always or not marker.exists():
            marker.touch()
            os._exit(1)
        return [{"design_hash": design_hash(design), "F1_N": F, "lifetime_s": 1.0, "failure": None}
                for F in design["F1_N"]]
    return evaluate


@pytest.mark.parametrize("always", [False, True])
def test_a_dead_worker_is_replaced_and_its_design_retried_once(tmp_path, always):
    import cloudpickle
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    spec = sweep_from_mapping({"axes": [{"name": "alpha_deg", "values": [30]}]})
    result = run_sweep(spec, tmp_path / "out", workers=1, evaluate=_worker_killer(str(tmp_path), always))
    rows = json.loads(next((tmp_path / "out" / "designs").glob("*.json")).read_text())
    if always:       # died on the first try and on the retry: the design's failure, not the sweep's
        assert result.failed == 1 and rows[0]["failure"].startswith("worker: KilledWorker")
    else:
        assert result.failed == 0 and rows[0]["failure"] is None and rows[0]["lifetime_s"] == 1.0


def test_a_killed_sweep_resumes_without_losing_or_repeating_a_design(tmp_path):
    """SIGKILL the whole sweep (client, scheduler and workers) once two designs are committed; the
    rerun computes exactly the missing ones, and the table has every design once."""
    sweep = tmp_path / "s.toml"
    sweep.write_text('[base]\nF1_N = [10]\n[[axes]]\nname = "alpha_deg"\nvalues = [26, 28, 30, 32, 34, 36]\n')
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "validation.cli", "sweep", str(sweep), "--out", str(out), "--workers", "1",
           "--quiet"]
    proc = subprocess.Popen(cmd, cwd=ROOT, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(list((out / "designs").glob("*.json"))) < 2:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    committed = {p.stem for p in (out / "designs").glob("*.json")}
    assert 2 <= len(committed) < 6 and not list((out / "designs").glob(".*.tmp"))
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert f"6 designs ({6 - len(committed)} computed, {len(committed)} reused, 0 failed)" in done.stdout
    frame = pd.read_csv(out / "results.csv")
    assert len(frame) == 6 and frame["design_hash"].is_unique
    assert committed <= set(frame["design_hash"])


def test_the_shipped_sweep_runs(tmp_path, capsys):
    """scenes/sweep_alpha_thickness.toml as the README shows it: six coarse designs, maps, Pareto."""
    assert main(["sweep", str(ROOT / "scenes" / "sweep_alpha_thickness.toml"), "--out", str(tmp_path),
                 "--workers", "2", "--quiet"]) == 0
    assert "6 designs (6 computed, 0 reused, 0 failed)" in capsys.readouterr().out
    frame = pd.read_csv(tmp_path / "results.csv")
    assert len(frame) == 12 and frame["failure"].isna().all()
    for png in ("map_lifetime_s.png", "map_small_u_stiffness_N_per_mm.png", "map_appendix_a_ratio.png",
                "pareto_lifetime_volume.png"):
        assert (tmp_path / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # a thicker root wall costs material: the volume column orders the designs as their d0
    thick = frame.groupby("d0_mm")["volume_mm3"].mean()
    assert thick[2.5] > thick[1.5]


def test_pareto_front_is_the_non_dominated_set():
    from validation.sweeps.figures import pareto_front

    life = np.array([10.0, 20.0, 15.0, 30.0, 5.0])
    vol = np.array([1.0, 2.0, 3.0, 4.0, 0.5])
    # (15, 3) is dominated by (20, 2); the rest trade lifetime for volume
    assert pareto_front(life, vol).tolist() == [4, 0, 1, 3]


def test_a_sweep_takes_its_base_from_a_scene_file(tmp_path):
    """One mechanism: a scene file (as `cupcheck run` reads it) is the sweep's base; [base] overrides."""
    (tmp_path / "base.toml").write_text('[cup]\npreset = "B"\n[contact]\nlaw = "sticking"\n'
                                        '[loads]\nF1_N = [20]\n[[outputs]]\nkind = "lifetimes"\n')
    spec = sweep_from_mapping({"scene": "base.toml", "base": {"fidelity": "medium"},
                               "axes": [{"name": "alpha_deg", "values": [20, 25]}]}, root=tmp_path)
    d = spec.designs()
    assert [x["alpha_deg"] for x in d] == [20, 25]
    assert {(x["cup"], x["contact"], x["fidelity"], tuple(x["F1_N"])) for x in d} == {("B", "sticking", "medium", (20.0,))}
    with pytest.raises(ValueError, match="scene: no such file"):
        sweep_from_mapping({"scene": "missing.toml"}, root=tmp_path)
