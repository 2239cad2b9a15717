"""Where users wait: whole-process times of the commands users run, and their ratio to a baseline.

    OMP_NUM_THREADS=1 python benchmarks/bench_speed.py [--repeat 5] [--with-suction]
    python benchmarks/bench_speed.py --tree ../old-checkout --write-baseline    # record a baseline

Every figure is a whole `cupcheck` process (start-up included), the median of --repeat runs:
`cupcheck --help`, a coarse and a medium frictionless stiffness curve of cup A, the main job cold
(--no-cache) and warm (its cache filled), one lifetime per route (paper and profile at 10 N; the
profile route's cost per force from 16 forces against one), and with --with-suction a coarse suction
table on the default grid and the coupled route's lifetime on it. Each is printed beside
benchmarks/speed_baseline.json (the same figures on an earlier main) as a ratio, new / baseline,
so a change's speed-up or slow-down is one number, and beside its target.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from datetime import date
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BASELINE = Path(__file__).with_name("speed_baseline.json")
FORCES = [str(f) for f in range(5, 85, 5)]
#: the targets [s] (lower is better): whole processes, except profile_per_force
TARGETS = {"help": 0.15, "curve_coarse": 0.35, "curve_medium": 0.7, "main_cold": 2.0,
           "lifetime_paper": 0.3, "profile_per_force": 0.03, "suction_coarse": 30.0}


class Runner:
    """Runs `cupcheck ARGS` as a whole process in one checkout (its sources first on the path)."""

    def __init__(self, tree: Path, work: Path):
        self.tree, self.work = tree, work
        self.env = {**os.environ, "PYTHONPATH": str(tree), "MPLBACKEND": "Agg"}

    def __call__(self, *args: str) -> float:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "validation.cli", *args], cwd=self.tree, env=self.env,
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        return time.perf_counter() - t0


def median(run: Callable[[], float], repeat: int, prepare: Callable[[], None] | None = None) -> float:
    times = []
    for _ in range(repeat):
        if prepare is not None:
            prepare()
        times.append(run())
    return statistics.median(times)


def figures(cli: Runner, repeat: int, with_suction: bool) -> dict[str, float]:
    w = cli.work
    out: dict[str, float] = {}
    out["help"] = median(lambda: cli("--help"), repeat)
    out["curve_coarse"] = median(lambda: cli("stiffness", "--cup", "A", "--fidelity", "coarse",
                                             "--out", str(w / "coarse.csv")), repeat)
    out["curve_medium"] = median(lambda: cli("stiffness", "--cup", "A", "--fidelity", "medium",
                                             "--out", str(w / "medium.csv")), repeat)
    main = ["run", "scenes/main.toml", "--quiet", "--out"]
    out["main_cold"] = median(lambda: cli(*main, str(w / "main_cold"), "--no-cache"), repeat)
    cli(*main, str(w / "main_warm"), "--cache-dir", str(w / "cache"))          # fill the cache
    out["main_warm"] = median(lambda: cli(*main, str(w / "main_warm"), "--cache-dir", str(w / "cache")), repeat)
    paper = ["lifetime", "--cup", "A", "--surface", "pmma-1.89", "--force"]
    out["lifetime_paper"] = median(lambda: cli(*paper, "10"), repeat)
    profile = ["lifetime", "--stiffness", str(w / "medium.csv"), "--route", "profile", "--surface",
               "pmma-1.89", "--force"]
    one = median(lambda: cli(*profile, "10"), repeat)
    many = median(lambda: cli(*profile, *FORCES), repeat)
    out["lifetime_profile"] = one
    out["profile_per_force"] = (many - one) / (len(FORCES) - 1)
    if with_suction:
        table = str(w / "suction.json")
        out["suction_coarse"] = median(lambda: cli("suction", "--cup", "A", "--fidelity", "coarse",
                                                   "--out", table), 1)
        out["lifetime_coupled"] = median(lambda: cli("lifetime", "--route", "coupled", "--suction-table",
                                                     table, "--surface", "pmma-1.89", "--force", "10"), repeat)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per figure (median; default 5)")
    ap.add_argument("--tree", type=Path, default=ROOT, help="the checkout to time (default: this one)")
    ap.add_argument("--with-suction", action="store_true", help="also the coarse suction table (minutes)")
    ap.add_argument("--write-baseline", action="store_true", help=f"store the figures as {BASELINE.name}")
    args = ap.parse_args()
    tree = args.tree.resolve()
    with tempfile.TemporaryDirectory() as d:
        got = figures(Runner(tree, Path(d)), args.repeat, args.with_suction)
    base = json.loads(BASELINE.read_text())["seconds"] if BASELINE.is_file() else {}
    print(f"{'figure':20s} {'time (s)':>9s} {'baseline':>9s} {'ratio':>6s} {'target':>7s}")
    for name, t in got.items():
        b = base.get(name)
        ratio = f"{t / b:6.2f}" if b else f"{'-':>6s}"
        target = TARGETS.get(name)
        mark = "" if target is None else ("  met" if t <= target else "  not met")
        print(f"{name:20s} {t:9.3f} {b if b else float('nan'):9.3f} {ratio} "
              f"{target if target else float('nan'):7.2f}{mark}")
    if args.write_baseline:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=tree, capture_output=True,
                                text=True).stdout.strip()
        BASELINE.write_text(json.dumps({"commit": commit, "date": date.today().isoformat(),
                                        "repeat": args.repeat, "seconds": got}, indent=1) + "\n")
        print(f"wrote {BASELINE}")


if __name__ == "__main__":
    main()
