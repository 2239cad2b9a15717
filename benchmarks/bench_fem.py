"""FEM benchmark: cup A pressed from u = 0 to 0.9 h1 at each fidelity, frictionless and sticking.

Prints, per contact law and fidelity level: DOFs, load steps, Newton iterations, wall time
(median of --repeat runs, default solver options) and the error of F0 and of the strip width l
against the reference: the Richardson extrapolation of the three levels (coarse, medium, fine: a
constant refinement ratio of 2) run again with small load steps, so that sampling the curves
between steps adds no error of its own; and the observed orders. Run from the repository:

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_fem.py [--repeat 3]

Error measures (relative to the extrapolated value at the same u):
  F0 [0.1,0.8]  largest |F0 - F0*| / F0* over u/h1 = 0.10, 0.15, ..., 0.80;
  F0 @0.9       the same at u = 0.9 h1, the steep end where the wall is pressed flat;
  l [0.3,0.9]   largest |l - l*| / l* over u/h1 = 0.30, ..., 0.90 (l is the pressure-weighted
                width; before ~0.25 h1 only the rim corner touches and l -> 0 with the mesh).
Curves are sampled at those u by monotone cubic (PCHIP) interpolation between the load steps.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fem.cup import compress_cup  # noqa: E402
from fem.geometry import cup_geometry  # noqa: E402
from fem.material import NeoHookean  # noqa: E402
from fem.mesh import FIDELITIES, cup_mesh  # noqa: E402
from fem.postprocess import richardson  # noqa: E402

U_F0 = np.round(np.arange(0.10, 0.801, 0.05), 4)     # u / h1 for the F0 error
U_L = np.round(np.arange(0.30, 0.901, 0.05), 4)      # u / h1 for the l error
U_MAX = 0.9
REF_STEP = 0.01       # load-step cap of the reference runs (fraction of u_max): small sampling error


def run_level(level: str, contact: str, repeat: int = 1, **solver_opts) -> dict:
    """Run one fidelity level `repeat` times; the sampled curves of the last run, the median time."""
    geometry = cup_geometry("A")
    mesh = cup_mesh(geometry, level)
    times, response = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        response = compress_cup(mesh, NeoHookean(), contact=contact, u_max_m=U_MAX * geometry.h1_m,
                                **solver_opts)
        times.append(time.perf_counter() - t0)
    x = response.u_m / response.h1_m
    sample = lambda y, at: PchipInterpolator(x, y)(at)     # noqa: E731
    return {"level": level, "spec": FIDELITIES[level], "dofs": int(response.stats.dofs),
            "steps": response.stats.steps, "newton": response.stats.newton_iterations,
            "time_s": statistics.median(times),
            "F0": sample(response.F0_N, np.append(U_F0, U_MAX)), "l": sample(response.l_m, U_L),
            "r_c": sample(response.r_c_m, U_L), "l_half": sample(response.l_half_max_m, U_L)}


def report(contact: str, runs: list[dict], reference: list[dict]) -> None:
    print(f"\ncup A, {contact} contact, u = 0 .. {U_MAX} h1, E = 4 MPa, nu = 0.49 (displacement formulation)")
    print(f"reference: Richardson extrapolation of the three levels run with max_step = {REF_STEP} "
          f"({', '.join(str(r['steps']) for r in reference)} steps); timed runs: default solver options")
    rich = {q: richardson(*(r[q] for r in reference)) for q in ("F0", "l", "r_c", "l_half")}
    print(f"{'fidelity':8} {'mesh':>6} {'DOFs':>6} {'steps':>5} {'Newton':>6} {'time/s':>7} "
          f"{'F0 [0.1,0.8]':>12} {'F0 @0.9':>8} {'l [0.3,0.9]':>11} {'l_hm [0.3,0.9]':>14}")
    for r in runs:
        eF = np.abs(r["F0"] / rich["F0"].extrapolated - 1)
        el = np.max(np.abs(r["l"] / rich["l"].extrapolated - 1))
        eh = np.max(np.abs(r["l_half"] / rich["l_half"].extrapolated - 1))
        s = r["spec"]
        print(f"{r['level']:8} {s.n_along:>3}x{s.n_through:<2} {r['dofs']:>6} {r['steps']:>5} "
              f"{r['newton']:>6} {r['time_s']:>7.2f} {100 * eF[:-1].max():>11.2f}% "
              f"{100 * eF[-1]:>7.2f}% {100 * el:>10.2f}% {100 * eh:>13.2f}%")
    for q, label in (("F0", "F0"), ("l", "l (weighted)"), ("r_c", "r_c"), ("l_half", "l (half max)")):
        order = rich[q].order
        ok = np.isfinite(order)
        med = f"{np.median(order[ok]):.2f}" if ok.any() else "n/a"
        print(f"  observed order of {label:13}: median {med} over {ok.sum()}/{order.size} monotone "
              f"samples; finest-mesh error estimate <= {100 * np.max(rich[q].fine_error / np.abs(rich[q].extrapolated)):.2f}%")
    print(f"  F0* at u/h1 = 0.1, 0.5, 0.8, 0.9: "
          + ", ".join(f"{rich['F0'].extrapolated[np.argmin(np.abs(np.append(U_F0, U_MAX) - u))]:.4g} N"
                      for u in (0.1, 0.5, 0.8, 0.9)))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=1, help="runs per level for the median wall time")
    parser.add_argument("--contact", choices=("frictionless", "sticking"), nargs="+",
                        default=["frictionless", "sticking"])
    args = parser.parse_args()
    for contact in args.contact:
        try:
            runs = [run_level(level, contact, args.repeat if level == "coarse" else 1) for level in FIDELITIES]
            reference = [run_level(level, contact, max_step=REF_STEP) for level in FIDELITIES]
        except RuntimeError as exc:
            print(f"\ncup A, {contact}: FAILED: {exc}")
            continue
        report(contact, runs, reference)
    return 0


if __name__ == "__main__":
    sys.exit(main())
