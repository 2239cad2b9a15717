"""Section 8: the cup's whole life in the FEM, with friction at the seal.

Cups A and B on pmma-1.89 on the route "fem" (`validation.bridge.fem_route`): the FEM cup pressed to
the paper's r_start with the gas escaping, sealed, pulled to F1 and held there along its
equilibrium branch while the gas leaks in through each state's own contact-pressure profile, until
the branch folds or the seal opens at the rim. Contact with the plane: frictionless, Coulomb
mu = 0.3, 0.5, 1, 2 and sticking, each carried along the path; the route's default plate step and
the coarse mesh (72 lives; the route's default is medium: frictionless, coarse is within 4.6 % of the fine mesh,
medium within 0.9 %, benchmarks/fem_route_mesh_study.md), E = 4 MPa, nu = 0.49, reference conventions (no
relaxation, air at 293.15 K, p_a = 100 kPa). Beside them: the paper route with the paper's own
inputs (Table 1's cup, Appendix A's F0, eqs 3-7 with beta) and the table-coupled route (the
frictionless FEM's suction table of the design on its default (u, dp) grid, built around the
paths, coarse mesh). No
parameter is fitted to a measured number.

A cell gives the lifetime [s] and why it ended: fold (the branch's largest N at F1), reached_r1
(the seal opened at the rim), over_force (F1 above what the sealed cup holds: it lets go at
once), sealed or horizon (no detachment: inf). A run that ends without a detachment or fails says
so ("no branch: stopped: ...", "failed: ..."), never a number, and so does a run still going after
10 min of CPU ("unfinished"). The largest holdable force is the
largest pull at fixed N0 from the sealed state; a force above it is over_force by the route's own
definition (its branch does not start), so that branch is not run. The seal radii are the inner contact radius r_c,
the seal node r_k and the outer end of the contact r_out, at the sealed state (pressed, before the
pull), at the start of the branch (pulled to F1 at N0) and at its end (the detachment).

Rerun into the committed report: `python -m validation.crosscheck.fem_life_rerun --into
validation/report` (each run is kept in the validate cache, keyed by the sources of fem, reduced
and the route).
"""

from __future__ import annotations

import math
import re
import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from validation.crosscheck.context import CROSSCHECK_FIDELITY, Context, pmma_uc_table
from validation.crosscheck.runs import FemRun

NAME = "fem_life"
TITLE = "8. The cup's whole life in the FEM"

#: (law, Coulomb's mu) of the FEM cup's contact with the plane
LAWS = (("frictionless", None), ("coulomb", 0.3), ("coulomb", 0.5), ("coulomb", 1.0), ("coulomb", 2.0),
        ("sticking", None))
QUICK_LAWS = (("frictionless", None), ("coulomb", 0.5))
FORCES_N = {"A": (5.0, 10.0, 20.0, 40.0, 60.0, 80.0), "B": (5.0, 10.0, 20.0, 40.0)}
QUICK_FORCES_N = {"A": (10.0,)}
SEAL_FORCES_N = (10.0, 40.0)
FIGURE_LAWS = (("frictionless", None), ("coulomb", 0.5), ("coulomb", 2.0), ("sticking", None))
FIGURE_FORCE_N = 10.0
FIDELITY = CROSSCHECK_FIDELITY           # coarse: 72 lives (`cupcheck lifetime --route fem` defaults to medium)
CPU_LIMIT_S = 600.0                      # a life still running after this much CPU becomes an "unfinished" cell
PAPER_HOLD_N = 88.0                      # the paper's cup A held about 9 kg (Sec. 5)
P_A_PA = 1e5


