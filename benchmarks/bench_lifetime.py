"""Benchmark the reduced model: one reference-mode lifetime and the 16-force sweep 5...80 N.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_lifetime.py [--repeat 30]

Targets (issue 2): <= 5 ms per reference-mode lifetime, <= 0.1 s for the sweep. Prints min and
median over the repeats (the machine is shared; the median is the honest figure). "cold" includes
building the model (Appendix A curve, fold-search grid, initial state), which a sweep pays once.
"""

from __future__ import annotations

import argparse
import statistics
import time

from reduced.critical_gap import ILLUSTRATIVE_UC_CSV, UcTable
from reduced.cup import CUP_A
from reduced.lifetime import largest_holdable_force, reference_model, solve_lifetime

FORCES_N = [float(f) for f in range(5, 85, 5)]


def _time(fn, repeat: int) -> tuple[float, float]:
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t0)
    return min(samples), statistics.median(samples)


def _sweep(model) -> list:
    """The lifetimes at every force of FORCES_N (sharing the model's precomputation)."""
    return [solve_lifetime(model, F1, route="paper") for F1 in FORCES_N]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=30, help="repetitions per figure (default: 30)")
    args = ap.parse_args()
    uc = UcTable.from_csv(ILLUSTRATIVE_UC_CSV)
    model = reference_model(CUP_A, uc)
    largest_holdable_force(model)          # warm the model's precomputation

    def cold(F1: float):
        m = reference_model(CUP_A, uc)
        return solve_lifetime(m, F1, route="paper")

    print("cupcheck reduced model, cup A, reference mode, illustrative u_c table")
    for F1 in (5.0, 20.0, 80.0):
        r = solve_lifetime(model, F1, route="paper")
        lo, med = _time(lambda: solve_lifetime(model, F1, route="paper"), args.repeat)
        print(f"  one lifetime F1 = {F1:4g} N ({r.lifetime_s:8.4g} s, {r.steps:2d} steps): "
              f"min {1e3 * lo:6.2f} ms, median {1e3 * med:6.2f} ms")
    lo, med = _time(lambda: cold(20.0), max(3, args.repeat // 3))
    print(f"  one lifetime F1 =   20 N, cold (model built too):        "
          f"min {1e3 * lo:6.2f} ms, median {1e3 * med:6.2f} ms")
    lo, med = _time(lambda: _sweep(model), max(3, args.repeat // 3))
    print(f"  sweep of {len(FORCES_N)} forces 5...80 N:                          "
          f"min {1e3 * lo:6.1f} ms, median {1e3 * med:6.1f} ms")
    lo, med = _time(lambda: _sweep(reference_model(CUP_A, uc)), max(3, args.repeat // 3))
    print(f"  sweep of {len(FORCES_N)} forces, cold:                             "
          f"min {1e3 * lo:6.1f} ms, median {1e3 * med:6.1f} ms")
    print("targets: <= 5 ms per lifetime, <= 100 ms per sweep")


if __name__ == "__main__":
    main()
