"""The profile route's lifetimes against the FEM's load steps: cup A, frictionless (or --contact),
the main job's surface, at each mesh level and largest step (a fraction of the default travel
0.9 h1), to the default u_max and to a longer one; then which of the curve's quantities carries the
difference between two step densities (the coarser curve with one column of the finer one put in).

    OMP_NUM_THREADS=1 python benchmarks/bench_profile_steps.py [--levels coarse medium]
        [--steps 0.05 0.025 0.0125 0.00625] [--u-max-mm 8.466] [--forces 5 20 50 80] [--contact sticking]

Per row: the level, the largest step, u_max, the curve's samples (a path that fails beyond 0.9 h1
keeps its converged part), the largest holdable force and
the lifetime (and how it ended, when not at r1) per force, and the relative difference to the same
level's finest step at the default u_max. The swap table: the lifetimes of the default-step curve
with the finest curve's F0, r_c or V (PCHIP onto the default samples), and with all three, against
the finest curve's own: what is left after all three is the leak through the sampled profiles.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np

from fem.geometry import cup_geometry
from fem.interface import ContactLaw
from reduced.fast_curve import ScalarPchip
from reduced.lifetime import solve_lifetime
from fem.solver import ConvergenceError
from validation.bridge.pipeline import converged_part, fem_curve, fem_path, neo_hookean
from validation.bridge.products import Products, _model
from validation.scenes.schema import load_scene

SCENE = Path(__file__).resolve().parents[1] / "scenes" / "main.toml"
GEOMETRY = cup_geometry("A")


def curve(level: str, law: str, u_max_mm: float | None, max_step: float):
    """Cup A's stiffness curve at `level` to u_max (None: 0.9 h1) with the largest step `max_step`
    (the converged part of a path that fails beyond the default u_max, as `cupcheck stiffness` keeps it)."""
    try:
        response = fem_path(GEOMETRY, neo_hookean(4e6, 0.49), ContactLaw(law), level,
                            None if u_max_mm is None else 1e-3 * u_max_mm, max_step=max_step)
    except ConvergenceError as exc:
        kept = converged_part(exc)
        if kept is None:
            raise
        response = kept[0]
    return fem_curve(response, GEOMETRY.describe(), level)


def lifetimes(setting, stiffness, forces):
    """(largest holdable force [N], [(lifetime [s], reason)] per force) on the profile route."""
    study, uc, cup = setting
    model = _model(study, stiffness, uc, cup)
    runs = [solve_lifetime(model, F, route="profile", refine=2) for F in forces]
    return runs[0].largest_force_N, [(r.lifetime_s, r.reason) for r in runs]


def swapped(base, other, names):
    """`base` with the columns `names` of `other` interpolated (PCHIP) onto its samples."""
    keep = base.u_m <= other.u_m[-1]
    cut = dataclasses.replace(base, u_m=base.u_m[keep], F0_N=base.F0_N[keep], r_c_m=base.r_c_m[keep],
                              l_m=base.l_m[keep], V_m3=base.V_m3[keep], profiles=base.profiles[:int(keep.sum())])
    values = {n: ScalarPchip(other.u_m, getattr(other, n), n).values_and_slopes(cut.u_m)[0] for n in names}
    return dataclasses.replace(cut, **values)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", nargs="+", default=["coarse", "medium"])
    ap.add_argument("--steps", type=float, nargs="+", default=[0.05, 0.025, 0.0125, 0.00625],
                    help="largest load steps, fractions of 0.9 h1 (the first is the default)")
    ap.add_argument("--u-max-mm", type=float, default=8.466, help="the longer path's end [mm]")
    ap.add_argument("--forces", type=float, nargs="+", default=[5.0, 20.0, 50.0, 80.0], help="F1 [N]")
    ap.add_argument("--contact", default="frictionless", choices=["frictionless", "sticking"])
    args = ap.parse_args()
    study = load_scene(SCENE).study()
    products = Products(study)
    setting = (study, products.uc_table(), products.cup())
    head = " ".join(f"{f'{F:g} N [s]':>12s} {'rel.':>7s}" for F in args.forces)
    print(f"cup A, {args.contact}, profile route; rel. = lifetime / the finest step's at the default u_max - 1")
    print(f"{'level':>7s} {'step':>8s} {'u_max':>7s} {'samples':>7s} {'F_max [N]':>9s} {'CPU [s]':>7s} {head}")
    for level in args.levels:
        curves, runs = {}, {}
        for step in args.steps:
            for u_max in (None, args.u_max_mm):
                t0 = time.process_time()
                c = curves[step, u_max] = curve(level, args.contact, u_max, step)
                runs[step, u_max] = (len(c.u_m), *lifetimes(setting, c, args.forces), time.process_time() - t0)
        ref = runs[min(args.steps), None][2]
        for (step, u_max), (n, fmax, lives, cpu) in runs.items():
            cells = " ".join(f"{t:12.5g} {(t / r[0] - 1 if r[0] > 0 else float('nan')):+7.2%}"
                             + ("" if why == "reached_r1" else f" ({why})")
                             for (t, why), r in zip(lives, ref))
            print(f"{level:>7s} {step:8.5g} {'default' if u_max is None else f'{u_max:g}':>7s} {n:7d} "
                  f"{fmax:9.4g} {cpu:7.2f} {cells}")
        base, fine = curves[args.steps[0], None], curves[min(args.steps), None]
        print(f"{level}: the step-{args.steps[0]:g} curve with columns of the step-{min(args.steps):g} curve")
        for names in ([], ["F0_N"], ["r_c_m"], ["V_m3"], ["F0_N", "r_c_m", "V_m3"]):
            fmax, lives = lifetimes(setting, swapped(base, fine, names) if names else base, args.forces)
            print(f"  {'+'.join(names) or 'none':>17s} F_max {fmax:8.4g} N  "
                  + " ".join(f"{t:10.5g}" + ("" if why == "reached_r1" else f" ({why})") for t, why in lives))
        fmax, lives = lifetimes(setting, fine, args.forces)
        print(f"  {'finest curve':>17s} F_max {fmax:8.4g} N  "
              + " ".join(f"{t:10.5g}" + ("" if why == "reached_r1" else f" ({why})") for t, why in lives))
        r_c = fine.r_c_m[fine.l_m > 0]
        print(f"  finest curve's r_c where a strip is resolved: {np.count_nonzero(np.diff(r_c) > 0)} of "
              f"{r_c.size - 1} steps move the edge outwards while the cup is pressed; the largest by "
              f"{1e3 * np.max(np.diff(r_c), initial=0.0):.3g} mm")


if __name__ == "__main__":
    main()
