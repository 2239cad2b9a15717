"""Sweep throughput on dask.distributed: 32 coarse designs with 2 workers against 1.

    python benchmarks/bench_sweep.py [--designs 32]

Prints the wall time of each run, the speed-up (target >= 1.8 on 2 cores), designs per minute,
and the scheduling overhead per design: (wall time of the 1-worker run - the cluster's start-up -
the sum of the designs' own wall times) / designs, against one coarse design's time (target < 5 %).
Each run starts from an empty output directory (nothing reused), its cluster start-up included in
the wall times and the speed-up.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

from validation.sweeps.execute import run_sweep
from validation.sweeps.spec import sweep_from_mapping


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=32)
    args = ap.parse_args()
    spec = sweep_from_mapping({"base": {"contact": "sticking", "fidelity": "coarse", "F1_N": [10.0]},
                               "sampling": {"method": "lhs", "n": args.designs, "seed": 7},
                               "axes": [{"name": "alpha_deg", "low": 25, "high": 40},
                                        {"name": "d0_mm", "low": 1.5, "high": 3.0}]})
    walls, own, startup = {}, {}, {}
    for workers in (1, 2):
        with tempfile.TemporaryDirectory() as tmp:
            result = run_sweep(spec, tmp, workers=workers)
            rows = [json.loads(p.read_text())[0] for p in Path(tmp, "designs").glob("*.json")]
            walls[workers] = result.wall_s
            startup[workers] = result.startup_s
            own[workers] = sum(r["wall_time_s"] for r in rows)
            print(f"{workers} worker(s): {result.designs} designs in {result.wall_s:.1f} s "
                  f"({60 * result.designs / result.wall_s:.1f} designs/min, {result.failed} failed)")
    per_design = own[1] / args.designs
    overhead = (walls[1] - startup[1] - own[1]) / args.designs
    print(f"speed-up 2 vs 1 worker: {walls[1] / walls[2]:.2f}x (cluster start-up {startup[1]:.1f} / "
          f"{startup[2]:.1f} s included)")
    print(f"one coarse design: {per_design:.2f} s; scheduling overhead per design (1 worker, after "
          f"start-up): {overhead:.3f} s = {100 * overhead / per_design:.1f} %")


if __name__ == "__main__":
    main()
