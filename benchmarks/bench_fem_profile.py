"""Where a stiffness curve's time goes: cup A, frictionless, u = 0 .. 0.9 h1, per fidelity level;
and, with --route-forces, where one lifetime of the route "fem" goes.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_fem_profile.py [--levels coarse medium]
        [--contact frictionless] [--repeat 3] [--whole] [--route-forces 10 [--route-only]
        [--route-contact frictionless sticking "coulomb 0.5"]]

Runs `fem.cup.compress_cup` in-process (no start-up, no CSV) and prints per curve: load steps,
Newton iterations, dofs, factorizations, the in-process wall time (first call and the median of
--repeat further calls), the time per Newton iteration, and the exclusive time of each part with
its share of the wall time:

  assembly   energy, internal force and tangent (`fem.forms.Mechanics`: the element kernels, the
             CSR assembly), per evaluation;
  factor     the shifted factorizations of K_ff (`fem.factorization.ShiftPolicy.factor`, with the
             condensation of the interior nodes) and the Schur complements of freed contact
             nodes (`fem.linsolve.BorderedFactor`); its calls count the requests, a reused
             factor included (the header gives the factorizations done);
  solve      the triangular solves with those factors (whole, and `solve_at`'s on a factor's
             trailing block: Coulomb's condensed columns read at the contact rows only);
  lcp        the contact step's small LCP (non-negative least squares);
  post       the per-step outputs (`fem.cup._measure`: pressure profile, r_c, l, V, stretch) and
             the admissibility check of each converged state (`fem.integrity.check_state`);
  other      the rest: the Newton loop, line search, contact projections, convergence tests.

and, on the tangent of the last factorization of the path (its free block K_ff), the time of one
factorization by the solver itself and by scipy's sparse LU (`scipy.sparse.linalg.splu`, COLAMD
ordering): the scale of the linear algebra alone against the time per Newton iteration, and
their ratio (a Newton iteration in units of one factorization of each kind).
With --route-forces F ..., also `cupcheck lifetime --route fem --cup A --force F --fidelity LEVEL`
(per contact law of --route-contact)
in-process (the command's own work: pressing, sealing, the largest holdable force, the branch,
the leak), its CPU time per part as above plus

  cavity     the cavity volume, its gradient and Hessian (`fem.cavity.CavitySurface`);
  sens       the branch's sensitivities dF1/dN, dF1/du and the linear response that predicts
             each trial's Newton start (`fem.branch_slopes.linear_response`: one factorization of
             the held plate's free block, `fem.free_block`, outside the solver's factorizations);
  setup      building a linear solver (`fem.condensation.make_solver`'s orderings and maps);

the branch walk's solves by kind (an F1 root's first trial, Coulomb's corrections started from
it, those given up, later trials, moves outside a root) with their Newton
iterations, and the damped relax_step sub-steps inside them;

and the calls of each, the inclusive CPU time of the route's phases (pressing and sealing, the
largest holdable force's pull at fixed N, the branch at F1; the rest is the leak along it and the
states the route adds), the largest pull's Newton iterations per load step (its maximum's state,
the states and iterations before and past it, its slips and failed Newton steps), and the CPU time
per solver factorization (each Newton iteration factors once; a shifted retry or a freed contact
node adds one) against one factorization of the last tangent the route factored.
With --whole, also the whole process `cupcheck stiffness --cup A --fidelity LEVEL` (median of
--repeat runs, CPU time of the child and wall time), whose excess over the in-process curve is
start-up (imports), the mesh and the output files.
Times are the process's CPU time (`time.process_time`; one thread with OMP_NUM_THREADS=1, so on a
quiet machine the wall time, which a busy second core inflates); the wrappers cost ~1 us a call.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import io
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse.linalg as spla

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import fem.contact_step  # noqa: E402
import fem.cup  # noqa: E402
import fem.factorization  # noqa: E402
import fem.linsolve  # noqa: E402
import fem.cavity  # noqa: E402
import fem.condensation  # noqa: E402
import fem.branch_walk  # noqa: E402
from fem.cup import compress_cup  # noqa: E402
from fem.forms import Mechanics  # noqa: E402
from fem.geometry import cup_geometry  # noqa: E402
from fem.material import NeoHookean  # noqa: E402
from fem.mesh import cup_mesh  # noqa: E402

PARTS = ("assembly", "factor", "solve", "lcp", "post", "cavity", "sens", "setup")


class Clock:
    """Exclusive wall time per part: a part's time excludes that of the parts called inside it."""

    def __init__(self) -> None:
        self.stack: list[list] = []
        self.reset()

    def reset(self) -> None:
        self.time = dict.fromkeys(PARTS, 0.0)
        self.calls = dict.fromkeys(PARTS, 0)
        self.last_factor: tuple | None = None

    def wrap(self, part: str, fn):
        @functools.wraps(fn)
        def timed(*args, **kwargs):
            frame = [time.process_time(), 0.0]
            self.stack.append(frame)
            try:
                return fn(*args, **kwargs)
            finally:
                elapsed = time.process_time() - frame[0]
                self.stack.pop()
                self.time[part] += elapsed - frame[1]
                self.calls[part] += 1
                if self.stack:
                    self.stack[-1][1] += elapsed
        return timed


