"""Where a fem-route branch stops: the held set's changes, iteration by iteration, in every load
step that fails on the way (cup A, coarse, pmma-1.89, the largest pull skipped).

    OMP_NUM_THREADS=1 python benchmarks/bench_branch_stops.py sticking --force 20
    OMP_NUM_THREADS=1 python benchmarks/bench_branch_stops.py "coulomb 10" --force 10 --budget 1000
    OMP_NUM_THREADS=1 python benchmarks/bench_branch_stops.py frictionless --force 10 --trajectory 2 5

Each change is (mesh node, position along the cavity chain or -1 off it, on/off, r [mm], z [mm]).
--budget sets `fem.newton._BUDGET` (a damped motion's iterations, in the path's iteration caps);
--trajectory U0 U1 prints the branch states with U0 <= u <= U1 mm of a run that ends.
"""

from __future__ import annotations

import argparse

import numpy as np

import fem.contact as contact
import fem.newton as newton
import fem.solver as solver
import reduced
from fem.failure import StepFailure
from fem.interface import ContactLaw
from fem.mesh import boundary_path
from validation.bridge import fem_route
from validation.bridge.pipeline import surface_uc_table


def _logging(shown: set[int]) -> None:
    """Wrap the plane's hold and the Newton step: record the held set's changes per iteration and
    print them for the failures numbered in `shown`."""
    log, fails, chains = [], [0], {}
    hold, step = contact.RigidPlane.hold, solver.newton_step

    def logged_hold(plane, state, active, u, *args, **kwargs):
        new = hold(plane, state, active, u, *args, **kwargs)
        if id(plane.kin.mesh) not in chains:
            chains[id(plane.kin.mesh)] = {int(n): i for i, n in enumerate(boundary_path(plane.kin.mesh, "cavity"))}
        at, X = chains[id(plane.kin.mesh)], plane.kin.node_coordinates()
        log.append([(int(n), at.get(int(n), -1), "on" if new.active[i] else "off",
                     round(float(1e3 * (X[0, n] + u[2 * n])), 3), round(float(1e3 * (X[1, n] + u[2 * n + 1])), 4))
                    for i, n in ((i, plane.nodes[i]) for i in np.flatnonzero(new.active != state.active))])
        return new

    def logged_step(*args, **kwargs):
        log.clear()
        try:
            return step(*args, **kwargs)
        except StepFailure as fail:
            fails[0] += 1
            if fails[0] in shown:
                print(f"failure {fails[0]} (t = {args[6]:.5g}): {str(fail)[:160]}")
                print("  held set's changes per iteration:", [c for c in log if c][:40], flush=True)
            raise
    contact.RigidPlane.hold = logged_hold
    solver.newton_step = logged_step


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("law", help='"frictionless", "sticking" or "coulomb MU"')
    ap.add_argument("--force", type=float, default=10.0, help="F1 [N]")
    ap.add_argument("--du-mm", type=float, default=1e3 * fem_route.DEFAULT_DU_M)
    ap.add_argument("--budget", type=int, default=newton._BUDGET)
    ap.add_argument("--show", type=int, nargs="+", default=[1, 2, 3, 10, 20, 40, 60, 100],
                    help="which failures to print (numbered from 1)")
    ap.add_argument("--trajectory", type=float, nargs=2, metavar=("U0", "U1"))
    a = ap.parse_args()
    newton._BUDGET = a.budget
    _logging(set(a.show))
    name, *mu = a.law.split()
    cup = fem_route.FemCup("A", "coarse", contact=ContactLaw(name, *map(float, mu)))
    model = reduced.reference_model(reduced.CUP_A, surface_uc_table())
    try:
        life = reduced.solve_lifetime(model, a.force, route="fem", cup=cup, du_m=1e-3 * a.du_mm, largest=False)
    except fem_route.FemRouteError as err:
        print(f"{a.law}, {a.force:g} N: {err}")
        return
    print(f"{a.law}, {a.force:g} N: {life.lifetime_s:.6g} s, {life.reason}")
    if a.trajectory:
        tr = dict(life.trajectory)
        N0 = life.details["N0"]
        print("u [mm] | N/N0 | p_b [kPa] | r_c [mm] | seal r_k [mm] | r_out [mm] | t [s]")
        for i in np.flatnonzero((tr["u_mm"] >= a.trajectory[0]) & (tr["u_mm"] <= a.trajectory[1])):
            print(f"{tr['u_mm'][i]:.3f} | {tr['N'][i] / N0:.3f} | {1e-3 * tr['p_b_Pa'][i]:.2f} | {tr['r_c_mm'][i]:.2f} | "
                  f"{tr['seal_r_mm'][i]:.2f} | {tr['r_out_mm'][i]:.2f} | {tr['t_s'][i]:.4g}")


if __name__ == "__main__":
    main()
