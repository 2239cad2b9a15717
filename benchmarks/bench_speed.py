"""Where users wait: whole-process times of the commands users run, and their ratio to a baseline.

    OMP_NUM_THREADS=1 python benchmarks/bench_speed.py [--repeat 5] [--with-suction] [--against ../pristine]
    OMP_NUM_THREADS=1 python benchmarks/bench_speed.py --only help lifetime_paper curve_coarse
    python benchmarks/bench_speed.py --tree ../old-checkout --write-baseline    # record a baseline

Every figure is a whole `cupcheck` process (start-up included), the median of --repeat runs:
`cupcheck --help`, a coarse and a medium frictionless stiffness curve of cup A, the main job cold
(--no-cache) and warm (its cache filled, the same output directory), one lifetime per route (paper
and profile at 10 N; the profile route's cost per further force from 16 forces against one, each
a `cupcheck lifetime` call in one process after a warm-up call, so that start-up's noise, ~0.1 s
a process on a loaded machine and 7 ms once divided by 15, stays out of it), and with
--with-suction a coarse suction table on the default grid and the coupled route's lifetime on it.
Each is printed beside benchmarks/speed_baseline.json (the same figures on an earlier main) as a
ratio, new / baseline, so a change's speed-up or slow-down is one number, and beside its target.
The CPU time (user + system) of each process is printed too: on a machine shared with other work
it moves much less than the wall time. --against times another checkout in the same run, each of
its runs next to this tree's, so that the ratio to it holds on a loaded machine too. --only
times the named figures alone (what they need, e.g. the medium curve of the profile route, is still
made, untimed). --pyc lets the processes cache their compiled bytecode (in a temporary
PYTHONPYCACHEPREFIX, as an installed package does) where the environment sets
PYTHONDONTWRITEBYTECODE: else every run compiles the project's sources anew (~0.05 s of a command).
--main-parts prints instead where the cold main job's time goes, run by run: the whole process's
wall time, the CPU of the main process and of the drawing process beside it (the figures,
validation.scenes.drawing), and the products' wall times from the manifest (FEM path, curve, u_c
table, lifetimes); --against gives the same for another checkout, run for run.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from datetime import date
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BASELINE = Path(__file__).with_name("speed_baseline.json")
FORCES = [str(f) for f in range(5, 85, 5)]
#: the targets [s] (lower is better): whole processes, except profile_per_force (in one process)
TARGETS = {"help": 0.15, "curve_coarse": 0.35, "curve_medium": 0.7, "main_cold": 2.0,
           "lifetime_paper": 0.3, "profile_per_force": 0.03, "suction_coarse": 30.0}


class Runner:
    """Runs `cupcheck ARGS` as a whole process in one checkout (its sources first on the path)."""

    def __init__(self, tree: Path, work: Path, pyc: bool = False):
        self.tree, self.work = tree, work
        self.env = {**os.environ, "PYTHONPATH": str(tree), "MPLBACKEND": "Agg"}
        if pyc:
            self.env.pop("PYTHONDONTWRITEBYTECODE", None)
            self.env["PYTHONPYCACHEPREFIX"] = str(work / "pyc")

    def __call__(self, *args: str) -> tuple[float, float]:
        """(wall time, CPU time: user + system) of one run [s]."""
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "validation.cli", *args], cwd=self.tree, env=self.env,
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)

    def calls(self, *argvs: list[str]) -> list[tuple[float, float]]:
        """(wall, CPU) [s] of each `cupcheck ARGV` called in turn in one process (start-up excluded)."""
        done = subprocess.run([sys.executable, "-c", IN_PROCESS, json.dumps(argvs)], cwd=self.tree,
                              env=self.env, check=True, capture_output=True, text=True)
        return [tuple(t) for t in json.loads(done.stdout.strip().splitlines()[-1])]


#: runs the argument lists of argv[1] (JSON) through `validation.cli.main`, prints their (wall, CPU)
IN_PROCESS = """import contextlib, io, json, sys, time
from validation.cli import main
times = []
for argv in json.loads(sys.argv[1]):
    w, c = time.perf_counter(), time.process_time()
    with contextlib.redirect_stdout(io.StringIO()):
        try:
            status = main(argv)
        except SystemExit as exc:
            status = exc.code
    if status not in (0, None):
        raise SystemExit(f"cupcheck {' '.join(argv)}: exit status {status}")
    times.append((time.perf_counter() - w, time.process_time() - c))
