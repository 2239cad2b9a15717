"""Cost, results and convergence of the route "fem" (validation.bridge.fem_route): cup A pressed to
r_start = 12 mm, sealed, held at F1 along its FEM branch, per mesh level and contact law.

    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --levels coarse medium --forces 10
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --levels coarse --forces 5 10 20 40
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --levels coarse --laws frictionless \
        --forces 5 10 20 40 --du-factors 1 0.5 0.25 --jsonl study.jsonl
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --summarize study.jsonl
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --why 5 20

For each (level, law, plate step): the largest holdable force (max pull at fixed N0), then per
force the lifetime (its wall and CPU time: the CPU time is the cost on a busy machine), its
reason, the branch's states and Newton iterations, the seal radius at the start of the branch
and at its end, and where the time goes (pressing + sealing, the branch's FEM
solves, the rest: sensitivities, measurement and the leak through every state's profile). With
--jsonl every lifetime is also appended as one JSON line, with what explains it: N_max / N0, the
leak rate at the branch's start and end, the mean of 1/Q over N (lifetime = (N_max - N0) times
it), p_b, u, the seal radius and the contact band's width (cut radius less inner contact radius)
at the start and end. --summarize turns such a file into the convergence table: each lifetime
beside the one at half its plate step and the next finer mesh's at the same step, in percent.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections import defaultdict

import numpy as np

import reduced
from fem.interface import ContactLaw
from validation.bridge.fem_route import DEFAULT_DU_M, FemCup, FemRouteError, lifetime_integral, register
from validation.bridge.pipeline import surface_uc_table

LAWS = {"frictionless": ContactLaw(), "coulomb 0.5": ContactLaw("coulomb", 0.5),
        "coulomb 2": ContactLaw("coulomb", 2.0), "sticking": ContactLaw("sticking")}


def _explain(life) -> dict:
    """What the lifetime is made of: how much gas the cup takes in and how fast it comes."""
    tr, d = life.trajectory, life.details
    if not len(tr.get("N", ())):
        return {}
    N, q = np.asarray(tr["N"]), np.asarray(tr["N_dot_per_s"])
    return {"N_max_over_N0": float(N[-1] / d["N0"]), "Q_start_per_s": float(q[0]), "Q_end_per_s": float(q[-1]),
            "mean_inv_Q_s": float(lifetime_integral(N, q)[-1] / (N[-1] - N[0])) if N[-1] > N[0] else math.nan,
            "p_b_start_kPa": float(tr["p_b_Pa"][0] / 1e3), "p_b_end_kPa": float(tr["p_b_Pa"][-1] / 1e3),
            "u_start_mm": float(tr["u_mm"][0]), "u_end_mm": float(tr["u_mm"][-1]),
            "seal_r_start_mm": float(tr["seal_r_mm"][0]), "seal_r_end_mm": float(tr["seal_r_mm"][-1]),
            "width_start_mm": float(tr["r_out_mm"][0] - tr["r_c_mm"][0]),
            "width_end_mm": float(tr["r_out_mm"][-1] - tr["r_c_mm"][-1])}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--levels", nargs="+", default=["coarse"])
    ap.add_argument("--laws", nargs="+", default=["frictionless", "coulomb 0.5", "sticking"], choices=list(LAWS))
    ap.add_argument("--forces", nargs="+", type=float, default=[10.0])
    ap.add_argument("--du-mm", type=float, default=None, help="the plate step (default: the route's)")
    ap.add_argument("--du-factors", nargs="+", type=float, default=[1.0], help="multiples of the plate step")
    ap.add_argument("--no-largest", action="store_true", help="skip the largest holdable force")
    ap.add_argument("--jsonl", default=None, help="append every lifetime as a JSON line to this file")
    ap.add_argument("--summarize", default=None, help="print the convergence table of a --jsonl file")
    ap.add_argument("--why", nargs=2, type=float, default=None, metavar=("F_LOW", "F_HIGH"),
                    help="the leak of the two forces' frictionless branch states at equal N / N0, each "
                         "also at the other's p_b (the profile's share against the pressure's)")
    a = ap.parse_args()
    if a.summarize:
        summarize(a.summarize)
        return
    model = reduced.reference_model(reduced.CUP_A, surface_uc_table())
    if a.why:
        why(model, *a.why, level=a.levels[0])
        return
    du0 = DEFAULT_DU_M if a.du_mm is None else 1e-3 * a.du_mm
    print("| level | law | du [mm] | F1 [N] | lifetime [s] | reason | states | Newton it. | seal r start/end [mm] "
          "| u end [mm] | wall [s]: total / press / branch FEM / rest | largest force [N] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for level in a.levels:
        for law in a.laws:
            route = register()
            route._sealed.clear()
            cup = FemCup("A", level, contact=LAWS[law])
            t0 = time.perf_counter()
            sealed = route.seal(model, {**route.options, "cup": cup})
            t_press = time.perf_counter() - t0
            t0 = time.perf_counter()
            largest = math.nan
            if not a.no_largest:
                try:
                    largest = route.largest_force(model, {**route.options, "cup": cup})
                except Exception as err:       # reported, not hidden
                    print(f"<!-- {level} {law}: largest force failed: {err} -->")
            t_largest = time.perf_counter() - t0
            for factor in a.du_factors:
                du = factor * du0
                for F in a.forces:
                    _one(model, cup, level, law, du, F, t_press, largest, a.jsonl)
            print(f"<!-- {level} {law}: press+seal {t_press:.1f} s, largest force {t_largest:.1f} s, "
                  f"N0 = {sealed.state.N:.4e}, u_sealed = {1e3 * sealed.state.u_m:.3f} mm, "
                  f"seal r at sealing = {1e3 * sealed.state.seal_r_m:.2f} mm -->", flush=True)


def _one(model, cup, level, law, du, F, t_press, largest, jsonl) -> None:
    t0, c0 = time.perf_counter(), time.process_time()
    row = {"level": level, "law": law, "du_mm": 1e3 * du, "F1_N": F, "largest_N": largest}
    try:
        life = reduced.solve_lifetime(model, F, route="fem", cup=cup, du_m=du)
    except (FemRouteError, RuntimeError) as err:
        wall = time.perf_counter() - t0
        print(f"| {level} | {law} | {1e3 * du:g} | {F:g} | failed | {str(err)[:90]} | | | | | "
              f"{wall:.1f} | {largest:.2f} |", flush=True)
        row.update(lifetime_s=math.nan, reason=f"failed: {err}", wall_s=wall)
    else:
        wall = time.perf_counter() - t0
        d = life.details
        tr = life.trajectory
        fem = d.get("wall_time_s", 0.0)
        seal = (f"{tr['seal_r_mm'][0]:.2f} / {tr['seal_r_mm'][-1]:.2f}" if len(tr.get("N", ())) else
                f"{d['seal_r_sealed_mm']:.2f} (sealed)")
        print(f"| {level} | {law} | {1e3 * du:g} | {F:g} | {life.lifetime_s:.4g} | {life.reason} | "
              f"{d.get('states', 0)} | {d.get('newton_iterations', 0)} | {seal} | {d.get('u_final_mm', math.nan):.3f} | "
              f"{wall:.1f} / {t_press:.1f} / {fem:.1f} / {wall - fem:.1f} | {largest:.2f} |", flush=True)
        row.update(lifetime_s=life.lifetime_s, reason=life.reason, wall_s=wall, fem_s=fem,
                   states=d.get("states", 0), newton=d.get("newton_iterations", 0),
                   branch_reason=d.get("branch_reason"), **_explain(life))
    row["cpu_s"] = time.process_time() - c0       # one core: the cost on a shared machine
    if jsonl:
        with open(jsonl, "a") as f:
            f.write(json.dumps(row) + "\n")


def why(model, low: float, high: float, level: str = "coarse") -> None:
    """Why the lifetime changes with the force: at N = 1, 2, 4, 8 N0 on both frictionless branches,
    the state's p_b, seal, contact force, peak contact pressure and leak Q, and the leak of each
    state's profile at the other state's p_b (`state_leak_rate` with p_b and dp swapped)."""
    from dataclasses import replace

    from fem.gas_branch import equilibrium_branch
    from validation.bridge.fem_route import state_leak_rate

    route = register()
    sealed = route.seal(model, {**route.options, "cup": FemCup("A", level)})
    N0 = sealed.state.N
    branches = [equilibrium_branch(sealed.cup, sealed.state, F, du_m=DEFAULT_DU_M) for F in (low, high)]
    print(f"| N/N0 | p_b [kPa] | r_k [mm] | contact force [N] | peak p [kPa] | Q [1/s] | Q at the other's p_b "
          f"[1/s] |  ({low:g} N / {high:g} N)")
    print("|---|---|---|---|---|---|---|")
    for ratio in (1.0, 2.0, 4.0, 8.0):
        a, b = (br.states[int(np.argmin(np.abs(br.column("N") / N0 - ratio)))] for br in branches)
        q = [state_leak_rate(s, model, sealed.E_Pa) for s in (a, b)]
        swapped = [state_leak_rate(replace(s, p_b_Pa=o.p_b_Pa, dp_Pa=o.dp_Pa), model, sealed.E_Pa)
                   for s, o in ((a, b), (b, a))]
        print(f"| {a.N / N0:.2f} / {b.N / N0:.2f} | {a.p_b_Pa / 1e3:.1f} / {b.p_b_Pa / 1e3:.1f} | "
              f"{1e3 * a.seal_r_m:.2f} / {1e3 * b.seal_r_m:.2f} | {a.contact_force_N:.2f} / {b.contact_force_N:.2f} | "
              f"{a.profile.p_Pa.max() / 1e3:.1f} / {b.profile.p_Pa.max() / 1e3:.1f} | {q[0]:.3g} / {q[1]:.3g} | "
              f"{swapped[0]:.3g} / {swapped[1]:.3g} |", flush=True)


def summarize(path: str) -> None:
    """The convergence table of a --jsonl file: per (law, F1) the lifetime at every (level, du),
    the change from the next finer plate step and from the next finer mesh at the same step."""
    rows = [json.loads(line) for line in open(path) if line.strip()]
    by = defaultdict(dict)
    for r in rows:
        by[(r["law"], r["F1_N"])][(r["level"], round(r["du_mm"], 6))] = r
    order = {"coarse": 0, "medium": 1, "fine": 2}
    print("| law | F1 [N] | level | du [mm] | lifetime [s] | vs du/2 | vs next mesh | N_max/N0 | mean 1/Q [s] "
          "| p_b start/end [kPa] | seal r start/end [mm] | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (law, F), runs in sorted(by.items()):
        for (level, du), r in sorted(runs.items(), key=lambda kv: (order.get(kv[0][0], 9), -kv[0][1])):
            t = r["lifetime_s"]
            half = runs.get((level, round(du / 2, 6)))
            finer = [v for (lv, d), v in runs.items() if d == du and order.get(lv, 9) == order.get(level, 9) + 1]

            def pct(other):
                return f"{100 * (t / other['lifetime_s'] - 1):+.2f} %" if other and math.isfinite(t) and \
                    math.isfinite(other["lifetime_s"]) else "–"
            print(f"| {law} | {F:g} | {level} | {du:g} | {t:.4g} | {pct(half)} | {pct(finer[0] if finer else None)} "
                  f"| {r.get('N_max_over_N0', math.nan):.4f} | {r.get('mean_inv_Q_s', math.nan):.4g} "
                  f"| {r.get('p_b_start_kPa', math.nan):.1f} / {r.get('p_b_end_kPa', math.nan):.1f} "
                  f"| {r.get('seal_r_start_mm', math.nan):.2f} / {r.get('seal_r_end_mm', math.nan):.2f} "
                  f"| {r.get('wall_s', math.nan):.1f} |")


if __name__ == "__main__":
    main()
