"""Mesh convergence of the profile route: cup A on pmma-1.89, frictionless FEM, by level.

    OMP_NUM_THREADS=1 python benchmarks/bench_profile_convergence.py [--levels coarse medium fine]
                                                                     [--scales 0.5 2]

Reference conventions (no relaxation, E = 4 MPa in p/E, air at 293.15 K, p_a = 1e5 Pa). For each
FEM level (`fem.cup.compress_cup` up to 0.9 h1, `validation.bridge.handoff.stiffness_curve`): the rim
corner at the first contact sample (its lumped pressure and its neighbours' distances: the point
load that grows under refinement), then the profile route's lifetimes at F1 = 5, 10, 20, 40, 80 N

- before: the lumped nodal profile as it is (the table without a patch length);
- after: the profile averaged over patches that hold every wavelength u_c depends on
  (`UcTable.patch_length_m` from `reduced.roughness.uc_table(..., with_patch_length=True)`, 202 um
  here), carrying F0, eq (6)'s share on the nominal contact (`reduced.profile_leak`, `reduced.seal`);
- with --scales: the same with the patch length times each factor (the length's weight);

and last the level-to-level differences (coarse vs medium, medium vs fine) of each.
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
from reduced.lifetime import reference_model, solve_lifetime
from reduced.roughness import preset
from reduced.roughness.persson import patch_length
from validation.bridge import handoff
from validation.crosscheck.context import pmma_uc_table

FORCES_N = (5.0, 10.0, 20.0, 40.0, 80.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", nargs="+", default=["coarse", "medium", "fine"])
    ap.add_argument("--scales", nargs="*", type=float, default=[],
                    help="also run with the patch length times these factors")
    args = ap.parse_args()
    uc, g = pmma_uc_table("pmma-1.89"), cup_geometry("A")
    L = patch_length(preset("pmma-1.89").spectrum(), 0.5)
    uc = dataclasses.replace(uc, patch_length_m=L)
    variants = {"before": dataclasses.replace(uc, patch_length_m=None), "after": uc}
    for s in args.scales:
        variants[f"L x {s:g}"] = dataclasses.replace(uc, patch_length_m=s * L)
    print(f"cup A, pmma-1.89, frictionless; patch length L = {1e6 * L:.1f} um (reduced.roughness.persson.patch_length); "
          f"F1 = {', '.join(f'{F:g}' for F in FORCES_N)} N")
    table: dict[str, dict[str, list[float]]] = {name: {} for name in variants}
    for level in args.levels:
        t0 = time.perf_counter()
        resp = compress_cup(cup_mesh(g, level), NeoHookean(E_Pa=4e6, nu=0.49), contact="frictionless",
                            u_max_m=0.9 * g.h1_m)
        curve = handoff.stiffness_curve(resp, {"source": "fem", "level": level})
        k = next(i for i, p in enumerate(curve.profiles) if p is not None)
        prof = curve.profiles[k]
        j = int(np.argmax(prof.p_Pa))
        gaps = np.diff(prof.r_m)
        print(f"{level}: FEM {time.perf_counter() - t0:.1f} s; at u = {1e3 * curve.u_m[k]:.3f} mm "
              f"{int(np.count_nonzero(prof.p_Pa))} loaded node(s), peak {1e-3 * prof.p_Pa[j]:.1f} kPa, "
              f"neighbours {1e6 * gaps[j - 1]:.1f} and {1e6 * gaps[j]:.1f} um away, profile force "
              f"{prof.force_N / curve.F0_N[k]:.3f} F0")
        for name, table_uc in variants.items():
            model = dataclasses.replace(reference_model(CUP_A, table_uc), stiffness=curve)
            t0 = time.perf_counter()
            lives = [solve_lifetime(model, F, route="profile").lifetime_s for F in FORCES_N]
            table[name][level] = lives
            print(f"  {name:8s} lifetimes {' '.join(f'{x:8.4g}' for x in lives)} s "
                  f"({time.perf_counter() - t0:.1f} s)")
    pairs = list(zip(args.levels[:-1], args.levels[1:]))
    if pairs:
        print("level-to-level differences (lifetime of the coarser over the finer, - 1):")
        for name, by_level in table.items():
            for a, b in pairs:
                d = [100.0 * (x / y - 1.0) for x, y in zip(by_level[a], by_level[b])]
                print(f"  {name:8s} {a} vs {b}: {' '.join(f'{x:+7.1f}%' for x in d)}   "
                      f"(largest {max(abs(x) for x in d):.1f} %)")


if __name__ == "__main__":
    main()