print(json.dumps(times))
"""


#: the cold main job in one process: its wall time, the CPU of this process and of its children (the
#: drawing process) and the manifest's product timings, as JSON on the last line
MAIN_PARTS = """import json, resource, sys, time
w = time.perf_counter()
from validation.cli import main
status = main(["run", "scenes/main.toml", "--quiet", "--no-cache", "--out", sys.argv[1]])
wall = time.perf_counter() - w
me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
timings = json.load(open(sys.argv[1] + "/manifest.json"))["timings_s"]
print(json.dumps({"wall": wall, "main_cpu": me.ru_utime + me.ru_stime, "drawing_cpu": kids.ru_utime + kids.ru_stime,
                  **{k.split("_")[0] if k.startswith("fem_path") else k: v for k, v in timings.items()}}))
"""


def main_parts(cli: Runner) -> dict[str, float]:
    """`MAIN_PARTS`' figures of one cold main job [s]."""
    out = cli.work / f"parts_{time.monotonic_ns()}"
    done = subprocess.run([sys.executable, "-c", MAIN_PARTS, str(out)], cwd=cli.tree, env=cli.env, check=True,
                          capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def print_main_parts(tree: Path, against: Path | None, repeat: int, pyc: bool) -> None:
    """The cold main job's parts (`MAIN_PARTS`), of `tree` and `against`, their runs interleaved."""
    with tempfile.TemporaryDirectory() as d, tempfile.TemporaryDirectory() as e:
        cli = Runner(tree, Path(d), pyc)
        other = Runner(against, Path(e), pyc) if against is not None else None
        got, base = [], []
        for _ in range(repeat):
            got.append(main_parts(cli))
            if other is not None:
                base.append(main_parts(other))
    print(f"{'main job, cold (s)':24s} {'this':>8s}" + (f" {'against':>8s} {'ratio':>6s}" if base else ""))
    for key in got[0]:
        t = statistics.median(r.get(key, 0.0) for r in got)
        line = f"{key:24s} {t:8.3f}"
        if base:
            b = statistics.median(r.get(key, 0.0) for r in base)
            line += f" {b:8.3f} {_cell(t / b if b > 0 else None, 6, 2)}"
        print(line, flush=True)


def median(run: Callable[[], tuple[float, float]], repeat: int,
           prepare: Callable[[], None] | None = None) -> tuple[float, float]:
    """The medians of the wall and CPU times of `repeat` runs."""
    times = []
    for _ in range(repeat):
        if prepare is not None:
            prepare()
        times.append(run())
    return statistics.median(t[0] for t in times), statistics.median(t[1] for t in times)


#: the figures in the order they are timed
NAMES = ("help", "curve_coarse", "curve_medium", "main_cold", "main_warm", "lifetime_paper",
         "lifetime_profile", "profile_per_force", "suction_coarse", "lifetime_coupled")


def figures(cli: Runner, repeat: int, with_suction: bool,
            only: frozenset[str] = frozenset(NAMES)) -> Iterator[tuple[str, tuple[float, float]]]:
    """(name, (wall, CPU) [s]) of each figure in `only`, in turn."""
    w = cli.work
    if "help" in only:
        yield "help", median(lambda: cli("--help"), repeat)
    if "curve_coarse" in only:
        yield "curve_coarse", median(lambda: cli("stiffness", "--cup", "A", "--fidelity", "coarse",
                                                 "--out", str(w / "coarse.csv")), repeat)
    medium = lambda: cli("stiffness", "--cup", "A", "--fidelity", "medium", "--out", str(w / "medium.csv"))  # noqa: E731
    if "curve_medium" in only:
        yield "curve_medium", median(medium, repeat)
    main = ["run", "scenes/main.toml", "--quiet", "--out"]
    if "main_cold" in only:
        yield "main_cold", median(lambda: cli(*main, str(w / "main_cold"), "--no-cache"), repeat)
    if "main_warm" in only:
        cli(*main, str(w / "main_warm"), "--cache-dir", str(w / "cache"))          # fill the cache
        yield "main_warm", median(lambda: cli(*main, str(w / "main_warm"), "--cache-dir", str(w / "cache")),
                                  repeat)
    paper = ["lifetime", "--cup", "A", "--surface", "pmma-1.89", "--force"]
    if "lifetime_paper" in only:
        yield "lifetime_paper", median(lambda: cli(*paper, "10"), repeat)
    profile = ["lifetime", "--stiffness", str(w / "medium.csv"), "--route", "profile", "--surface",
               "pmma-1.89", "--force"]
    if only & {"lifetime_profile", "profile_per_force"}:
        if "curve_medium" not in only:
            medium()                                                                # its input, untimed
        one = median(lambda: cli(*profile, "10"), repeat)
        if "lifetime_profile" in only:
            yield "lifetime_profile", one
        if "profile_per_force" in only:
            pairs = cli.calls(profile + ["10"], *[[*profile, *f] for _ in range(repeat) for f in (["10"], FORCES)])
            extra = [tuple((m - o) / (len(FORCES) - 1) for m, o in zip(pairs[k + 1], pairs[k]))
                     for k in range(1, len(pairs), 2)]
            yield "profile_per_force", (statistics.median(e[0] for e in extra),
                                        statistics.median(e[1] for e in extra))
    if with_suction:
        table = str(w / "suction.json")
        yield "suction_coarse", median(lambda: cli("suction", "--cup", "A", "--fidelity", "coarse",
                                                   "--out", table), 1)
        yield "lifetime_coupled", median(lambda: cli("lifetime", "--route", "coupled", "--suction-table",
                                                     table, "--surface", "pmma-1.89", "--force", "10"), repeat)


def _cell(value: float | None, width: int, digits: int = 3) -> str:
    return f"{value:{width}.{digits}f}" if value is not None else f"{'-':>{width}s}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per figure (median; default 5)")
    ap.add_argument("--tree", type=Path, default=ROOT, help="the checkout to time (default: this one)")
    ap.add_argument("--against", type=Path, default=None,
                    help="another checkout timed in the same run, figure by figure (its ratio: tree / against)")
    ap.add_argument("--with-suction", action="store_true", help="also the coarse suction table (minutes)")
    ap.add_argument("--pyc", action="store_true",
                    help="cache compiled bytecode between runs (a temporary PYTHONPYCACHEPREFIX)")
    ap.add_argument("--only", nargs="+", choices=NAMES, default=None, metavar="FIGURE",
                    help=f"time only these figures ({', '.join(NAMES)})")
    ap.add_argument("--write-baseline", action="store_true", help=f"store the figures as {BASELINE.name}")
    ap.add_argument("--main-parts", action="store_true",
                    help="where the cold main job's time goes (the main and drawing processes' CPU, the products)")
    args = ap.parse_args()
    if args.main_parts:
        print_main_parts(args.tree.resolve(), args.against.resolve() if args.against else None, args.repeat, args.pyc)
        return
    if args.only is not None and args.write_baseline:
        ap.error("--write-baseline: records every figure; drop --only")
    only = frozenset(args.only or NAMES)
    tree = args.tree.resolve()
    base = json.loads(BASELINE.read_text())["seconds"] if BASELINE.is_file() else {}
    got: dict[str, float] = {}
    head = f"{'figure':18s} {'time (s)':>9s} {'cpu (s)':>8s} {'baseline':>9s} {'ratio':>6s}"
    if args.against is not None:
        head += f" {'against':>8s} {'cpu':>7s} {'ratio':>6s} {'cpu':>6s}"
    print(head + f" {'target':>7s}", flush=True)
    with tempfile.TemporaryDirectory() as d, tempfile.TemporaryDirectory() as e:
        other = figures(Runner(args.against.resolve(), Path(e), args.pyc), args.repeat, args.with_suction, only) \
            if args.against is not None else None
        for name, (t, cpu) in figures(Runner(tree, Path(d), args.pyc), args.repeat, args.with_suction, only):
            got[name] = t
            b = base.get(name)
            line = (f"{name:18s} {t:9.3f} {cpu:8.3f} {_cell(b, 9)} "
                    f"{_cell(t / b if b else None, 6, 2)}")
            if other is not None:
                _, (ta, ca) = next(other)
                line += (f" {ta:8.3f} {ca:7.3f} {_cell(t / ta if ta > 0 else None, 6, 2)}"
                         f" {_cell(cpu / ca if ca > 0 else None, 6, 2)}")
            target = TARGETS.get(name)
            mark = "" if target is None else ("  met" if t <= target else "  not met")
            print(f"{line} {_cell(target, 7, 2)}{mark}", flush=True)
    if args.write_baseline:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=tree, capture_output=True,
                                text=True).stdout.strip()
        BASELINE.write_text(json.dumps({"commit": commit, "date": date.today().isoformat(),
                                        "repeat": args.repeat, "seconds": got}, indent=1) + "\n")
        print(f"wrote {BASELINE}")

if __name__ == "__main__":
    main()
