"""Cost of the sealed cup's path with the trapped gas in the FEM (fem.trapped_gas, fem.gas_path).

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_gas.py [--levels coarse medium]
        [--laws frictionless sticking coulomb:0.5]

Cup A, pressed to 4 mm with the cavity open, sealed, the plate raised to 1 mm at fixed N, then
N raised by half at the held plate. Prints per mesh level and contact law, per stage, the states,
Newton iterations (per state), wall time (per state) and the end state (p_b, F1, V, r_k); a stage
that fails prints the solver's message.
"""

from __future__ import annotations

import argparse
import time

from fem.geometry import cup_geometry
from fem.gas_path import CupWithGas
from fem.material import NeoHookean
from fem.mesh import cup_mesh

U_PRESS_M, U_PULLED_M, N_RATIO = 4e-3, 1e-3, 1.5


def _law(text: str) -> tuple[str, float]:
    law, _, mu = text.partition(":")
    return law, float(mu) if mu else 0.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", nargs="+", default=["coarse", "medium"])
    parser.add_argument("--laws", nargs="+", default=["frictionless", "sticking", "coulomb:0.5"])
    args = parser.parse_args()
    for level in args.levels:
        mesh = cup_mesh(cup_geometry("A"), level)
        for text in args.laws:
            law, mu = _law(text)
            cup = CupWithGas.of(mesh, NeoHookean(), law, mu)
            begin = time.perf_counter()
            stages = (("pressed", lambda: cup.press(U_PRESS_M)),
                      ("pulled", lambda: cup.move_plate(states[-1], U_PULLED_M)),
                      ("leaked", lambda: cup.let_in(states[-1], N_RATIO * states[-1].N)))
            states = []
            print(f"{level} {text} ({cup.cup.mech.kin.ndofs} dofs):")
            for name, run in stages:
                try:
                    states = run()
                except RuntimeError as err:
                    print(f"  {name}: failed: {err}")
                    break
                s, end = cup.costs[-1], states[-1]
                print(f"  {name}: {s.steps} states, {s.newton_iterations} Newton iterations "
                      f"({s.newton_iterations / s.steps:.2f} per state), {s.cutbacks} cutbacks, "
                      f"{s.wall_time_s:.2f} s ({1e3 * s.wall_time_s / s.steps:.0f} ms per state); end: "
                      f"u {end.u_m * 1e3:.3g} mm, p_b {end.p_b_Pa / 1e3:.4g} kPa, F1 {end.F1_N:.4g} N, "
                      f"V {end.V_m3 * 1e9:.5g} mm^3, r_k {end.seal_r_m * 1e3:.4g} mm")
            print(f"  total {time.perf_counter() - begin:.2f} s with the measurements")


if __name__ == "__main__":
    main()