@dataclass(frozen=True)
class LifeRun:
    """One FEM life on the route "fem": the cup pressed, sealed and held at `force_N` [N] (None:
    the largest holdable force only), contact `law` with Coulomb's `friction` (mu, coulomb only)."""

    cup: str
    law: str
    friction: float | None
    force_N: float | None
    fidelity: str = FIDELITY
    cpu_limit_s: float = CPU_LIMIT_S

    def law_label(self) -> str:
        return f"mu {self.friction:g}" if self.law == "coulomb" else self.law

    def label(self) -> str:
        what = "largest holdable force" if self.force_N is None else f"F1 = {self.force_N:g} N"
        return f"cup {self.cup}, {self.law_label()}, {self.fidelity}, {what}"

    def fem_cup(self):
        from fem.interface import ContactLaw
        from validation.bridge.fem_route import FemCup
        return FemCup(self.cup, self.fidelity, contact=ContactLaw(self.law, self.friction or 0.0))


@dataclass(frozen=True, eq=False)
class LifeOutcome:
    """What the section keeps of one `LifeRun` (plain data, cached on disk): the lifetime [s] (nan
    when the run failed), its reason ("failed", "no branch" or "unfinished" when there is no
    lifetime), the route's message, the largest holdable force [N] (nan if unknown), the seal radii
    [mm] of the sealed state, the branch's trajectory columns and the wall time [s]."""

    run: LifeRun
    lifetime_s: float
    reason: str
    message: str
    largest_force_N: float
    sealed: dict = field(default_factory=dict)
    trajectory: dict = field(default_factory=dict, repr=False)
    wall_s: float = math.nan

    @property
    def failed(self) -> bool:
        return self.reason in ("failed", "no branch", "not run", "unfinished")

    def cell(self) -> str:
        """The table cell: 'lifetime (reason)', or what stopped the run."""
        if self.failed:
            return f"{self.reason}: {self.message}"
        if self.run.force_N is None:
            return f"holds up to {self.largest_force_N:.4g} N"
        t = "inf" if math.isinf(self.lifetime_s) else f"{self.lifetime_s:.4g}"
        return f"{t} ({self.reason})"


def plan(quick: bool) -> tuple[LifeRun, ...]:
    """The section's FEM lives, per cup and law: the largest holdable force, then each force."""
    forces, laws = (QUICK_FORCES_N, QUICK_LAWS) if quick else (FORCES_N, LAWS)
    return tuple(LifeRun(cup, law, mu, F) for cup, Fs in forces.items() for law, mu in laws
                 for F in (None, *Fs))


def requests(quick: bool) -> tuple[FemRun, ...]:
    """No compression runs: the route builds and solves its own FEM cups (`plan`)."""
    return ()


def model_for(cup: str):
    """The reference-convention `LeakageModel` of a Table 1 cup on the section's surface."""
    from reduced.cup import CUPS
    from reduced.lifetime import reference_model
    return reference_model(CUPS[cup], pmma_uc_table())


class CpuLimitReached(BaseException):
    """A life ran out of its CPU time (a BaseException, so that no handler inside the route takes it
    for a solver failure)."""


@contextmanager
def cpu_limit(seconds: float) -> Iterator[None]:
    """Raise `CpuLimitReached` in the enclosed block once the process has spent `seconds` of CPU
    (user + system, all its threads) in it: the profiling timer's SIGPROF. An enclosing limit that
    ends sooner keeps its own deadline, and a later one is re-armed with what is left of it.
    Signal handlers belong to the main thread: elsewhere, and where the platform has no profiling
    timer, the block runs without a limit. (A library timeout such as func_timeout or
    timeout-decorator measures wall time, which a shared machine stretches.)"""
    if not hasattr(signal, "setitimer") or threading.current_thread() is not threading.main_thread():
        yield
        return
    outer, _ = signal.getitimer(signal.ITIMER_PROF)
    if 0.0 < outer <= seconds:                   # the enclosing limit comes first: it is the one
        yield
        return
    armed = [True]

    def reached(signum, frame):
        if armed[0]:
            armed[0] = False
            raise CpuLimitReached(seconds)

    previous = signal.signal(signal.SIGPROF, reached)
    start = time.process_time()
    signal.setitimer(signal.ITIMER_PROF, seconds)
    try:
        yield
    finally:
        armed[0] = False
        signal.setitimer(signal.ITIMER_PROF, 0.0)
        signal.signal(signal.SIGPROF, signal.SIG_DFL if previous is None else previous)
        if outer > 0.0:                          # the enclosing limit, less the CPU spent here
            signal.setitimer(signal.ITIMER_PROF, max(outer - (time.process_time() - start), 1e-6))


