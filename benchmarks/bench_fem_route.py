"""Cost, results and convergence of the route "fem" (validation.bridge.fem_route): cup A pressed to
r_start = 12 mm, sealed, held at F1 along its FEM branch, per mesh level and contact law.

    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --levels coarse medium --forces 10
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --levels coarse --forces 5 10 20 40
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --levels coarse --laws frictionless \
        --forces 5 10 20 40 --du-factors 1 0.5 0.25 --jsonl study.jsonl
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --summarize study.jsonl
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --why 5 20
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --seal 5 10 20 40 --levels coarse medium fine \
        --laws "coulomb 0.5" --jsonl benchmarks/fem_route_mesh_study.jsonl
    OMP_NUM_THREADS=1 python benchmarks/bench_fem_route.py --mesh-study --levels coarse medium fine \
        --laws frictionless "coulomb 0.5" --forces 5 10 20 40 --jsonl benchmarks/fem_route_mesh_study.jsonl

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
--mesh-study runs the (level, law, force) lifetimes missing from the --jsonl file (a level is a
fidelity name or an intermediate mesh "N_ALONGxN_THROUGH" with the levels' grading), then prints
the mesh study: per law and force each level's lifetime, the converged estimate (Richardson from
the three finest levels where they converge monotonically, else the finest level) and each
level's error against it, and the coarsest level within 1 % wherever every level has a lifetime.
--seal F1 [F1 ...] splits each level's lifetime at each F1 at N = 8 N0 (before the seal narrows to
a few nodes), read from the lumped profile and as the route reads it (validation.bridge.fem_leak),
on the same states; with --jsonl it appends the route's lifetimes (and their CPU) for --mesh-study.
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
from fem.mesh import FIDELITIES, mesh_spec
from validation.bridge.fem_route import DEFAULT_DU_M, FemCup, FemRouteError, Press, lifetime_integral, register
from validation.bridge.pipeline import surface_uc_table

LAWS = {"frictionless": ContactLaw(), "coulomb 0.3": ContactLaw("coulomb", 0.3),
        "coulomb 0.5": ContactLaw("coulomb", 0.5),
        "coulomb 1": ContactLaw("coulomb", 1.0), "coulomb 2": ContactLaw("coulomb", 2.0),
        "coulomb 5": ContactLaw("coulomb", 5.0), "coulomb 10": ContactLaw("coulomb", 10.0),
        "coulomb 20": ContactLaw("coulomb", 20.0), "sticking": ContactLaw("sticking")}


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


def fem_cup(level: str, law: str) -> FemCup:
    """Cup A at a mesh level: a fidelity name or "N_ALONGxN_THROUGH" (the levels' grading)."""
    if level in FIDELITIES:
        return FemCup("A", level, contact=LAWS[law])
    n_along, n_through = (int(n) for n in level.split("x"))
    return FemCup("A", mesh_spec("coarse", n_along=n_along, n_through=n_through), contact=LAWS[law])


def _elements(level: str) -> int:
    spec = FIDELITIES[level] if level in FIDELITIES else fem_cup(level, "frictionless").fidelity
    return spec.n_along * spec.n_through


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--levels", nargs="+", default=["coarse"],
                    help="mesh levels: coarse, medium, fine or N_ALONGxN_THROUGH (e.g. 108x12)")
    ap.add_argument("--laws", nargs="+", default=["frictionless", "coulomb 0.5", "sticking"], choices=list(LAWS))
    ap.add_argument("--forces", nargs="+", type=float, default=[10.0])
    ap.add_argument("--du-mm", type=float, default=None, help="the plate step (default: the route's)")
    ap.add_argument("--du-factors", nargs="+", type=float, default=[1.0], help="multiples of the plate step")
    ap.add_argument("--press-u-mm", type=float, default=None,
                    help="press the cup to this plate displacement [mm] instead of to r_start")
    ap.add_argument("--no-largest", action="store_true", help="skip the largest holdable force")
    ap.add_argument("--jsonl", default=None, help="append every lifetime as a JSON line to this file")
    ap.add_argument("--summarize", default=None, help="print the convergence table of a --jsonl file")
    ap.add_argument("--mesh-study", action="store_true",
                    help="run the lifetimes missing from --jsonl, then print the mesh study (module docstring)")
    ap.add_argument("--seal", nargs="+", type=float, default=None, metavar="F1",
                    help="the seal diagnosis at each F1 per level (seal_diagnosis): the lifetime until "
                         "N = 8 N0 and after, read from the lumped profile and as the route reads it; "
                         "with --jsonl the route's lifetimes are appended")
    ap.add_argument("--why", nargs=2, type=float, default=None, metavar=("F_LOW", "F_HIGH"),
                    help="the leak of the two forces' frictionless branch states at equal N / N0, each "
                         "also at the other's p_b (the profile's share against the pressure's)")
    a = ap.parse_args()
    if a.summarize:
        summarize(a.summarize)
        return
    if a.mesh_study and not a.jsonl:
        ap.error("--mesh-study: needs --jsonl FILE (the study's lifetimes, reused where present)")
    for level in a.levels:                        # a bad level fails here, before any run
        try:
            fem_cup(level, "frictionless")
        except ValueError:
            ap.error(f"--levels: expected coarse, medium, fine or N_ALONGxN_THROUGH, got {level!r}")
    model = reduced.reference_model(reduced.CUP_A, surface_uc_table())
    if a.why:
        why(model, *a.why, level=a.levels[0])
        return
    du0 = DEFAULT_DU_M if a.du_mm is None else 1e-3 * a.du_mm
    if a.seal is not None:
        for law in a.laws:
            for f in a.du_factors:
                seal_diagnosis(model, a.seal, a.levels, law, du_m=f * du0, jsonl=a.jsonl)
        return
    press = None if a.press_u_mm is None else Press("u_m", 1e-3 * a.press_u_mm)
    done = _done(a.jsonl) if a.mesh_study else set()
    print("| level | law | du [mm] | F1 [N] | lifetime [s] | reason | states | Newton it. | seal r start/end [mm] "
          "| u end [mm] | wall [s]: total / press / branch FEM / rest | largest force [N] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for level in a.levels:
        for law in a.laws:
            todo = [(f * du0, F) for f in a.du_factors for F in a.forces
                    if _key(level, law, 1e3 * f * du0, F, a.press_u_mm) not in done]
            if not todo:
                continue
            route = register()
            route._sealed.clear()
            cup = fem_cup(level, law)
            options = {**route.options, "cup": cup, "press": press}
            t0 = time.perf_counter()
            sealed = route.seal(model, options)
            t_press = time.perf_counter() - t0
            t0 = time.perf_counter()
            largest, partial = math.nan, None
            if not a.no_largest:
                try:
                    largest, partial = route._largest_checked(model, options)
                except Exception as err:       # reported, not hidden
                    print(f"<!-- {level} {law}: largest force failed: {err} -->")
            t_largest = time.perf_counter() - t0
            for du, F in todo:
                _one(model, cup, level, law, du, F, t_press, largest, a.jsonl, press, partial)
            print(f"<!-- {level} {law}: press+seal {t_press:.1f} s, largest force {t_largest:.1f} s, "
                  f"N0 = {sealed.state.N:.4e}, u_sealed = {1e3 * sealed.state.u_m:.3f} mm, "
                  f"seal r at sealing = {1e3 * sealed.state.seal_r_m:.2f} mm -->", flush=True)
    if a.mesh_study:
        mesh_study(a.jsonl, a.levels, a.laws, a.forces, 1e3 * du0, a.press_u_mm)


def _one(model, cup, level, law, du, F, t_press, largest, jsonl, press=None, partial=None) -> None:
    t0, c0 = time.perf_counter(), time.process_time()
    row = {"level": level, "law": law, "du_mm": 1e3 * du, "F1_N": F, "largest_N": largest,
           "largest_lower_bound": partial is not None, "press_u_mm": None if press is None else 1e3 * press.value}
    try:
        life = reduced.solve_lifetime(model, F, route="fem", cup=cup, du_m=du, press=press,
                                      largest=math.isfinite(largest) or partial is not None)
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
                   branch_reason=d.get("branch_reason"), N0=d["N0"], u_sealed_mm=d["u_sealed_mm"],
                   seal_r_sealed_mm=d["seal_r_sealed_mm"], **_explain(life))
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
        plane = sealed.cup.cup.plane
        q = [state_leak_rate(s, model, sealed.E_Pa, plane=plane) for s in (a, b)]
        swapped = [state_leak_rate(replace(s, p_b_Pa=o.p_b_Pa, dp_Pa=o.dp_Pa), model, sealed.E_Pa, plane=plane)
                   for s, o in ((a, b), (b, a))]
        print(f"| {a.N / N0:.2f} / {b.N / N0:.2f} | {a.p_b_Pa / 1e3:.1f} / {b.p_b_Pa / 1e3:.1f} | "
              f"{1e3 * a.seal_r_m:.2f} / {1e3 * b.seal_r_m:.2f} | {a.contact_force_N:.2f} / {b.contact_force_N:.2f} | "
              f"{a.profile.p_Pa.max() / 1e3:.1f} / {b.profile.p_Pa.max() / 1e3:.1f} | {q[0]:.3g} / {q[1]:.3g} | "
              f"{swapped[0]:.3g} / {swapped[1]:.3g} |", flush=True)


