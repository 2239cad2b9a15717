"""The routes' cost and their mesh dependence: cup A on pmma-1.89, frictionless FEM, by level.

    python benchmarks/bench_routes.py [--levels coarse medium fine]

For each FEM level: the FEM time, then per route (paper: eq 6's strip with the cone laws; profile:
the FEM's contact-pressure profiles with its r_c and V) the lifetimes at F1 = 5, 10, 20, 40, 60,
80 N and their time; then the profile route's molecule flow at fixed states (p_b = 50 kPa, beta
(p_a - p_b) added) along the path, which shows where the levels disagree: at small u only the
sharp rim corner touches, one loaded node whose lumped pressure grows as the mesh is refined.
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
from reduced.lifetime import lifetime, reference_model
from reduced.profile_leak import profile_leak_rate, ring_gaps
from validation import handoff
from validation.crosscheck.context import pmma_uc_table

FORCES_N = (5.0, 10.0, 20.0, 40.0, 60.0, 80.0)
ROUTES = {"paper": {"geometry": "cone"}, "profile": {"geometry": "curve", "seal": "profile"}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", nargs="+", default=["coarse", "medium", "fine"])
    args = ap.parse_args()
    uc, g = pmma_uc_table("pmma-1.89"), cup_geometry("A")
    for level in args.levels:
        t0 = time.perf_counter()
        resp = compress_cup(cup_mesh(g, level), NeoHookean(E_Pa=4e6, nu=0.49), contact="frictionless",
                            u_max_m=0.9 * g.h1_m)
        curve = handoff.stiffness_curve(resp, {"source": "fem"})
        print(f"{level}: FEM {time.perf_counter() - t0:.1f} s")
        for route, kw in ROUTES.items():
            model = dataclasses.replace(reference_model(CUP_A, uc), stiffness=curve, **kw)
            t0 = time.perf_counter()
            lives = [lifetime(model, F).lifetime_s for F in FORCES_N]
            print(f"  {route:8s} lifetimes {' '.join(f'{x:.4g}' for x in lives)} s "
                  f"({time.perf_counter() - t0:.2f} s for {len(FORCES_N)} forces)")
        flows = []
        for k in range(2, curve.u_m.size, 4):
            prof = curve.profiles[k]
            gaps = ring_gaps(prof, uc, 4e6, extra_Pa=0.8 * 5e4)
            flows.append(f"u {1e3 * curve.u_m[k]:.2f} mm: {profile_leak_rate(AIR, 1e5, 5e4, prof.r_m, gaps):.3g}/s "
                         f"(narrowest gap {1e9 * np.min(gaps):.0f} nm, {prof.r_m.size} points)")
        print("  profile flow at p_b = 50 kPa: " + "; ".join(flows))


if __name__ == "__main__":
    main()
