"""Where a suction-table build spends its time: every path `fem.suction.SuctionStates` solves, by
kind (pressing a row, a dp ramp in a pressed row, a raised state ramped in its row, a raise at
fixed dp by how many lattice rows it spans or from the anchor row), whether Newton started on a
predictor, and whether the path failed (a predictor that failed and was retried without it,
a raise that reached no state); per kind the paths, Newton iterations, load steps, cut-backs and
CPU seconds, and the CPU of the states' hand-off outside the paths. A bench option only
(`--counters` of bench_coupled_paper_start.py and bench_coupled_raised.py): it wraps the class's
methods for the duration of a `with` block and changes no result.
"""

from __future__ import annotations

import contextlib
import time
from collections import defaultdict

from fem.solver import ConvergenceError
from fem.suction import SuctionStates


class Counters:
    """Per kind: [paths, Newton iterations, steps, cut-backs, CPU s]."""

    def __init__(self):
        self.kinds: dict[str, list[float]] = defaultdict(lambda: [0, 0, 0, 0, 0.0])
        self.state_cpu = 0.0
        self.solve_cpu = 0.0
        self.asked: list[tuple[float, float]] = []       # the states asked, in order
        self.failures: list[str] = []                    # each failed path: where, cost, cause

    def add(self, kind: str, stats, cpu: float) -> None:
        row = self.kinds[kind]
        row[0] += 1
        if stats is not None:
            row[1] += stats.newton_iterations
            row[2] += stats.steps
            row[3] += stats.cutbacks
        row[4] += cpu
        self.solve_cpu += cpu

    def report(self) -> str:
        lines = [f"{'kind':<34} {'paths':>6} {'Newton':>7} {'/path':>6} {'steps':>6} {'cuts':>5} {'CPU s':>7} "
                 f"{'ms/path':>8}"]
        total = [0, 0, 0, 0, 0.0]
        for kind in sorted(self.kinds):
            n, its, steps, cuts, cpu = self.kinds[kind]
            total = [a + b for a, b in zip(total, (n, its, steps, cuts, cpu))]
            lines.append(f"{kind:<34} {n:>6} {its:>7} {its / n:>6.2f} {steps:>6} {cuts:>5} {cpu:>7.2f} "
                         f"{1e3 * cpu / n:>8.1f}")
        n, its, steps, cuts, cpu = total
        lines.append(f"{'all paths':<34} {n:>6} {its:>7} {its / max(n, 1):>6.2f} {steps:>6} {cuts:>5} {cpu:>7.2f}")
        lines.append(f"states' CPU outside the paths (hand-off, measures): {self.state_cpu - self.solve_cpu:.2f} s")
        lines += ["failed: " + f for f in self.failures]
        return "\n".join(lines)


def _kind(states: SuctionStates, where: str, t_max: float, u_plate: float, predict) -> str:
    if where.startswith("pressing"):
        kind = "press"
    elif where.startswith("plate raised from"):
        rows = t_max / (-states.floor_m / _RAISED_ROWS)
        if abs(u_plate + t_max - states.anchor_m) < 1e-12 * states.h1_m:
            kind = "raise from the anchor row"
        elif rows < 3.5:
            kind = f"raise {round(rows)} row{'s' if round(rows) > 1 else ''}"
        else:
            kind = "raise 4-20 rows" if rows < 20.5 else "raise > 20 rows"
    elif "(raised)" in where:
        kind = "ramp in a raised row"
    else:
        kind = "ramp in a pressed row"
    return kind + (", predicted" if predict is not None else "")


_RAISED_ROWS = 540


class _NONE:
    newton_iterations = steps = cutbacks = 0


@contextlib.contextmanager
def counting(raised_rows: int = 540):
    """Count every path `SuctionStates` solves inside the block (module docstring)."""
    global _RAISED_ROWS
    _RAISED_ROWS = raised_rows
    counters = Counters()
    segment, state = SuctionStates._segment, SuctionStates.state

    def counted_segment(self, mech, dirichlet, t_max, start, u_plate, where, options=None, predict=None):
        kind = _kind(self, where, t_max, u_plate, predict)
        t = time.process_time()
        try:
            result = segment(self, mech, dirichlet, t_max, start, u_plate, where, options, predict)
        except ConvergenceError as err:
            stats = err.stats if err.stats is not None else _last_stats(self) or _NONE
            counters.add(kind + ", failed", stats, time.process_time() - t)
            counters.failures.append(f"{kind}: {where}: {stats.newton_iterations} iterations, {stats.cutbacks} "
                                     f"cut-backs, {time.process_time() - t:.2f} s: {str(err)[:160]}")
            raise
        counters.add(kind, _last_stats(self), time.process_time() - t)
        return result

    depth = [0]

    def counted_state(self, u, dp):
        if depth[0] == 0:
            counters.asked.append((u, dp))
        depth[0] += 1
        t = time.process_time()
        try:
            return state(self, u, dp)
        finally:
            depth[0] -= 1
            if depth[0] == 0:
                counters.state_cpu += time.process_time() - t

    SuctionStates._segment, SuctionStates.state = counted_segment, counted_state
    try:
        yield counters
    finally:
        SuctionStates._segment, SuctionStates.state = segment, state


def _last_stats(states: SuctionStates):
    """The stats of the path just solved: the difference of the joined totals."""
    prev = getattr(states, "_counted", None)
    now = states.stats
    if now is prev:
        return None
    states._counted = now
    if prev is None:
        return now

    class _Diff:
        newton_iterations = now.newton_iterations - prev.newton_iterations
        steps = now.steps - prev.steps
        cutbacks = now.cutbacks - prev.cutbacks
    return _Diff
