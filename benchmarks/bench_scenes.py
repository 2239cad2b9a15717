"""Cold and warm runs of the shipped scenes, start-up included (the `cupcheck run` process).

    python benchmarks/bench_scenes.py [--repeat 3]

Cold: an empty cache directory; warm: the same scene again with its cache. Prints the median of
`--repeat` runs of each, per scene and for the whole set.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def timed(args: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "validation.cli", "run", *args, "--quiet"], cwd=ROOT, check=True,
                   stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    scenes = sorted(p for p in (ROOT / "scenes").glob("*.toml") if not p.name.startswith("sweep_"))
    totals = {"cold": 0.0, "warm": 0.0}
    for scene in scenes:
        cold, warm = [], []
        for _ in range(args.repeat):
            with tempfile.TemporaryDirectory() as d:
                run = [str(scene), "--out", f"{d}/out", "--cache-dir", f"{d}/cache"]
                cold.append(timed(run))
                warm.append(timed(run))
        c, w = statistics.median(cold), statistics.median(warm)
        totals["cold"] += c
        totals["warm"] += w
        print(f"{scene.name:32s} cold {c:5.2f} s   warm {w:5.2f} s")
    print(f"{'all shipped scenes':32s} cold {totals['cold']:5.2f} s   warm {totals['warm']:5.2f} s")


if __name__ == "__main__":
    main()
