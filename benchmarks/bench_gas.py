"""Cost of the sealed cup's path with the trapped gas in the FEM (fem.trapped_gas, fem.gas_path).

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_gas.py [--levels coarse medium]
        [--laws frictionless sticking coulomb:0.5] [--branch F1_N ...] [--du-mm 0.25]

Cup A, pressed to 4 mm with the cavity open, sealed, the plate raised to 1 mm at fixed N, then
N raised by half at the held plate. Prints per mesh level and contact law, per stage, the states,
Newton iterations (per state), wall time (per state) and the end state (p_b, F1, V, r_k); a stage
that fails prints the solver's message. With --branch, then the held branch at each F1 from the
same sealed state (`fem.gas_branch.equilibrium_branch`, plate steps of --du-mm): states, Newton
iterations, wall time per state and per branch, the detachment (reason, u, N_max / N0, r_k).
"""

from __future__ import annotations

import argparse
import time

from fem.gas_branch import equilibrium_branch
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
    parser.add_argument("--branch", nargs="*", type=float, default=[], metavar="F1_N")
    parser.add_argument("--du-mm", type=float, default=0.25)
    parser.add_argument("--stages", nargs="+", default=["pressed", "pulled", "leaked"])
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
                if name not in args.stages:
                    continue
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
                if name == "pressed":
                    sealed = end
            for F1 in args.branch:
                _branch(cup, sealed, F1, args.du_mm * 1e-3)
            print(f"  total {time.perf_counter() - begin:.2f} s with the measurements")


def _branch(cup: CupWithGas, sealed, F1_N: float, du_m: float) -> None:
    """Run and print one held branch (module docstring)."""
    begin = time.perf_counter()
    try:
        b = equilibrium_branch(cup, sealed, F1_N, du_m=du_m)
    except RuntimeError as err:
        print(f"  branch F1 = {F1_N:g} N: failed after {time.perf_counter() - begin:.1f} s: {err}")
        return
    wall, s, d = time.perf_counter() - begin, b.stats, b.detachment
    n = len(b.states)
    end = (f"{b.reason} at u {d.u_m * 1e3:.4g} mm, N_max/N0 {d.N / sealed.N:.5g}, p_b "
           f"{d.p_b_Pa / 1e3:.4g} kPa, r_k {d.seal_r_m * 1e3:.4g} mm" if d is not None else b.reason)
    print(f"  branch F1 = {F1_N:g} N: {n} states, {s.steps} solves, {s.newton_iterations} Newton "
          f"iterations ({s.newton_iterations / n:.1f} per state), {s.cutbacks} cutbacks, {wall:.1f} s "
          f"({1e3 * wall / n:.0f} ms per state, measurements included); {end}")


if __name__ == "__main__":
    main()
