"""Cost and results of the route "fem" (validation.bridge.fem_route): cup A pressed to r_start = 12 mm,
sealed, held at F1 along its FEM branch, per mesh level and contact law.

    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --levels coarse medium --forces 10
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --levels coarse --forces 5 10 20 40

For each (level, law): the largest holdable force (max pull at fixed N0), then per force the
lifetime, its reason, the branch's states and Newton iterations, the seal radius at the start of
the branch and at its end, and where the time goes (pressing + sealing, the branch's FEM solves,
the rest: sensitivities, measurement and the leak through every state's profile).
"""

from __future__ import annotations

import argparse
import math
import time

import reduced
from fem.interface import ContactLaw
from validation.bridge.fem_route import FemCup, FemRouteError, register
from validation.bridge.pipeline import surface_uc_table

LAWS = {"frictionless": ContactLaw(), "coulomb 0.5": ContactLaw("coulomb", 0.5),
        "sticking": ContactLaw("sticking")}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--levels", nargs="+", default=["coarse"])
    ap.add_argument("--laws", nargs="+", default=list(LAWS), choices=list(LAWS))
    ap.add_argument("--forces", nargs="+", type=float, default=[10.0])
    ap.add_argument("--du-mm", type=float, default=None)
    a = ap.parse_args()
    model = reduced.reference_model(reduced.CUP_A, surface_uc_table())
    opts = {} if a.du_mm is None else {"du_m": 1e-3 * a.du_mm}
    print("| level | law | F1 [N] | lifetime [s] | reason | states | Newton it. | seal r start/end [mm] "
          "| u end [mm] | wall [s]: total / press / branch FEM / rest | largest force [N] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for level in a.levels:
        for law in a.laws:
            route = register()
            route._sealed.clear()
            cup = FemCup("A", level, contact=LAWS[law])
            t0 = time.perf_counter()
            sealed = route.seal(model, {**route.options, "cup": cup})
            t_press = time.perf_counter() - t0
            t0 = time.perf_counter()
            try:
                largest = route.largest_force(model, {**route.options, "cup": cup})
            except Exception as err:       # reported, not hidden
                largest = math.nan
                print(f"<!-- {level} {law}: largest force failed: {err} -->")
            t_largest = time.perf_counter() - t0
            for F in a.forces:
                t0 = time.perf_counter()
                try:
                    life = reduced.solve_lifetime(model, F, route="fem", cup=cup, **opts)
                except (FemRouteError, RuntimeError) as err:
                    print(f"| {level} | {law} | {F:g} | failed | {str(err)[:90]} | | | | | "
                          f"{time.perf_counter() - t0:.1f} | {largest:.2f} |", flush=True)
                    continue
                wall = time.perf_counter() - t0
                d = life.details
                tr = life.trajectory
                fem = d.get("wall_time_s", 0.0)
                seal = (f"{tr['seal_r_mm'][0]:.2f} / {tr['seal_r_mm'][-1]:.2f}" if len(tr.get("N", ())) else
                        f"{d['seal_r_sealed_mm']:.2f} (sealed)")
                print(f"| {level} | {law} | {F:g} | {life.lifetime_s:.4g} | {life.reason} | {d.get('states', 0)} | "
                      f"{d.get('newton_iterations', 0)} | {seal} | {d.get('u_final_mm', math.nan):.3f} | "
                      f"{wall:.1f} / {t_press:.1f} / {fem:.1f} / {wall - fem:.1f} | {largest:.2f} |", flush=True)
            print(f"<!-- {level} {law}: press+seal {t_press:.1f} s, largest force {t_largest:.1f} s, "
                  f"N0 = {sealed.state.N:.4e}, u_sealed = {1e3 * sealed.state.u_m:.3f} mm, "
                  f"seal r at sealing = {1e3 * sealed.state.seal_r_m:.2f} mm -->", flush=True)


if __name__ == "__main__":
    main()