CLOCK = Clock()


def _instrument() -> None:
    """Wrap the functions of each part (module docstring), once."""
    w = CLOCK.wrap
    Mechanics._evaluate = w("assembly", Mechanics._evaluate)
    Mechanics.energy = w("assembly", Mechanics.energy)
    Mechanics.internal_force = w("assembly", Mechanics.internal_force)
    policy_factor = fem.factorization.ShiftPolicy.factor

    def factor(self, solver, K, free, shift):
        CLOCK.last_factor = (solver, K, free.copy())
        return policy_factor(self, solver, K, free, shift)

    fem.factorization.ShiftPolicy.factor = w("factor", factor)
    fem.linsolve.BorderedFactor.__init__ = w("factor", fem.linsolve.BorderedFactor.__init__)
    for cls in (fem.linsolve.Factor, fem.linsolve.BorderedFactor, fem.condensation.CondensedFactor):
        cls.solve = w("solve", cls.solve)
        if hasattr(cls, "solve_at"):             # (a solve exact at a few dofs only)
            cls.solve_at = w("solve", cls.solve_at)
    fem.contact_step.lcp = w("lcp", fem.contact_step.lcp)
    fem.cup._measure = w("post", fem.cup._measure)
    fem.cup.check_state = w("post", fem.cup.check_state)
    fem.cavity.CavitySurface._terms = w("cavity", fem.cavity.CavitySurface._terms)
    if hasattr(fem.branch_walk, "sensitivities"):     # (an older checkout's walk calls it directly)
        fem.branch_walk.sensitivities = w("sens", fem.branch_walk.sensitivities)
    if hasattr(fem.branch_walk, "linear_response"):   # (the sensitivities with the predictor's response)
        fem.branch_walk.linear_response = w("sens", fem.branch_walk.linear_response)
    if hasattr(fem.condensation, "_new_solver"):     # (a solver per path, uncounted, before it)
        fem.condensation._new_solver = w("setup", fem.condensation._new_solver)


PHASES: dict[str, float] = {}


def _phase(name: str, fn):
    """fn, its inclusive CPU time added to PHASES[name]."""
    @functools.wraps(fn)
    def timed(*args, **kwargs):
        t = time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            PHASES[name] = PHASES.get(name, 0.0) + time.process_time() - t
    return timed


PULL_STEPS: list[list[int]] = []
PULL_STATES: list[tuple[float, float, int, int]] = []   # (rise of the plate [m], F1 [N], Newton iterations, path);
#                                                          the first: the sealed plate's position [m] and pull
PULL_CUTS = [0]                                      # the largest pull's failed Newton steps (cut-backs)


def _count_cutbacks() -> None:
    """Count the Newton steps that fail inside the largest pull's paths (each one a cut-back or a
    relax_step's retry)."""
    import fem.solver
    newton_step = fem.solver.newton_step

    def counted(*args, **kwargs):
        try:
            return newton_step(*args, **kwargs)
        except Exception:
            if PHASES.get("_in pull"):
                PULL_CUTS[0] += 1
            raise
    fem.solver.newton_step = counted