def live(run: LifeRun, code: str = "", progress: Callable[[float, str], None] | None = None) -> LifeOutcome:
    """Run one FEM life (`code`, the sources' hash, is only the cache key); a failure becomes an
    outcome that names it, and so does a life still running after its CPU limit ("unfinished")."""
    t0 = time.perf_counter()
    try:
        with cpu_limit(run.cpu_limit_s):
            return _live(run)
    except CpuLimitReached:
        return LifeOutcome(run, math.nan, "unfinished", f"not finished within {run.cpu_limit_s:g} s of CPU",
                           math.nan, wall_s=time.perf_counter() - t0)


def _live(run: LifeRun) -> LifeOutcome:
    from reduced.lifetime import largest_holdable_force, solve_lifetime
    from validation.bridge.fem_route import FemRouteError, register

    route = register()
    model = model_for(run.cup)
    t0 = time.perf_counter()
    sealed, largest = {}, math.nan
    try:
        options = {**route.options, "cup": run.fem_cup()}
        s = route.seal(model, options).state
        sealed = {"r_c_mm": 1e3 * s.r_c_m, "r_k_mm": 1e3 * s.seal_r_m, "r_out_mm": 1e3 * s.cut_r_m,
                  "u_mm": 1e3 * s.u_m, "p_b_kPa": 1e-3 * s.p_b_Pa, "N0": s.N}
        if run.force_N is None:
            largest = largest_holdable_force(model, "fem", **options)
            return LifeOutcome(run, math.nan, "largest", f"{largest:.4g} N", largest, sealed,
                               wall_s=time.perf_counter() - t0)
        life = solve_lifetime(model, run.force_N, route="fem", **options)
    except FemRouteError as exc:
        text = str(exc).splitlines()[0]
        m = re.search(r"without a detachment \((.*)\) after (\d+) states", text)
        why = f"{m.group(1)} ({m.group(2)} states)" if m else text
        return LifeOutcome(run, math.nan, "no branch", why, largest, sealed, wall_s=time.perf_counter() - t0)
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        return LifeOutcome(run, math.nan, "failed", f"{type(exc).__name__}: {str(exc).splitlines()[0][:200]}",
                           largest, sealed, wall_s=time.perf_counter() - t0)
    trajectory = {k: np.asarray(v, dtype=float) for k, v in life.trajectory.items()}
    return LifeOutcome(run, float(life.lifetime_s), life.reason, life.message, float(life.largest_force_N),
                       sealed, trajectory, time.perf_counter() - t0)


def lives(runs, one: Callable[[LifeRun], LifeOutcome]) -> dict[tuple, LifeOutcome]:
    """(cup, law, mu, F1) -> outcome of each run by `one`, except a force above the largest holdable
    force of its cup and law (planned before it): the route's branch does not start there (its
    definition of the largest force), so the cell says over_force without running it."""
    out: dict[tuple, LifeOutcome] = {}
    for r in runs:
        held = out.get((r.cup, r.law, r.friction, None))
        if r.force_N is not None and held is not None and not held.failed and r.force_N > held.largest_force_N:
            o = LifeOutcome(r, 0.0, "over_force", f"F1 above the largest holdable force "
                            f"{held.largest_force_N:.4g} N: the cup lets go at once (branch not run)",
                            held.largest_force_N, held.sealed, wall_s=0.0)
            print(f"{NAME}: {r.label()}: {o.cell()} (above {held.largest_force_N:.4g} N, not run)", flush=True)
        else:
            o = one(r)
        out[(r.cup, r.law, r.friction, r.force_N)] = o
    return out


