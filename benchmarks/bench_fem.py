"""FEM benchmark: cup A pressed from u = 0 to 0.9 h1 at each fidelity, frictionless and sticking.

Prints, per contact law and fidelity level: DOFs, load steps, Newton iterations, wall time
(median of --repeat runs, default solver options) and the error of F0 and of the strip width l
against the reference: the Richardson extrapolation of the three levels (coarse, medium, fine: a
constant refinement ratio of 2) run again with small load steps, so that sampling the curves
between steps adds no error of its own; and the observed orders. Run from the repository:

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_fem.py [--repeat 3]

Timing only (no reference runs, no errors; median of --repeat runs at every chosen level):

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_fem.py --timing \
        --levels coarse medium --repeat 3

Error measures (relative to the extrapolated value at the same u):
  F0            largest |F0 - F0*| / F0* over u/h1 = 0.10, 0.15, ..., 0.80;
  @0.9          the same at u = 0.9 h1, the steep end where the wall is pressed flat;
  l, l_hm       largest relative error over u/h1 = 0.30, ..., 0.90 of the hand-off's strip width
                (the force-quartile width, CupResponse.l_m) and of the half-maximum width (before
                ~0.25 h1 only the rim touches); the targets line takes l over u >= 0.7 h1, and
                adds the horizontal distance of the l(u) curve from the reference (the largest
                shift in u at which the level reaches the reference's l, bench_mesh_levels.py):
                where the sticking strip spreads (1 -> 5 mm between 0.7 and 0.8 h1) a shift of
                the curve by 0.005 h1 is a 10 % error at fixed u.
Curves are sampled at those u by monotone cubic (PCHIP) interpolation between the load steps.
'mesh' errors come from runs with the reference's small steps, 'curve' errors from the timed
runs with the default steps: they add the sampling error of the delivered curve (the F0(u) curve
has a kink where the wall touches down, near u = 0.2 h1 for cup A).
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
from fem.mesh import DEFAULT_FIDELITY, FIDELITIES, cup_mesh  # noqa: E402
from fem.postprocess import richardson  # noqa: E402
from bench_mesh_levels import U_DENSE, touchdown, u_shift  # noqa: E402

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
            "l_dense": sample(response.l_m, U_DENSE),
            "r_c": sample(response.r_c_m, U_L), "l_half": sample(response.l_half_max_m, U_L),
            "u_td": touchdown(np.linspace(0.3, U_MAX, 601), sample(response.F0_N, np.linspace(0.3, U_MAX, 601))),
            "fold": np.inf if response.folding_u_m is None else response.folding_u_m / response.h1_m}


def report(contact: str, runs: list[dict], reference: list[dict], detail: bool) -> None:
    print(f"\ncup A, {contact} contact, u = 0 .. {U_MAX} h1, E = 4 MPa, nu = 0.49 (displacement formulation)")
    print(f"reference: Richardson extrapolation of the three levels run with max_step = {REF_STEP} "
          f"({', '.join(str(r['steps']) for r in reference)} steps)")
    rich = {q: richardson(*(r[q] for r in reference)) for q in ("F0", "l", "r_c", "l_half")}
    err = lambda r, q: np.abs(r[q] / rich[q].extrapolated - 1)      # noqa: E731
    print("  'mesh' errors: the level run with the reference's small steps (discretisation only);")
    print("  'curve' errors: the timed run with default steps, PCHIP between its steps (what a user gets)")
    print(f"{'fidelity':8} {'mesh':>6} {'DOFs':>6} {'steps':>5} {'Newton':>6} {'time/s':>7} | "
          f"{'F0 mesh':>7} {'@0.9':>6} | {'F0 curve':>8} {'@0.9':>6} | {'l mesh':>7} {'l curve':>7} {'l_hm mesh':>9}")
    for r, ref in zip(runs, reference):
        s = r["spec"]
        print(f"{r['level']:8} {s.n_along:>3}x{s.n_through:<2} {r['dofs']:>6} {r['steps']:>5} "
              f"{r['newton']:>6} {r['time_s']:>7.2f} | {100 * err(ref, 'F0')[:-1].max():>6.2f}% "
              f"{100 * err(ref, 'F0')[-1]:>5.2f}% | {100 * err(r, 'F0')[:-1].max():>7.2f}% "
              f"{100 * err(r, 'F0')[-1]:>5.2f}% | {100 * err(ref, 'l').max():>6.1f}% "
              f"{100 * err(r, 'l').max():>6.1f}% {100 * err(ref, 'l_half').max():>8.1f}%")
    default = next(k for k, r in enumerate(runs) if r["level"] == DEFAULT_FIDELITY)
    d, finest = runs[default], reference[-1]
    u_f0, fold, u_td = np.append(U_F0, U_MAX), finest["fold"], finest["u_td"]
    # trusted samples: below the finest level's folding stretch (beyond it the curve depends on the
    # mesh, CupResponse.folding_u_m) and outside a mid-wall touchdown (there the relative error
    # measures where a level puts the touchdown: bench_mesh_levels.py)
    keep = u_f0 <= fold + 1e-9
    if np.isfinite(u_td):
        keep &= (u_f0 < u_td - 0.05) | (u_f0 > u_td + 0.10)
    late = (U_L >= 0.7 - 1e-9) & (U_L <= fold + 1e-9)
    shift = u_shift(d["l_dense"], rich["l"].extrapolated[late], U_L[late])
    left_out = [f"u > {fold:.2f} h1 (folding)"] if np.isfinite(fold) and fold < U_MAX else []
    left_out += [f"{u_td - 0.05:.2f}-{u_td + 0.10:.2f} h1 (touchdown)"] if np.isfinite(u_td) else []
    print(f"  targets, default level ({DEFAULT_FIDELITY}, curve errors{', without ' + ', '.join(left_out) if left_out else ''}): "
          f"F0 within {100 * err(d, 'F0')[keep].max():.2f} % in {d['time_s']:.2f} s (target: 1 % in 3 s); "
          f"l within {100 * err(d, 'l')[late].max():.2f} % for u >= 0.7 h1 (target: 2 % in 10 s), "
          f"the l(u) curve within {np.nanmax(np.abs(shift)):.4f} h1 of the reference in u")
    for q, label in (("F0", "F0"), ("l", "l (quartile)"), ("r_c", "r_c"), ("l_half", "l (half max)")):
        order = rich[q].order
        ok = np.isfinite(order)
        med = f"{np.median(order[ok]):.2f}" if ok.any() else "n/a"
        print(f"  observed order of {label:13}: median {med} over {ok.sum()}/{order.size} samples in the "
              f"asymptotic range; finest-mesh error estimate <= "
              f"{100 * np.max(rich[q].fine_error / np.abs(rich[q].extrapolated)):.2f}%")
    if detail:
        for q, grid, unit in (("F0", np.append(U_F0, U_MAX), 1.0), ("r_c", U_L, 1e3), ("l", U_L, 1e3),
                              ("l_half", U_L, 1e3)):
            print(f"  {q} per u/h1 (reference runs: coarse, medium, fine | extrapolated, order | coarse curve)")
            for k, u in enumerate(grid):
                vals = " ".join(f"{unit * ref[q][k]:9.4f}" for ref in reference)
                print(f"    {u:4.2f} {vals} | {unit * rich[q].extrapolated[k]:9.4f} {rich[q].order[k]:5.2f} | "
                      f"{unit * runs[0][q][k]:9.4f}")


def timing(contacts: list[str], levels: list[str], repeat: int) -> int:
    """Cost table: DOFs, steps, Newton iterations, cut-backs and the median wall time per level."""
    print(f"cup A, u = 0 .. {U_MAX} h1, default solver options, median of {repeat} run(s)")
    print(f"{'contact':13} {'fidelity':8} {'DOFs':>6} {'steps':>5} {'Newton':>6} {'time/s':>7}  (all runs)")
    for contact in contacts:
        for level in levels:
            geometry = cup_geometry("A")
            mesh = cup_mesh(geometry, level)
            times = []
            for _ in range(repeat):
                t0 = time.perf_counter()
                resp = compress_cup(mesh, NeoHookean(), contact=contact, u_max_m=U_MAX * geometry.h1_m)
                times.append(time.perf_counter() - t0)
            s = resp.stats
            print(f"{contact:13} {level:8} {s.dofs:>6} {s.steps:>5} {s.newton_iterations:>6} "
                  f"{statistics.median(times):>7.2f}  ({', '.join(f'{t:.2f}' for t in times)})", flush=True)
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=1, help="runs per level for the median wall time")
    parser.add_argument("--detail", action="store_true", help="also print the sampled curves per u")
    parser.add_argument("--contact", choices=("frictionless", "sticking"), nargs="+",
                        default=["frictionless", "sticking"])
    parser.add_argument("--levels", choices=tuple(FIDELITIES), nargs="+", default=list(FIDELITIES))
    parser.add_argument("--timing", action="store_true",
                        help="only time the default-step runs of --levels (median of --repeat each)")
    args = parser.parse_args()
    if args.timing:
        return timing(args.contact, args.levels, args.repeat)
    for contact in args.contact:
        runs, reference, failures = [], [], []
        for level in FIDELITIES:
            for into, label, opts in ((runs, "default steps", {"repeat": args.repeat if level == DEFAULT_FIDELITY else 1}),
                                      (reference, f"max_step {REF_STEP}", {"max_step": REF_STEP})):
                try:
                    into.append(run_level(level, contact, **opts))
                except RuntimeError as exc:
                    failures.append(f"{level} ({label}): {exc}")
        if len(reference) == len(runs) == len(FIDELITIES):
            report(contact, runs, reference, args.detail)
        else:
            print(f"\ncup A, {contact} contact: no Richardson reference; the runs that converged:")
            for r in runs + reference:
                print(f"  {r['level']:8} {r['dofs']:>6} DOFs {r['steps']:>4} steps {r['newton']:>5} Newton "
                      f"{r['time_s']:>7.2f} s  F0(0.5 h1) = {r['F0'][list(np.append(U_F0, U_MAX)).index(0.5)]:.4g} N, "
                      f"F0(0.9 h1) = {r['F0'][-1]:.4g} N")
        for failure in failures:
            print(f"  FAILED {failure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
