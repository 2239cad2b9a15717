"""The profile route's cost per force and what the flow tables change: the main job's lifetimes.

    OMP_NUM_THREADS=1 python benchmarks/bench_profile_speed.py [--repeats 3] [--baseline CSV]

The main job (scenes/main.toml: cup A, medium frictionless FEM, pmma-1.89, F1 = 5 .. 80 N, refine=2),
its 16 lifetimes solved on a fresh model per run (so the flow tables are built inside the timing):

- direct: every flow through a profile solved at its state (`route="profile", exact=True`);
- tabulated: the default, each sample's flow tabulated against p_b (`reduced.seal.PbTable`).

Prints per mode the median over the runs of the wall and CPU time per force (all 16 forces, the
tables' cost included) and of the first force alone (where the tables are built), then per force
the lifetimes of both modes and their relative difference, the same lifetimes by quadrature
(`lifetime_by_quadrature`, no time stepping: the tables' own effect), and with --baseline the
main job's CSV before the change, to 4 significant digits. Run on a tree without the tables (a
checkout before them) it times the route as it is there, as "direct".
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import statistics
import time
from pathlib import Path

from reduced.lifetime import ROUTES, lifetime_by_quadrature, solve_lifetime
from validation.bridge.products import Products, _model
from validation.scenes.schema import load_scene

SCENE = Path(__file__).resolve().parents[1] / "scenes" / "main.toml"


def _run(model, forces, exact: bool | None) -> tuple[list[float], list[float], list[float], float]:
    """(lifetimes, wall per force [s], CPU per force [s], total CPU [s]) on a fresh copy of model."""
    fresh = dataclasses.replace(model)          # a new object: no tables or start state cached
    options = {} if exact is None else {"exact": exact}
    lives, wall, cpu = [], [], []
    for F in forces:
        w0, c0 = time.perf_counter(), time.process_time()
        lives.append(solve_lifetime(fresh, F, route="profile", refine=2, **options).lifetime_s)
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return lives, wall, cpu, sum(cpu)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--baseline", help="the main job's lifetime_vs_force.csv before the change")
    args = ap.parse_args()
    study = load_scene(SCENE).study()
    products = Products(study)
    t0 = time.perf_counter()
    model = _model(study, products.curve(), products.uc_table(), products.cup())
    forces = [float(F) for F in study.loads.forces_N]
    print(f"main job: FEM curve and u_c table {time.perf_counter() - t0:.2f} s; {len(forces)} forces, "
          f"{sum(p is not None for p in model.stiffness.profiles)} profiles")
    modes = {"direct": True, "tabulated": False} if "exact" in ROUTES["profile"].options else {"direct": None}
    lives = {}
    print(f"{'mode':10s} {'ms/force wall':>14s} {'ms/force CPU':>13s} {'first force wall':>17s} "
          f"{'rest wall':>10s}   (median of {args.repeats} runs)")
    for name, exact in modes.items():
        runs = [_run(model, forces, exact) for _ in range(args.repeats)]
        lives[name] = runs[0][0]
        per = statistics.median(1e3 * sum(r[1]) / len(forces) for r in runs)
        cpu = statistics.median(1e3 * r[3] / len(forces) for r in runs)
        first = statistics.median(1e3 * r[1][0] for r in runs)
        rest = statistics.median(1e3 * statistics.mean(r[1][1:]) for r in runs)
        print(f"{name:10s} {per:14.1f} {cpu:13.1f} {first:17.1f} {rest:10.1f}")
    base = {}
    if args.baseline:
        base = {float(r["force_N"]): float(r["lifetime_s"]) for r in csv.DictReader(open(args.baseline))}
    if "tabulated" not in lives:
        for F, t in zip(forces, lives["direct"]):
            print(f"  F1 = {F:4g} N: {t:.10g} s" + (f"  (baseline {base[F]:.10g}, {t / base[F] - 1:+.1e})" if F in base else ""))
        return
    print("F1 [N]   direct [s]  tabulated [s]  rel. diff   by quadrature: direct, tabulated, rel. diff"
          + ("   4 digits: baseline, tabulated" if base else ""))
    worst, changed = 0.0, 0
    for F, a, b in zip(forces, lives["direct"], lives["tabulated"]):
        qa = lifetime_by_quadrature(model, F, epsrel=1e-10, exact=True)
        qb = lifetime_by_quadrature(model, F, epsrel=1e-10)
        worst = max(worst, abs(b / a - 1))
        line = f"{F:6g} {a:12.7g} {b:14.7g} {b / a - 1:+10.1e}   {qa:12.7g} {qb:12.7g} {qb / qa - 1:+9.1e}"
        if F in base:
            same = f"{base[F]:.4g}" == f"{b:.4g}"
            changed += not same
            line += f"   {base[F]:.4g} {b:.4g}" + ("" if same else f" (changed; direct vs quadrature {a / qa - 1:+.1e})")
        print(line)
    print(f"largest |tabulated/direct - 1| through the integrator: {worst:.1e}"
          + (f"; {changed} of {len(forces)} lifetimes change in the 4th digit" if base else ""))


if __name__ == "__main__":
    main()