def _runner(ctx: Context, cached_only: bool = False) -> Callable[[LifeRun], LifeOutcome]:
    """`live` through the run memo's cache directory (when there is one); see `cached_runner`."""
    return cached_runner(ctx.memo.cache_dir, ctx.progress, cached_only)


def cached_runner(root, progress: Callable[[float, str], None] = lambda f, m: None,
                  cached_only: bool = False) -> Callable[[LifeRun], LifeOutcome]:
    """`live` cached under `root` / fem_life (None: not cached), keyed by the run and the sources of
    fem, reduced and the route; `cached_only`: a run not in the cache is not run (its cell says so)."""
    from joblib import Memory

    from validation.bridge.cache import Cache, source_hash

    cached = Cache(None if root is None else root / "fem_life").cached(live, ignore=["progress"])
    code = source_hash("fem", "reduced", "validation/bridge/fem_route.py", "validation/bridge/pipeline.py")
    stored = None if root is None else Memory(str(root / "fem_life"), verbose=0).cache(live, ignore=["progress"])

    def run_one(run: LifeRun) -> LifeOutcome:
        progress(0.0, f"{NAME}: {run.label()}")
        if cached_only and (stored is None or not stored.check_call_in_cache(run, code)):
            out = LifeOutcome(run, math.nan, "not run", "not in the cache (rerun to fill)", math.nan)
        else:
            out = cached(run, code)
        print(f"{NAME}: {run.label()}: {out.cell()} ({out.wall_s:.0f} s)", flush=True)
        return out
    return run_one


def groups(quick: bool, cups=None, laws=None) -> list[tuple[LifeRun, ...]]:
    """The plan cut into its independent parts, one per (cup, law): each part's largest holdable
    force comes first, since it decides which of its forces run (`lives`). `cups`, `laws`: keep
    only these (None: all)."""
    parts: dict[tuple, list[LifeRun]] = {}
    for r in plan(quick):
        if (cups is None or r.cup in cups) and (laws is None or (r.law, r.friction) in laws):
            parts.setdefault((r.cup, r.law, r.friction), []).append(r)
    return [tuple(p) for p in parts.values()]


def _fill_part(runs: tuple[LifeRun, ...], root) -> int:
    """Run one (cup, law) part into the cache under `root`; returns how many lives it holds."""
    return len(lives(runs, cached_runner(root)))


def fill(parts, root, jobs: int = 1, tables=()) -> None:
    """Run the (cup, law) parts, and build the suction tables of the cups in `tables` (the
    table-coupled route's), into the cache under `root`, `jobs` processes at a time (joblib's loky
    workers; the cache on disk is the hand-back). The slowest tasks go first."""
    from joblib import Parallel, delayed

    tasks = [delayed(_build_table)(cup, root) for cup in tables]
    tasks += [delayed(_fill_part)(p, root) for p in sorted(parts, key=_expected_cost, reverse=True)]
    Parallel(n_jobs=jobs, backend="loky", verbose=0)(tasks)


def _build_table(cup: str, root) -> None:
    _table_in(cup, root)


def _expected_cost(part: tuple[LifeRun, ...]) -> float:
    """A rough order of the parts' cost: sticking and large mu walk longer branches."""
    r = part[0]
    return {"sticking": 3.0, "coulomb": 1.0 + (r.friction or 0.0)}.get(r.law, 1.0)


