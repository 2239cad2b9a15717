"""How many of the main job's printed digits a round-off change in the FEM may move: the profile
route's lifetimes on the main job's curve, and on the same curve with each contact pressure
multiplied by (1 + 1e-12 N(0, 1)), at the integrator's default tolerance and a tighter one.

    OMP_NUM_THREADS=1 python benchmarks/bench_profile_reproducibility.py [--forces 5 20 55] [--rtol 1e-6 1e-9]

A change of 1e-12 in the input (what any reordering of the FEM's floating-point work gives) moves
the adaptive integrator's step sequence (the number of output points differs) and with it the
lifetime by up to the integrator's own error: so a main job's lifetime_vs_force.csv is reproduced
to its 10 printed digits only by bit-identical FEM output, and the tighter tolerance shows how far
the default one is from the converged value.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

from reduced.lifetime import solve_lifetime
from reduced.profile_leak import ContactProfile
from validation.bridge.products import Products, _model
from validation.scenes.schema import load_scene

SCENE = Path(__file__).resolve().parents[1] / "scenes" / "main.toml"


def perturbed(model, size: float, seed: int = 1):
    """The model with its curve's contact pressures multiplied by (1 + size N(0, 1))."""
    rng = np.random.default_rng(seed)
    curve = model.stiffness
    profiles = [None if p is None else ContactProfile(p.r_m, p.p_Pa * (1.0 + size * rng.normal(size=p.p_Pa.size)))
                for p in curve.profiles]
    return dataclasses.replace(model, stiffness=dataclasses.replace(curve, profiles=profiles))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--forces", type=float, nargs="+", default=[5.0, 20.0, 55.0], help="F1 [N]")
    ap.add_argument("--rtol", type=float, nargs="+", default=[1e-6, 1e-9], help="integrator tolerances")
    ap.add_argument("--size", type=float, default=1e-12, help="relative size of the perturbation")
    args = ap.parse_args()
    study = load_scene(SCENE).study()
    products = Products(study)
    model = _model(study, products.curve(), products.uc_table(), products.cup())
    other = perturbed(model, args.size)
    print(f"{'rtol':>7s} {'F1 [N]':>7s} {'lifetime [s]':>14s} {'perturbed [s]':>14s} {'rel. change':>11s}"
          f" {'rel. to tightest rtol':>21s}")
    tightest = min(args.rtol)
    for F in args.forces:
        runs = {rtol: [solve_lifetime(dataclasses.replace(m), F, route="profile", refine=2, rtol=rtol).lifetime_s
                       for m in (model, other)] for rtol in sorted(args.rtol, reverse=True)}
        for rtol, (t, tp) in runs.items():
            print(f"{rtol:7.0e} {F:7g} {t:14.10g} {tp:14.10g} {tp / t - 1:+11.1e} {t / runs[tightest][0] - 1:+21.1e}")


if __name__ == "__main__":
    main()
