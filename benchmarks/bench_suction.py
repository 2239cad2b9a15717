"""Cost and content of the cup's (u, dp) suction grid (fem.suction), the FEM input of the coupled
cavity route (issue 12, section 2).

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_suction.py [--levels coarse medium]

Prints per mesh level the wall time, Newton iterations and cutbacks of the grid u = 0.5 ... 7 mm x
dp = 0 ... 100 kPa on cup A (frictionless), the pull on the handle F1(u, dp), and the largest
residual of the global balance F1 + N = dp pi r_k^2 relative to dp pi r_k^2.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from fem.geometry import cup_geometry
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from fem.suction import suction_grid

U_MM = [0.5, 1.0, 2.0, 3.0, 5.0, 7.0]
DP_KPA = [0.0, 20.0, 40.0, 60.0, 80.0, 100.0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", nargs="+", default=["coarse", "medium"])
    args = parser.parse_args()
    np.set_printoptions(precision=2, suppress=True, linewidth=120)
    for level in args.levels:
        mesh = cup_mesh(cup_geometry("A"), level)
        start = time.perf_counter()
        g = suction_grid(mesh, NeoHookean(), u_m=np.array(U_MM) * 1e-3, dp_Pa=np.array(DP_KPA) * 1e3)
        wall = time.perf_counter() - start
        suction = g.dp_Pa * np.pi * g.seal_r_m**2
        balance = np.max(np.abs(g.F1_N + g.contact_force_N - suction)[:, 1:] / suction[:, 1:])
        print(f"{level}: {wall:.1f} s, {g.stats.newton_iterations} Newton iterations, "
              f"{g.stats.cutbacks} cutbacks, {g.stats.dofs} dofs; balance residual {balance:.1e}")
        print(f"  F1 [N], rows u = {U_MM} mm, columns dp = {DP_KPA} kPa:")
        print(g.F1_N)
        print("  V_cav [mm^3]:")
        print(g.V_m3 * 1e9)
        print("  seal radius r_k [mm]:")
        print(g.seal_r_m * 1e3)


if __name__ == "__main__":
    main()