READINGS = {"lumped profile": {"lone_by_reaction": False},
            "route (lone node by its reaction)": {}}


def seal_diagnosis(model, forces: list[float], levels: list[str], law: str = "frictionless", split: float = 8.0,
                   du_m: float = DEFAULT_DU_M, jsonl: str | None = None) -> None:
    """Where the mesh moves the lifetime at each force under `law`: per level, the time until
    N = split N0 (before any level's seal has narrowed to a few nodes) and after it, read in the
    two ways of READINGS (`validation.bridge.fem_leak`) on the same branch states (refined as
    the route refines them, with its reading: the route's lifetime); and at the first state whose
    contact is one node (the rim corner alone) its N, the corner's reaction and the lumped
    profile's force over its neighbours' radii. With jsonl, the route's lifetime per (level,
    force) is appended as --jsonl rows (no trajectory fields), with its CPU time."""
    from fem.branch_end import up_to_most_gas
    from fem.gas_branch import equilibrium_branch, state_between
    from reduced.profile_leak import ContactProfile
    from validation.bridge.fem_leak import seal_load, state_leak_rate
    from validation.bridge.fem_route import refine_branch

    print(f"| level | F1 [N] | reading | lifetime [s] | until {split:g} N0 [s] | after [s] | one node from N/N0 "
          f"| corner reaction [N] | lumped profile's force [N] | CPU [s] |  ({law}, du = {1e3 * du_m:g} mm)")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for level in levels:
        route = register()
        sealed = route.seal(model, {**route.options, "cup": fem_cup(level, law)})
        plane = sealed.cup.cup.plane
        for F in forces:
            c0 = time.process_time()
            leak = lambda s: state_leak_rate(s, model, sealed.E_Pa, plane=plane)  # noqa: E731
            branch = equilibrium_branch(sealed.cup, sealed.state, F, du_m=du_m)
            kept = up_to_most_gas(branch.states) if branch.reason == "fold" else list(branch.states)
            states, q, _ = refine_branch(sealed.cup, kept, [leak(s) for s in kept], F, leak, state_between)
            cpu = time.process_time() - c0
            N = np.array([s.N for s in states])
            loads = [seal_load(s, plane) for s in states]
            lone = [k for k, ld in enumerate(loads) if ld.rings_r_m.size == 1 and not np.any(ld.p_Pa)]
            k = lone[0] if lone else len(states) - 1
            s = states[k]
            corner = float(np.sum(plane.held_reactions(s.state)[1])) if lone else math.nan
            profile_force = ContactProfile(s.profile.r_m, s.profile.p_Pa).force_N if s.profile.r_m.size > 1 else 0.0
            for name, how in READINGS.items():
                rate = q if not how else np.array([state_leak_rate(x, model, sealed.E_Pa, plane=plane, **how)
                                                   for x in states])
                t = lifetime_integral(N, rate)
                until = float(np.interp(split * N[0], N, t))
                print(f"| {level} | {F:g} | {name} | {t[-1]:.4g} | {until:.4g} | {t[-1] - until:.4g} "
                      f"| {N[k] / N[0]:.3f} | {corner:.3f} | {profile_force:.3f} | {cpu:.1f} |", flush=True)
            if jsonl:
                t = lifetime_integral(N, q)
                reason = "fold" if branch.reason == "fold" else "reached_r1"
                row = {"level": level, "law": law, "du_mm": 1e3 * du_m, "F1_N": F, "largest_N": math.nan,
                       "largest_lower_bound": False, "press_u_mm": None, "lifetime_s": float(t[-1]),
                       "reason": reason, "states": len(states), "N0": float(N[0]),
                       "N_max_over_N0": float(N[-1] / N[0]), "cpu_s": cpu, "from": "--seal"}
                with open(jsonl, "a") as f:
                    f.write(json.dumps(row) + "\n")


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


