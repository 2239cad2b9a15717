"""The table-coupled route past the touching height: cup A or B (coarse, frictionless, pmma-1.89)
from the fem route's sealed content, the table route on the default grid's table built around its
paths (raised rows evenly down to the plate's floor h1 - 2 L, `DEFAULT_GRID`), beside the fem
route, and the same with the raised rows' spacing halved (the grid's interpolation error).

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_coupled_raised.py [--half] [--cup B] [--forces 10 20 40] [--counters]

Prints the fem route's lifetimes, the table's build (states solved, CPU seconds) and per force
the table route's lifetime, how it ended, its last u, and its difference from the fem route's.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import time

import numpy as np
from scipy.optimize import brentq

import reduced
from validation.bridge.coupled.adaptive import SuctionGoal
from validation.bridge.coupled.build import DEFAULT_GRID, suction_table_for
from validation.bridge.fem_route import FemCup, register
from validation.bridge.pipeline import surface_uc_table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--half", action="store_true", help="halve the raised rows' u spacing")
    parser.add_argument("--cup", choices=("A", "B"), default="A")
    parser.add_argument("--forces", type=float, nargs="+", default=[5.0, 10.0, 20.0])
    parser.add_argument("--out", default=None, help="also write the table (JSON) here")
    parser.add_argument("--counters", action="store_true", help="the build's paths by kind (bench_coupled_counters.py)")
    args = parser.parse_args()
    model = reduced.reference_model(reduced.CUP_A if args.cup == "A" else reduced.CUP_B, surface_uc_table())
    route, cup = register(), FemCup(args.cup, "coarse")
    sealed = route.seal(model, {**route.options, "cup": cup})
    u_start = brentq(lambda u: sealed.cup.move_plate(sealed.state, u)[-1].F1_N,
                     0.3 * sealed.state.u_m, (1 - 1e-6) * sealed.state.u_m, xtol=1e-10)
    fem, hint = {}, []
    for F in args.forces:
        fem[F] = reduced.solve_lifetime(model, F, route="fem", cup=cup)
        u, dp = 1e-3 * fem[F].trajectory["u_mm"], model.p_a_Pa - fem[F].trajectory["p_b_Pa"]
        hint += list(zip(u, dp)) + [(u_start + s * (u[0] - u_start), s * dp[0]) for s in np.linspace(0, 1, 40)]
        print(f"fem route   F1 = {F:g} N: {fem[F].lifetime_s:.4g} s, {fem[F].reason}, u_end = "
              f"{fem[F].trajectory['u_mm'][-1]:.3f} mm", flush=True)
    grid = DEFAULT_GRID.halved_raised() if args.half else DEFAULT_GRID
    goal = SuctionGoal(dataclasses.replace(model, suction=None, stiffness=None), tuple(args.forces),
                       u_start_m=u_start, hint=tuple(hint), largest=False)
    t = time.process_time()
    if args.counters:
        from bench_coupled_counters import counting
    with counting(grid.raised_rows) if args.counters else contextlib.nullcontext() as counted:
        table = suction_table_for(args.cup, fidelity="coarse", goal=goal, grid=grid)
    print(f"table {table.provenance['grid']}: {table.provenance['states_solved']} states solved, "
          f"{int((~table.sealed).sum())} without a seal, {time.process_time() - t:.1f} s CPU", flush=True)
    if counted is not None:
        print(counted.report(), flush=True)
    if args.out:
        table.to_json(args.out)
    for F in args.forces:
        c = table_lifetime(model, table, F, u_start)
        print(f"table route F1 = {F:g} N: {c.lifetime_s:.4g} s, {c.reason}, u_end = "
              f"{1e3 * c.u_m[-1]:.3f} mm, {100 * (c.lifetime_s / fem[F].lifetime_s - 1):+.2f} % "
              f"from the fem route", flush=True)


def table_lifetime(model, table, force_N: float, u_start_m: float):
    """The coupled route's lifetime record on `table` released at u_start_m (its cavity's
    `lifetime`: `reduced.solve_lifetime` also gives the largest holdable force, whose path the
    table around the lifetimes' paths does not hold)."""
    from reduced.lifetime.routes import ROUTES

    route = ROUTES["coupled"]
    cavity, u_start, _ = route.cavity(dataclasses.replace(model, suction=table),
                                      {**route.options, "u_start_m": u_start_m})
    return cavity.lifetime(force_N, u_start)


if __name__ == "__main__":
    main()
