"""Coulomb friction on cup A: F0(u) for several mu, the cost against the sticking law, and the mu
whose small-u stiffness F0(1 mm) / 1 mm matches the paper's dry 2.5 N/mm (Appendix A's value).

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_friction.py [--fidelity medium] [--repeat 1]

Prints per law: wall time (min of --repeat), Newton iterations, F0 at 1, 3, 5, 7 mm, the small-u
stiffness, the largest cone excess; the ratio of each Coulomb time to the sticking one; then the
matching mu by bisection on runs to u = 1 mm (to 1 %).
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


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--fidelity", default="medium")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--mus", default="0,0.1,0.3,0.5,1,2")
    args = ap.parse_args()
    mesh = cup_mesh(cup_geometry("A"), args.fidelity)
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