def _key(level: str, law: str, du_mm: float, F: float, press_u_mm: float | None) -> tuple:
    return (level, law, round(du_mm, 6), float(F),
            None if press_u_mm is None else round(press_u_mm, 6))


def _rows(path: str) -> list[dict]:
    try:
        with open(path) as f:
            return [json.loads(line) for line in f if line.strip()]
    except FileNotFoundError:
        return []


def _done(path: str) -> set:
    return {_key(r["level"], r["law"], r["du_mm"], r["F1_N"], r.get("press_u_mm")) for r in _rows(path)}


#: the lifetime's tolerance the default mesh level is chosen for
MESH_TOL = 0.01


def converged_estimate(by_level: dict[str, float]) -> tuple[float, str]:
    """The converged lifetime from the nested levels coarse, medium, fine (ratio 2): Richardson
    with the observed order p = log2((L_m - L_c) / (L_f - L_m)) where the three change
    monotonically and 0.5 <= p <= 4 (a clear asymptotic order), else the finest level's value.
    (estimate, how: "Richardson p=..." or the finest level's name)."""
    c, m, f = (by_level.get(k, math.nan) for k in ("coarse", "medium", "fine"))
    if all(map(math.isfinite, (c, m, f))) and (m - c) * (f - m) > 0:
        p = math.log2((m - c) / (f - m))
        if 0.5 <= p <= 4.0:
            return f + (f - m) / (2.0 ** p - 1.0), f"Richardson p = {p:.2f}"
    finite = [k for k in sorted(by_level, key=_elements) if math.isfinite(by_level[k])]
    return (by_level[finite[-1]], finite[-1]) if finite else (math.nan, "none")


