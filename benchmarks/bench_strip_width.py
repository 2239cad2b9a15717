"""Strip-width definitions across mesh levels: does l converge?

Cup A (E = 4 MPa, nu = 0.49), pressed to 0.9 h1 at fidelity coarse, medium and fine, with load steps
of at most 2 % of the range (so the curves are sampled alike). Prints F0, r_c and the three strip
widths of `fem.cup.CupResponse` (force-quartile l_m, the hand-off's, `fem.postprocess.quartile_width`
of the innermost contact zone; median-force l_median_m; pressure-weighted l_weighted_m;
half-maximum l_half_max_m) (all from each step's lumped nodal
pressure) at u/h1 = 0.2 ... 0.9, one row per level. Takes ~5-10 min (the fine level dominates).

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_strip_width.py [frictionless|sticking]
"""

import sys
import time

import numpy as np

from fem.cup import compress_cup
from fem.geometry import cup_geometry
from fem.material import NeoHookean
from fem.mesh import cup_mesh

QUANTITIES = (("F0_N", 1.0, "F0 [N]"), ("r_c_m", 1e3, "r_c [mm]"), ("l_weighted_m", 1e3, "l weighted [mm]"),
              ("l_half_max_m", 1e3, "l half-max [mm]"), ("l_median_m", 1e3, "l median [mm]"),
              ("l_m", 1e3, "l force-quartile [mm]"))


def main(contact: str = "frictionless") -> None:
    geometry = cup_geometry("A")
    u_over_h1 = np.array([0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9])
    u = u_over_h1 * geometry.h1_m
    rows = {}
    for fidelity in ("coarse", "medium", "fine"):
        t0 = time.perf_counter()
        resp = compress_cup(cup_mesh(geometry, fidelity), NeoHookean(4e6, 0.49), contact=contact,
                            u_max_m=0.9 * geometry.h1_m, max_step=0.02)
        values = {name: getattr(resp, name) for name, _, _ in QUANTITIES}
        rows[fidelity] = {name: np.interp(u, resp.u_m, values[name]) for name, _, _ in QUANTITIES}
        print(f"{fidelity}: {time.perf_counter() - t0:.1f} s, {resp.stats.dofs} dofs", flush=True)
    print(f"\ncup A, {contact}; columns u/h1 = " + " ".join(f"{v:.1f}" for v in u_over_h1))
    for name, scale, label in QUANTITIES:
        print(label)
        for fidelity, values in rows.items():
            print(f"  {fidelity:7s}" + "".join(f"{scale * v:9.4g}" for v in values[name]))


if __name__ == "__main__":
    main(*sys.argv[1:])
