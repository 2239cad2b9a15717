"""Cold and warm runs of the shipped scenes, start-up included (the `cupcheck run` process).

    python benchmarks/bench_scenes.py [--repeat 3] [--tree ../other-checkout]

Cold: an empty cache directory and output directory; warm: the same scene again into the same
output directory with its cache. Prints the median wall and CPU (user + system) time of `--repeat`
runs of each, per scene and for the whole set, and warm / cold (the target: all shipped scenes
warm <= 0.5 of cold). The CPU times move much less than the wall times on a shared machine.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: all shipped scenes warm / cold
TARGET = 0.5


def timed(tree: Path, args: list[str]) -> tuple[float, float]:
    """(wall, CPU) [s] of one `cupcheck run` process in checkout `tree`."""
    env = {**os.environ, "PYTHONPATH": str(tree), "MPLBACKEND": "Agg"}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "validation.cli", "run", *args, "--quiet"], cwd=tree, env=env,
                   check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tree", type=Path, default=ROOT, help="the checkout to time (default: this one)")
    args = ap.parse_args()
    tree = args.tree.resolve()
    scenes = sorted(p for p in (tree / "scenes").glob("*.toml") if not p.name.startswith("sweep_"))
    totals = {"cold": [0.0, 0.0], "warm": [0.0, 0.0]}
    print(f"{'scene':32s} {'cold (s)':>9s} {'cpu':>6s} {'warm (s)':>9s} {'cpu':>6s} {'warm/cold':>9s}", flush=True)
    for scene in scenes:
        cold, warm = [], []
        for _ in range(args.repeat):
            with tempfile.TemporaryDirectory() as d:
                run = [str(scene), "--out", f"{d}/out", "--cache-dir", f"{d}/cache"]
                cold.append(timed(tree, run))
                warm.append(timed(tree, run))
        c = [statistics.median(t[i] for t in cold) for i in (0, 1)]
        w = [statistics.median(t[i] for t in warm) for i in (0, 1)]
        for i in (0, 1):
            totals["cold"][i] += c[i]
            totals["warm"][i] += w[i]
        print(f"{scene.name:32s} {c[0]:9.2f} {c[1]:6.2f} {w[0]:9.2f} {w[1]:6.2f} {w[0] / c[0]:9.2f}", flush=True)
    (c, cc), (w, wc) = totals["cold"], totals["warm"]
    print(f"{'all shipped scenes':32s} {c:9.2f} {cc:6.2f} {w:9.2f} {wc:6.2f} {w / c:9.2f}  "
          f"(cpu {wc / cc:.2f}; target {TARGET}: {'met' if w / c <= TARGET else 'not met'})")


if __name__ == "__main__":
    main()