def mesh_study(path: str, levels: list[str], laws: list[str], forces: list[float], du_mm: float,
               press_u_mm: float | None) -> None:
    """The mesh study of a --jsonl file (module docstring): per law and force (and the largest
    holdable force) each level's value and its error against the converged estimate; each level's
    largest error and mean CPU time per lifetime; the coarsest level within MESH_TOL everywhere."""
    rows = {_key(r["level"], r["law"], r["du_mm"], r["F1_N"], r.get("press_u_mm")): r for r in _rows(path)}
    levels = sorted(levels, key=_elements)
    press = "r_start" if press_u_mm is None else f"u = {press_u_mm:g} mm"
    print(f"\nMesh study: cup A, pmma-1.89, du = {du_mm:g} mm, pressed to {press}; lifetimes [s] "
          f"(error against the estimate)\n")
    print("| law | F1 [N] | " + " | ".join(levels) + " | estimate | from |")
    print("|---|---|" + "---|" * len(levels) + "---|---|")
    worst: dict[str, float] = {}
    where = {lv: [] for lv in levels}
    cpu = defaultdict(list)
    for law in laws:
        cases = [(f"{F:g}", {lv: rows.get(_key(lv, law, du_mm, F, press_u_mm)) for lv in levels}) for F in forces]
        largest = {}
        for lv in levels:
            r = next((r for (lv2, law2, _, _, pr), r in rows.items()
                      if (lv2, law2, pr) == (lv, law, press_u_mm) and math.isfinite(r.get("largest_N", math.nan))),
                     None)
            largest[lv] = r and {"lifetime_s": r["largest_N"], "reason": "largest",
                                 "lower_bound": r.get("largest_lower_bound", False)}
        cases.append(("largest", largest))
        for label, runs in cases:
            bound = {lv for lv, r in runs.items() if (r or {}).get("lower_bound")}
            vals = {lv: math.nan if lv in bound else (r or {}).get("lifetime_s", math.nan) for lv, r in runs.items()}
            vals = {lv: v if v is not None and math.isfinite(v) else math.nan for lv, v in vals.items()}
            est, how = converged_estimate(vals)
            cells = []
            for lv in levels:
                v = vals[lv]
                if label != "largest" and runs[lv] is not None and "cpu_s" in runs[lv]:
                    cpu[lv].append(runs[lv]["cpu_s"])
                if lv in bound:
                    cells.append(f">= {runs[lv]['lifetime_s']:.4g} (the solver stopped)")
                    continue
                if not math.isfinite(v):
                    reason = (runs[lv] or {}).get("reason", "not run")
                    cells.append("failed" if str(reason).startswith("failed") else reason)
                    continue
                err = v / est - 1.0 if math.isfinite(est) else math.nan
                cells.append(f"{v:.4g} ({100 * err:+.2f} %)" if how != lv else f"{v:.4g}")
                if how != lv and math.isfinite(err):
                    worst[lv] = max(worst.get(lv, 0.0), abs(err))
                    if abs(err) > MESH_TOL:
                        where[lv].append(f"{law} {label}")
            unit = " N" if label == "largest" else ""
            print(f"| {law} | {label} | " + " | ".join(cells) + f" | {est:.4g}{unit} | {how} |")
    print("\n| level | elements | largest error | over 1 % at | mean CPU per lifetime [s] |")
    print("|---|---|---|---|---|")
    for lv in levels:
        c = cpu.get(lv, [])
        err = f"{100 * worst[lv]:.2f} %" if lv in worst else "– (the estimate)"
        print(f"| {lv} | {_elements(lv)} | {err} | {', '.join(where[lv]) or '–'} | "
              f"{np.mean(c) if c else math.nan:.1f} |")
    within = [lv for lv in levels if lv in worst and not where[lv]]
    print(f"\nCoarsest level within {100 * MESH_TOL:g} % of the estimate everywhere: "
          f"{within[0] if within else 'none below the finest'}")


if __name__ == "__main__":
    main()