def _counted_steps(follow):
    """follow (`fem.gas_pull`'s path follower), the Newton iterations of each of its load steps
    appended to PULL_STEPS, one list per path."""
    @functools.wraps(follow)
    def counted(*args, on_step, **kwargs):
        its = []
        PULL_STEPS.append(its)

        dofs, z = args[1](0.0)
        lift = dofs[dofs.size // 2:]           # the plate's vertical dofs: its rise and pull
        if not PULL_STATES:          # the sealed state: its plate position and pull
            PULL_STATES.append((float(z[-1]), float(np.sum(kwargs["start"].r_int[lift])), 0, 0))
        z0 = PULL_STATES[0][0]

        def step(s):
            if s.t > 0:
                its.append(s.iterations)
                PULL_STATES.append((float(args[1](s.t)[1][-1] - z0), float(np.sum(s.r_int[lift])),
                                    s.iterations, len(PULL_STEPS)))
            on_step(s)
        return follow(*args, on_step=step, **kwargs)
    return counted


BRANCH: dict[str, list[int]] = {}   # kind of solve of the branch walk -> Newton iterations of each
BRANCH_KINDS = {"first": "an F1 root's first trial (from the branch state)",
                "started": "a correction started from the last trial (`Walk._corrects`)",
                "given up": "a started correction given up and solved from the state",
                "later": "a later trial, Newton not started by Coulomb's rule (frictionless: from the last "
                         "trial's response; Coulomb: from the state: secant, regula falsi, second try)",
                "move": "outside a root: the raise at N0, the moves across jumps",
                "relax": "relax_step calls inside the walk's solves (damped sub-steps)"}


def _count_branch() -> None:
    """Count the branch walk's solves by kind (BRANCH_KINDS) and their Newton iterations."""
    import fem.solver
    walk = fem.branch_walk.Walk
    solve, root_from, unpredicted, relax = walk.solve, walk._root_from, walk._unpredicted, fem.solver.relax_step
    ctx = {"depth": 0, "trial": None, "redone": False}

    def counted_solve(self, *args, **kwargs):
        ctx["depth"] += 1
        before, t = (self.stats.newton_iterations if self.stats else 0), None
        try:
            t = solve(self, *args, **kwargs)
            return t
        finally:
            ctx["depth"] -= 1
            if ctx["depth"] == 0:
                its = (self.stats.newton_iterations if self.stats else 0) - before
                kind = ("move" if ctx["trial"] is None else "given up" if ctx["redone"] else
                        "started" if t is not None and t.predicted else
                        "first" if ctx["trial"] == 0 else "later")
                BRANCH.setdefault(kind, []).append(its)
                ctx["redone"] = False
                if ctx["trial"] is not None:
                    ctx["trial"] += 1

    def counted_root(self, *args, **kwargs):
        ctx["trial"] = 0
        try:
            return root_from(self, *args, **kwargs)
        finally:
            ctx["trial"] = None

    def counted_unpredicted(self, *args, **kwargs):
        ctx["redone"] = True
        return unpredicted(self, *args, **kwargs)

    def counted_relax(*args, **kwargs):
        out = relax(*args, **kwargs)
        if ctx["depth"]:
            BRANCH.setdefault("relax", []).append(out[3])
        return out
    walk.solve, walk._root_from, walk._unpredicted = counted_solve, counted_root, counted_unpredicted
    fem.solver.relax_step = counted_relax


def _instrument_route() -> None:
    """Time the fem route's phases (module docstring), once."""
    import fem.gas_branch
    import fem.gas_pull
    import validation.bridge.fem_route as route

    if hasattr(fem.branch_walk.Walk, "_root_from"):     # (the walk's counts, since the started corrections)
        _count_branch()

    route.FemRoute.seal = _phase("press + seal", route.FemRoute.seal)
    largest = _phase("largest pull", fem.gas_pull.largest_pull_checked)

    def flagged(*args, **kwargs):
        PHASES["_in pull"] = 1.0
        try:
            return largest(*args, **kwargs)
        finally:
            PHASES.pop("_in pull")
    fem.gas_pull.largest_pull_checked = functools.wraps(largest)(flagged)
    _count_cutbacks()
    fem.gas_pull.follow_gas_path = _counted_steps(fem.gas_pull.follow_gas_path)
    fem.gas_branch.equilibrium_branch = _phase("branch", fem.gas_branch.equilibrium_branch)


def _median_time(fn, repeat: int = 7) -> float:
    times = []
    for _ in range(repeat):
        t = time.process_time()
        fn()
        times.append(time.process_time() - t)
    return statistics.median(times)


def profile_curve(level: str, contact: str, repeat: int) -> dict:
    """One level: the first call, then `repeat` timed calls; the parts of the last one."""
    geometry = cup_geometry("A")
    mesh = cup_mesh(geometry, level)
    run = lambda: compress_cup(mesh, NeoHookean(), contact=contact,       # noqa: E731
                               u_max_m=0.9 * geometry.h1_m)
    t = time.process_time()
    run()
    first = time.process_time() - t
    walls, parts = [], []
    for _ in range(repeat):
        CLOCK.reset()
        t = time.process_time()
        resp = run()
        walls.append(time.process_time() - t)
        parts.append((dict(CLOCK.time), dict(CLOCK.calls)))
    wall = statistics.median(walls)
    i = int(np.argsort(walls)[len(walls) // 2])
    part_time, part_calls = parts[i]
    solver, K, free = CLOCK.last_factor
    own = _median_time(lambda: solver.factor(K, free))
    K_ff = K[free][:, free].tocsc()
    lu = _median_time(lambda: spla.splu(K_ff))
    s = resp.stats
    return {"level": level, "steps": s.steps, "newton": s.newton_iterations, "dofs": s.dofs,
            "factorizations": s.factorizations, "first": first, "wall": walls[i], "median": wall,
            "min": min(walls),
            "parts": part_time, "calls": part_calls, "own_factor": own, "splu": lu,
            "free": int(free.sum())}


def profile_route(level: str, force_N: float, contact: str = "frictionless") -> dict:
    """One `cupcheck lifetime --route fem` in-process: its CPU time and parts (module docstring);
    contact: a law's name, or "coulomb MU"."""
    from validation.cli import main as cli
    law = contact.split()
    law_args = ["--contact", law[0]] + (["--friction", law[1]] if len(law) > 1 else [])
    CLOCK.reset()
    PHASES.clear()
    PULL_STEPS.clear()
    PULL_STATES.clear()
    PULL_CUTS[0] = 0
    BRANCH.clear()
    t = time.process_time()
    with contextlib.redirect_stdout(io.StringIO()) as out, contextlib.redirect_stderr(io.StringIO()) as err:
        code = cli(["lifetime", "--route", "fem", "--cup", "A", "--force", f"{force_N:g}", "--fidelity", level]
                   + law_args)
    cpu = time.process_time() - t
    solver, K, free = CLOCK.last_factor
    own = _median_time(lambda: solver.factor(K, free))
    row = next((line.split() for line in out.getvalue().splitlines()
                if line.split()[:1] == [f"{force_N:g}"]), None)
    if row is None:              # no lifetime printed: the command's exit status and last message
        last = (err.getvalue().strip().splitlines() or ["?"])[-1]
        row = ["", "?", f"exit {code}: {last}"]
    largest = re.search(r"largest holdable force (\S+ N)", out.getvalue())
    return {"level": level, "force": force_N, "contact": contact, "cpu": cpu, "lifetime": row[1],
            "reason": row[2], "largest": largest.group(1) if largest else "?",
            "parts": dict(CLOCK.time), "calls": dict(CLOCK.calls), "own_factor": own,
            "phases": dict(PHASES), "pull_steps": [list(p) for p in PULL_STEPS],
            "pull_states": list(PULL_STATES), "pull_cuts": PULL_CUTS[0],
            "branch": {k: list(v) for k, v in BRANCH.items()}}


def report_route(r: dict) -> None:
    total = r["cpu"]
    print(f"\nfem route, cup A {r['level']}, {r['contact']}, F1 = {r['force']:g} N: lifetime {r['lifetime']} s "
          f"({r['reason']}), largest holdable force {r['largest']}; in-process CPU time {total:.2f} s")
    phases = r["phases"]
    rest = total - sum(phases.values())
    print("  phases: " + ", ".join(f"{k} {v:.2f} s" for k, v in phases.items()) + f", rest {rest:.2f} s")
    pull = r["pull_steps"]
    print(f"  largest pull: {sum(map(len, pull))} load steps, {sum(map(sum, pull))} Newton iterations; per step "
          f"(a path per group): " + " | ".join(" ".join(map(str, p)) for p in pull))
    _report_pull(r)
    if r["branch"]:
        print("  branch walk (the route's whole: the branch, its refinement): solves / Newton iterations "
              "(per solve: most common, largest) by kind:")
        for kind, its in r["branch"].items():
            common = max(set(its), key=its.count)
            print(f"    {kind:10} {len(its):4d} / {sum(its):5d} ({common}, {max(its)})  {BRANCH_KINDS[kind]}")
    per = total / r["calls"]["factor"]
    print(f"  per solver factorization (~ per Newton iteration) {1e3 * per:.2f} ms; one factorization of the "
          f"last tangent {1e3 * r['own_factor']:.2f} ms: a Newton iteration costs {per / r['own_factor']:.1f} of them")
    print(f"  {'part':9} {'time/s':>7} {'share':>6} {'calls':>6} {'per call/ms':>11}")
    for part in PARTS + ("other",):
        t = r["parts"].get(part, total - sum(r["parts"].values()))
        calls = r["calls"].get(part, 0)
        per_call = f"{1e3 * t / calls:11.3f}" if calls else f"{'':11}"
        print(f"  {part:9} {t:7.3f} {t / total:6.1%} {calls:6d} {per_call}")


def _report_pull(r: dict) -> None:
    """Where the largest pull's Newton iterations go: the states before its maximum and past it
    (the search goes on until the pull has fallen by 2 % since the last slip), the slips (a fall of
    more than 2 % of the largest pull in one step) and the failed Newton steps."""
    states = sorted(r["pull_states"][1:])      # by the plate's rise (a scout's filled steps in their place)
    if not states:
        return
    F, its = [s[1] for s in states], [s[2] for s in states]
    k = int(np.argmax(F))
    slips = sum(1 for a, b in zip(F, F[1:]) if a - b > 0.02 * F[k])
    print(f"    its maximum {F[k]:.4f} N at state {k + 1} of {len(F)} (the plate {1e3 * states[k][0]:.3f} mm above "
          f"the sealed one); before it {k + 1} states / {sum(its[:k + 1])} Newton iterations, past it "
          f"{len(F) - k - 1} / {sum(its[k + 1:])}; {slips} slips; {r['pull_cuts']} failed Newton steps")


def whole_process(level: str, contact: str, repeat: int) -> tuple[float, float]:
    """(CPU, wall) [s] of `cupcheck stiffness` for cup A at `level`, the medians of `repeat` runs."""
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root), "OMP_NUM_THREADS": "1"}
    cpu, wall = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeat):
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            t = time.perf_counter()
            subprocess.run([sys.executable, "-m", "validation.cli", "stiffness", "--cup", "A",
                            "--fidelity", level, "--contact", contact, "--out",
                            str(Path(tmp) / "curve.csv")], cwd=root, env=env, check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            wall.append(time.perf_counter() - t)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    return statistics.median(cpu), statistics.median(wall)


def report(r: dict) -> None:
    n = r["newton"]
    print(f"\ncup A {r['level']}: {r['steps']} steps, {n} Newton iterations, {r['dofs']} dofs "
          f"({r['free']} free at the end), {r['factorizations']} factorizations")
    print(f"  in-process CPU time: first call {r['first']:.3f} s, median {r['median']:.3f} s "
          f"(min {r['min']:.3f} s); "
          f"per Newton iteration {1e3 * r['wall'] / n:.2f} ms")
    print(f"  one factorization of the last tangent's K_ff: the solver's own {1e3 * r['own_factor']:.2f} ms, "
          f"scipy splu {1e3 * r['splu']:.2f} ms; a Newton iteration costs "
          f"{r['wall'] / n / r['own_factor']:.1f} of the former, {r['wall'] / n / r['splu']:.2f} of the latter")
    print(f"  {'part':9} {'time/s':>7} {'share':>6} {'calls':>6} {'per call/ms':>11} {'per iteration/ms':>16}")
    total = r["wall"]
    for part in PARTS[:5] + ("other",):
        t = r["parts"].get(part, total - sum(r["parts"].values()))
        calls = r["calls"].get(part, 0)
        per_call = f"{1e3 * t / calls:11.3f}" if calls else f"{'':11}"
        print(f"  {part:9} {t:7.3f} {t / total:6.1%} {calls:6d} {per_call} {1e3 * t / n:16.2f}")
    if "whole_cpu" in r:
        print(f"  whole process (cupcheck stiffness): CPU {r['whole_cpu']:.3f} s, wall {r['whole_wall']:.3f} s; "
              f"beyond the curve (start-up, mesh, output): CPU {r['whole_cpu'] - r['median']:.3f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", nargs="+", default=["coarse", "medium"])
    ap.add_argument("--contact", default="frictionless", choices=["frictionless", "sticking"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--whole", action="store_true", help="also time the whole cupcheck process")
    ap.add_argument("--route-forces", nargs="*", type=float, default=[],
                    help="also profile one fem route lifetime per force [N] and level")
    ap.add_argument("--route-only", action="store_true", help="skip the stiffness curves")
    ap.add_argument("--route-contact", nargs="+", default=["frictionless"],
                    help='the route\'s contact laws: frictionless, sticking, "coulomb MU"')
    args = ap.parse_args()
    _instrument()
    if args.route_forces:
        _instrument_route()
    for level in args.levels:
        if not args.route_only:
            r = profile_curve(level, args.contact, args.repeat)
            if args.whole:
                r["whole_cpu"], r["whole_wall"] = whole_process(level, args.contact, args.repeat)
            report(r)
        for force in args.route_forces:
            for contact in args.route_contact:
                report_route(profile_route(level, force, contact))


if __name__ == "__main__":
    main()
