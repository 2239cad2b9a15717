"""Coulomb friction on cup A: F0(u) for several mu, the cost against the sticking law, and the mu
whose small-u stiffness F0(1 mm) / 1 mm matches the paper's dry 2.5 N/mm (Appendix A's value);
with --refine, the step refinement of a frictional path through the wall's snap.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_friction.py [--fidelity medium] [--repeat 1]
    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_friction.py --refine [--mu 2] [--fidelity medium]

Prints per law: wall time (min of --repeat), Newton iterations, F0 at 1, 3, 5, 7 mm, the small-u
stiffness, the largest cone excess; the ratio of each Coulomb time to the sticking one; then the
matching mu by bisection on runs to u = 1 mm (to 1 %). --refine: the path at the default largest
step (0.05 of the range) and at 1/2, 1/4, 1/8 of it (also the sticking law's), F0 at 4.5, 5, 6,
7 and 8 mm for each, and each one's largest difference from the next finer one.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from fem.cup import compress_cup
from fem.geometry import cup_geometry
from fem.material import NeoHookean
from fem.mesh import cup_mesh

MAT = NeoHookean(E_Pa=4e6, nu=0.49)
PAPER_DRY_N_PER_MM = 2.5


def run(mesh, contact, mu=0.0, u_max_m=None, repeat=1):
    best = None
    for _ in range(repeat):
        t = time.perf_counter()
        r = compress_cup(mesh, MAT, contact=contact, friction=mu, u_max_m=u_max_m)
        dt = time.perf_counter() - t
        best = dt if best is None else min(best, dt)
    return r, best


def small_u_stiffness(mesh, mu) -> float:
    r, _ = run(mesh, "coulomb", mu, u_max_m=1e-3)
    return float(r.F0_N[-1] / 1.0)


REFINE_U_MM = (4.5, 5.0, 6.0, 7.0, 8.0)
REFINE_STEPS = (0.05, 0.025, 0.0125, 0.00625)     # the default largest step, 1/2, 1/4, 1/8


def refinement(mesh, contact: str, mu: float, steps=REFINE_STEPS) -> list[tuple[float, np.ndarray, object]]:
    """(largest step, F0 at REFINE_U_MM [N], solver stats) of the path at each step in `steps`."""
    out = []
    for step in steps:
        r = compress_cup(mesh, MAT, contact=contact, friction=mu, max_step=step)
        out.append((step, np.interp(np.array(REFINE_U_MM) * 1e-3, r.u_m, r.F0_N), r.stats))
    return out


def print_refinement(mesh, mu: float) -> None:
    for contact, m in (("coulomb", mu), ("sticking", 0.0)):
        rows = refinement(mesh, contact, m)
        print(f"{contact} mu = {m:g}: F0 [N] at u = " + ", ".join(f"{u:g}" for u in REFINE_U_MM) + " mm")
        for i, (step, F, stats) in enumerate(rows):
            diff = ""
            if i + 1 < len(rows):
                diff = f"  largest |F0 - finer| / finer: {np.max(np.abs(F / rows[i + 1][1] - 1.0)):.2%}"
            print(f"  step {step:7.5f}: " + " ".join(f"{f:7.3f}" for f in F)
                  + f"  ({stats.newton_iterations} Newton iterations, {stats.wall_time_s:.1f} s){diff}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--fidelity", default="medium")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--mus", default="0,0.1,0.3,0.5,1,2")
    ap.add_argument("--refine", action="store_true", help="the step refinement study (module docstring)")
    ap.add_argument("--mu", type=float, default=2.0, help="Coulomb's mu of the refinement study")
    args = ap.parse_args()
    mesh = cup_mesh(cup_geometry("A"), args.fidelity)
    if args.refine:
        print(f"cup A, {args.fidelity}, E = 4 MPa, nu = 0.49, to 0.9 h1: step refinement")
        print_refinement(mesh, args.mu)
        return
    laws = [("frictionless", 0.0), ("sticking", 0.0)] + [("coulomb", float(m)) for m in args.mus.split(",")]
    times = {}
    print(f"cup A, {args.fidelity}, E = 4 MPa, nu = 0.49, to 0.9 h1")
    print(f"{'law':>12} {'mu':>5} {'time_s':>7} {'iters':>6} " + " ".join(f"F0({u}mm)" for u in (1, 3, 5, 7))
          + "  k_small_N/mm  cone_excess")
    for law, mu in laws:
        r, dt = run(mesh, law, mu, repeat=args.repeat)
        times[(law, mu)] = dt
        F = np.interp(np.array([1, 3, 5, 7]) * 1e-3, r.u_m, r.F0_N)
        print(f"{law:>12} {mu:5.2f} {dt:7.2f} {r.stats.newton_iterations:6d} "
              + " ".join(f"{f:8.3f}" for f in F) + f"  {F[0]:11.3f}  {np.max(r.cone_excess):.1e}")
    stick = times[("sticking", 0.0)]
    print("time ratio coulomb / sticking: " + ", ".join(
        f"mu {mu:g}: {t / stick:.2f}" for (law, mu), t in times.items() if law == "coulomb"))
    lo, hi = 0.0, 2.0
    k_lo, k_hi = small_u_stiffness(mesh, lo), small_u_stiffness(mesh, hi)
    if not (k_lo < PAPER_DRY_N_PER_MM < k_hi):
        print(f"2.5 N/mm not bracketed by mu in [{lo}, {hi}]: {k_lo:.3f} .. {k_hi:.3f} N/mm")
        return
    while hi - lo > 0.01 * hi:
        mid = 0.5 * (lo + hi)
        k = small_u_stiffness(mesh, mid)
        lo, hi = (mid, hi) if k < PAPER_DRY_N_PER_MM else (lo, mid)
    print(f"mu matching the paper's dry {PAPER_DRY_N_PER_MM} N/mm at u = 1 mm: {0.5 * (lo + hi):.3f} "
          f"(bracket {lo:.3f} .. {hi:.3f})")


if __name__ == "__main__":
    main()
