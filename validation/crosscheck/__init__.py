"""The validation report of issue 5: cross-checks of Appendix A, the cone laws, the lifetime, the
speed-accuracy trade, the extremes, the paper's numbers, Coulomb friction and the cup's whole life in
the FEM, each a section with
the FEM runs it needs declared up front.

    from validation.crosscheck import run_validation
    report = run_validation("out/validate", quick=True)          # tables, figures, summary.json

Each section module defines NAME, TITLE, ``requests(quick) -> tuple[FemRun, ...]`` and
``run(ctx)``; `RunMemo` runs every distinct request once for all sections together.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from validation.crosscheck import appendix, cone_laws, extremes, fem_life, friction, lifetimes, paper, speed
from validation.crosscheck.context import Context
from validation.crosscheck.report import Report
from validation.crosscheck.runs import FemRun, RunMemo

__all__ = ["SECTIONS", "section_names", "planned_requests", "run_validation", "FemRun", "RunMemo"]

SECTIONS = (appendix, cone_laws, lifetimes, speed, extremes, paper, friction, fem_life)


def section_names() -> tuple[str, ...]:
    return tuple(s.NAME for s in SECTIONS)


def _select(only: Sequence[str] | None):
    if not only:
        return SECTIONS
    unknown = sorted(set(only) - set(section_names()))
    if unknown:
        raise ValueError(f"--only: unknown section(s) {', '.join(unknown)}; allowed: {', '.join(section_names())}")
    return tuple(s for s in SECTIONS if s.NAME in only)


def planned_requests(quick: bool, only: Sequence[str] | None = None) -> tuple[FemRun, ...]:
    """The distinct FEM runs the selected sections need, in first-use order."""
    seen: dict[FemRun, None] = {}
    for s in _select(only):
        for r in s.requests(quick):
            seen.setdefault(r, None)
    return tuple(seen)


def run_validation(out_dir: str | Path, *, quick: bool = False, only: Sequence[str] | None = None,
                   memo: RunMemo | None = None, scene: bool = True,
                   progress: Callable[[float, str], None] | None = None) -> Report:
    """Run the selected sections into `out_dir` (which the caller makes atomic); returns the report."""
    import time

    sections = _select(only)
    memo = memo or RunMemo()
    plan = planned_requests(quick, only)
    report = Report(Path(out_dir))
    done = {"sections": 0}
    base = progress or (lambda f, m: None)

    def step(fraction: float, message: str) -> None:      # runs asked for so far + sections done
        n = memo.computed + memo.cache_hits + done["sections"]
        base(min(n / max(len(plan) + len(sections), 1), 0.999), message)

    ctx = Context(memo=memo, report=report, quick=quick, progress=step)
    t0 = time.perf_counter()
    for s in sections:
        s.run(ctx)
        done["sections"] += 1
    if scene:
        from validation.crosscheck.scene import deformed_cup_scene
        deformed_cup_scene(ctx)
    report.summary.update({"quick": quick, "sections": [s.NAME for s in sections],
                           "fem_runs_computed": memo.computed, "fem_runs_from_cache": memo.cache_hits,
                           "fem_runs_planned": len(plan),
                           # reruns a check asks for (the extremes' energy check halves the step)
                           "fem_runs_unplanned": len(set(memo.requests) - set(plan)),
                           "wall_s": time.perf_counter() - t0})
    report.write("cupcheck validation report" + (" (quick subset)" if quick else ""),
                 [s.NAME for s in sections] + ["scene"], {s.NAME: s.TITLE for s in SECTIONS} |
                 {"scene": "Deformed cup"})
    base(1.0, "done")
    return report