def run(ctx: Context, cached_only: bool = False) -> None:
    from validation.crosscheck.fem_life_report import Layout, write_section

    rep = ctx.report
    rep.text(NAME, __doc__.split("\n\n", 1)[1])
    outcomes = lives(plan(ctx.quick), _runner(ctx, cached_only))
    others = {cup: other_routes(ctx, cup, Fs, cached_only) for cup, Fs in (QUICK_FORCES_N if ctx.quick else FORCES_N).items()}
    forces = QUICK_FORCES_N if ctx.quick else FORCES_N
    write_section(ctx, Layout(NAME, QUICK_LAWS if ctx.quick else LAWS, forces, SEAL_FORCES_N, FIGURE_LAWS,
                              FIGURE_FORCE_N, FIDELITY, PAPER_HOLD_N, P_A_PA), outcomes, others)


def other_routes(ctx: Context, cup: str, forces, cached_only: bool = False) -> dict[str, tuple[list[str], float, list[float]]]:
    """route label -> (cells per force, largest holdable force [N], lifetimes [s]) of the paper route (the paper's
    inputs) and, in the full section, the table-coupled route (frictionless FEM suction table)."""
    from dataclasses import replace

    from validation.bridge.lifetimes import lifetimes

    out = {}
    model = model_for(cup)
    ctx.progress(0.0, f"{NAME}: paper route, cup {cup}")
    out["paper"] = _route_cells(lambda: lifetimes(model, forces, "paper"), len(forces))
    if not ctx.quick and cached_only and not suction_table_cached(ctx, cup):
        out["coupled"] = (["not run: no suction table in the cache"] * len(forces), math.nan, [math.nan] * len(forces))
    elif not ctx.quick:
        ctx.progress(0.0, f"{NAME}: coupled route, cup {cup} (suction table, cached)")
        out["coupled"] = _route_cells(lambda: lifetimes(replace(model, suction=suction_table(ctx, cup)),
                                                        forces, "coupled"), len(forces))
    return out


def _route_cells(compute: Callable, n: int) -> tuple[list[str], float, list[float]]:
    """(cells, largest holdable force [N], lifetimes [s], nan where the route failed)."""
    try:
        res = compute()
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        return [f"failed: {type(exc).__name__}: {str(exc).splitlines()[0][:120]}"] * n, math.nan, [math.nan] * n
    cells = [("inf" if math.isinf(r.lifetime_s) else f"{r.lifetime_s:.4g}") + f" ({r.reason})" for r in res]
    return cells, float(res.largest_force_N), [float(r.lifetime_s) for r in res]


def suction_table(ctx: Context, cup: str):
    """The frictionless FEM suction table of a preset cup on the default grid, kept where section 6
    keeps it (the memo's cache directory / suction): one build per code version for both."""
    return _table_in(cup, ctx.memo.cache_dir)


def _table_in(cup: str, root):
    """Built around the section's paths (`validation.bridge.coupled.around`: only the states the
    lifetimes and the largest holdable force read, each the full default grid's own)."""
    from validation.bridge.coupled.build import DEFAULT_GRID, suction_table_for

    cache = None if root is None else root / "suction"
    return suction_table_for(cup, fidelity=CROSSCHECK_FIDELITY, grid=DEFAULT_GRID, cache_dir=cache,
                             goal=_table_goal(cup))


def _table_goal(cup: str):
    from validation.bridge.coupled.adaptive import SuctionGoal
    return SuctionGoal(model_for(cup), FORCES_N[cup])


def suction_table_cached(ctx: Context, cup: str) -> bool:
    """Whether `suction_table` would read the table from the cache (not build it)."""
    from joblib import Memory

    from fem.geometry import cup_geometry
    from fem.interface import ContactLaw
    from validation.bridge.cache import source_hash
    from validation.bridge.coupled import build

    if ctx.memo.cache_dir is None:
        return False
    memo = Memory(str(ctx.memo.cache_dir / "suction"), verbose=0).cache(build._build_around, ignore=["progress"])
    code = source_hash("fem", "validation/bridge/coupled", "reduced")
    return memo.check_call_in_cache(cup_geometry(cup), CROSSCHECK_FIDELITY, ContactLaw(), 4e6, 0.49,
                                    build.DEFAULT_GRID, _table_goal(cup), build.AroundSpec(), code)
