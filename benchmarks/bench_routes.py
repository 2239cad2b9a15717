"""The three routes side by side: cup A's lifetimes, their cost and their mesh dependence.

    OMP_NUM_THREADS=1 python benchmarks/bench_routes.py [--levels coarse medium fine]
                                                        [--coupled-levels coarse medium]

Cup A, frictionless FEM, reference conventions (no relaxation, E = 4 MPa in p/E, air at 293.15 K,
p_a = 1e5 Pa). For each FEM level: the FEM path's time, then per route the lifetimes at F1 = 5, 10,
20, 40, 80 N on pmma-1.89 and at 10 N on the table surface, with the route's cost:
- paper: the FEM's F0 through eq (6)'s strip and the cone laws (3)-(5);
- profile: the FEM's F0, r_c, V and contact-pressure profiles at dp = 0, beta (p_a - p_b) added;
- coupled: the FEM suction table on the default (u, dp) grid (`validation.bridge.coupled.build`, cached in
  --cache-dir; the table's cost is the FEM time it recorded when it was built), the cup's
  state and profile from the table (`reduced.coupled`).
Last, the raw (not patch-averaged) profile's molecule flow at fixed states (p_b = 50 kPa) along the path, which shows
where the levels disagree: at small u only the sharp rim corner touches, one loaded node whose
lumped pressure grows as the mesh is refined.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from fem.cup import compress_cup
from fem.geometry import cup_geometry
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from reduced.cup import CUP_A
from reduced.gas import AIR
from reduced.lifetime import LeakageModel, largest_holdable_force, reference_model, solve_lifetime
from reduced.profile_leak import profile_leak_rate, ring_gaps
from validation.bridge import handoff
from validation.bridge.coupled.build import suction_table_for
from validation.crosscheck.context import pmma_uc_table

FORCES_N = (5.0, 10.0, 20.0, 40.0, 80.0)
SURFACES = ("pmma-1.89", "table")
ROUTES = {"paper": {"route": "paper", "cup_laws": "cone"}, "profile": {"route": "profile"}}


def _row(route: str, lives: list[float], table_10N: float, held: float, cost: str) -> None:
    print(f"  {route:8s} " + " ".join(f"{x:9.4g}" for x in lives) + f" {table_10N:9.4g} {held:8.4g}  {cost}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", nargs="+", default=["coarse", "medium", "fine"])
    ap.add_argument("--coupled-levels", nargs="*", default=["coarse", "medium"],
                    help="levels whose suction table is built (fine: ~20 min)")
    ap.add_argument("--cache-dir", default="out/bench_routes",
                    help="where suction tables are kept (cupcheck validate --cache-dir D keeps its own in D/suction)")
    args = ap.parse_args()
    uc = {s: pmma_uc_table(s) for s in SURFACES}
    g = cup_geometry("A")
    for level in args.levels:
        t0 = time.perf_counter()
        resp = compress_cup(cup_mesh(g, level), NeoHookean(E_Pa=4e6, nu=0.49), contact="frictionless",
                            u_max_m=0.9 * g.h1_m)
        curve = handoff.stiffness_curve(resp, {"source": "fem"})
        print(f"{level}: FEM path {time.perf_counter() - t0:.1f} s")
        print(f"  {'route':8s} " + " ".join(f"{f'{F:g} N':>9}" for F in FORCES_N)
              + f" {'table 10N':>9} {'held_N':>8}  cost")
        for route, kw in ROUTES.items():
            models = {s: dataclasses.replace(reference_model(CUP_A, uc[s]), stiffness=curve) for s in SURFACES}
            t0 = time.perf_counter()
            lives = [solve_lifetime(models["pmma-1.89"], F, **kw).lifetime_s for F in FORCES_N]
            spent = time.perf_counter() - t0
            _row(route, lives, solve_lifetime(models["table"], 10.0, **kw).lifetime_s,
                 largest_holdable_force(models["pmma-1.89"], **kw),
                 f"FEM path + {spent / len(FORCES_N):.2g} s per lifetime")
        if level in args.coupled_levels:
            _coupled(g, level, uc, args.cache_dir)
        _profile_flows(curve, uc["pmma-1.89"])


def _coupled(g, level: str, uc: dict, cache_dir: str) -> None:
    t0 = time.perf_counter()
    table = suction_table_for(g, fidelity=level, cache_dir=cache_dir)
    read = time.perf_counter() - t0
    u_start = table.h1_m - CUP_A.h_start_m
    models = {s: LeakageModel(cup=CUP_A, suction=table, u_c=uc[s]) for s in SURFACES}
    kw = {"route": "coupled", "u_start_m": u_start}
    t0 = time.perf_counter()
    solve_lifetime(models["pmma-1.89"], FORCES_N[0], **kw)           # the nodes' conductances, once
    setup = time.perf_counter() - t0
    t0 = time.perf_counter()
    lives = [solve_lifetime(models["pmma-1.89"], F, **kw).lifetime_s for F in FORCES_N]
    spent = time.perf_counter() - t0
    _row("coupled", lives, solve_lifetime(models["table"], 10.0, **kw).lifetime_s,
         largest_holdable_force(models["pmma-1.89"], **kw),
         f"table {table.provenance['solver']['wall_time_s']:.0f} s once ({table.provenance['grid']}; "
         f"read {read:.1f} s) + {setup:.1f} s conductances + {spent / len(FORCES_N):.2g} s per lifetime")


def _profile_flows(curve, uc) -> None:
    flows = []
    for k in range(2, curve.u_m.size, 4):
        prof = curve.profiles[k]
        gaps = ring_gaps(prof, uc, 4e6, extra_Pa=0.8 * 5e4)
        flows.append(f"u {1e3 * curve.u_m[k]:.2f} mm: {profile_leak_rate(AIR, 1e5, 5e4, prof.r_m, gaps):.3g}/s "
                     f"(narrowest gap {1e9 * np.min(gaps):.0f} nm, {prof.r_m.size} points)")
    print("  raw (not patch-averaged) profile flow at p_b = 50 kPa: " + "; ".join(flows))


if __name__ == "__main__":
    main()
