"""Benchmark: a 200-pressure u_c table for a 2000-point spectrum (issue 4 target: <= 0.2 s, 2 cores).

Prints the median wall time of `critical_gap_table` for both methods (repeat runs, so the median is
robust to the other jobs sharing the machine), then the u_c(p/E) curves of the calibrated presets
in the form of the paper's Fig. 1pressureMPa.2loguc (log10 of u_c in nm against p/E).

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_uc.py [--repeat 9]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from reduced.roughness.persson import critical_gap_table
from reduced.roughness.surfaces import load_presets


def bench(spectrum, method: str, repeat: int) -> tuple[float, float]:
    p_over_E = np.geomspace(1e-5, 0.2, 200)
    critical_gap_table(spectrum, 4e6, 0.5, p_over_E, method=method)       # warm the kernel tables
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        critical_gap_table(spectrum, 4e6, 0.5, p_over_E, method=method)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=9)
    args = ap.parse_args()
    presets = load_presets()
    spec = presets["pmma-1.89"].spectrum(n=2000)
    print(f"u_c table: 200 pressures (p/E 1e-5 .. 0.2), spectrum pmma-1.89 with "
          f"{spec.q_per_m.size} points, median of {args.repeat}")
    for method in ("emt", "critical-junction"):
        med, best = bench(spec, method, args.repeat)
        print(f"  {method:18s} median {med * 1e3:7.1f} ms   best {best * 1e3:7.1f} ms   "
              f"target 200 ms: {'ok' if med <= 0.2 else 'MISSED'}")

    p_over_E = np.array([1e-4, 3e-4, 1e-3, 3e-3, 0.01, 0.02, 0.025, 0.03, 0.05, 0.1])
    print("\nlog10(u_c / nm) vs p/E (E = 4 MPa, nu = 0.5, emt; '-' = sealed)")
    print("  p/E      " + " ".join(f"{n:>10s}" for n in presets))
    tables = {n: critical_gap_table(p.spectrum(), 4e6, 0.5, p_over_E) for n, p in presets.items()}
    for i, pe in enumerate(p_over_E):
        cells = [f"{np.log10(t.u_c_m[i] * 1e9):10.3f}" if not t.sealed[i] else f"{'-':>10s}"
                 for t in tables.values()]
        print(f"  {pe:8.1e} " + " ".join(cells))


if __name__ == "__main__":
    main()
