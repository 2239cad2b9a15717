"""A suction table with holes in the coupled cavity (`reduced.coupled`): which states a point reads.

A table may hold states only where the cup's paths go (`SuctionTable.built`). The interpolation
of `reduced.table_surface` at (u, dp) in cell (i, j) reads the nodes of the columns j, j + 1
(only j on a node of dp) and, along u, the rows i, i + 1 (linear) or i - 1 ... i + 2 (monotone
cubic: each node's slope is Fritsch-Carlson's of its two neighbours' secants); on a node of u
only its row. Where all of them are built the value is the full table's to the last bit; where
one is missing `Holes.need` raises `MissingStates` naming the missing nodes, so that a builder
can add them, instead of reading a hole. `Holes.root_cell` finds, along one line of the grid,
the built cell in which a monotone quantity crosses a target; the functions below are the root
finders of `reduced.coupled.CoupledCavity` (`cc`) on a table with holes, bracketed there instead
of across the whole table, with its tolerances. A state without a seal (`SuctionTable.sealed`
False) is built but not readable: a value that reads one raises `SealOpen` (the cup has let go
there) instead of `MissingStates`, unless it also reads a hole.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from scipy.optimize import brentq

from reduced.suction_table import MissingStates, SealOpen
from reduced.table_surface import cell

__all__ = ["Holes", "NEAR_CELLS", "dp_low", "force_cell", "holding_dp", "start_dp", "u_at"]

#: the cells either side of a path's last crossing named first where a line has a gap there
#: (`Holes.near_missing`)
NEAR_CELLS = 2


class Holes:
    """The built nodes of a table on the axes u [m] and dp [Pa], and which of them hold a seal
    (None: all; module docstring)."""

    def __init__(self, built: np.ndarray, u: np.ndarray, dp: np.ndarray, along_u: str,
                 sealed: np.ndarray | None = None):
        self.solved = np.asarray(built, dtype=bool)
        self.built = self.solved if sealed is None else self.solved & np.asarray(sealed, dtype=bool)
        self.u, self.dp, self.cubic = u, dp, along_u == "pchip"
        self._u_list, self._dp_list = u.tolist(), dp.tolist()
        self._lines: dict[tuple, tuple[int, list[bool], list[int]]] = {}

    def rows(self, i: int, s: float) -> range:
        """The rows the value at local coordinate s of row interval i reads."""
        if s == 0.0:
            return range(i, i + 1)
        if s == 1.0:
            return range(i + 1, i + 2)
        return range(max(i - 1, 0), min(i + 3, self.u.size)) if self.cubic else range(i, i + 2)

    @staticmethod
    def cols(j: int, t: float) -> range:
        return range(j, j + 1) if t == 0.0 else range(j + 1, j + 2) if t == 1.0 else range(j, j + 2)

    def missing(self, u: float, dp: float) -> list[tuple[int, int]]:
        """The nodes (i, j) the value at (u, dp) reads that the table lacks or that hold no seal."""
        i, j, s, t = cell(self.u, self.dp, u, dp)
        rows, cols = self.rows(i, s), self.cols(j, t)
        block = self.built[rows.start:rows.stop, cols.start:cols.stop]
        if block.all():
            return []
        return [(rows.start + a, cols.start + b) for a, b in zip(*np.nonzero(~block))]

    def need(self, u: float, dp: float) -> None:
        """MissingStates if the value at (u, dp) reads a hole, else SealOpen if it reads a state
        without a seal."""
        lacking = self.missing(u, dp)
        if lacking:
            self.unreadable(lacking, f"at u = {1e3 * u:.4g} mm, dp = {dp / 1e3:.4g} kPa")

    def unreadable(self, nodes, where: str):
        """Raise MissingStates for the nodes not built, else SealOpen for those without a seal."""
        holes = [(i, j) for i, j in nodes if not self.solved[i, j]]
        if holes:
            raise MissingStates(holes, self.u, self.dp, where)
        raise SealOpen(nodes, self.u, self.dp, where)

    def cell_missing(self, axis: str, k: int, fixed: float) -> list[tuple[int, int]]:
        """The missing nodes of interval k of `axis` on the line where the other coordinate is `fixed`."""
        if axis == "u":
            return self.missing(0.5 * (self.u[k] + self.u[k + 1]), fixed)
        return self.missing(fixed, 0.5 * (self.dp[k] + self.dp[k + 1]))

    def line(self, axis: str, fixed: float, top: float) -> tuple[int, list[bool], list[int]]:
        """(the last node at most top, which cells are built, their end nodes) of one line; kept
        per line class (the other axis' interval and whether `fixed` is on its node)."""
        i, j, s, t = cell(self.u, self.dp, fixed, fixed)
        key = (axis, j, t if t in (0.0, 1.0) else 0.5, top) if axis == "u" else \
            (axis, i, s if s in (0.0, 1.0) else 0.5, top)
        if key not in self._lines:
            xs = self._u_list if axis == "u" else self._dp_list
            last = len(xs) - 1 if top >= xs[-1] else bisect.bisect_left(xs, top)    # the cell holding top
            ok = [not self.cell_missing(axis, k, fixed) for k in range(last)]
            nodes = sorted({k for k in range(last) if ok[k]} | {k + 1 for k in range(last) if ok[k]})
            self._lines[key] = (last, ok, nodes)
        return self._lines[key]

    def root_cell(self, axis: str, fixed: float, value: Callable[[float], float], target: float,
                  rising: bool, top: float = np.inf, near: float | None = None) -> tuple[float, float] | str:
        """Along `axis` ('u' or 'dp', the other coordinate `fixed`), with value(x) monotone (rising
        or falling) and read only at built cells: the interval [x_a, x_b] of one built cell (x_b
        at most `top`; x_a = x_b where a node hits `target`) whose ends bracket `target`; 'below'
        or 'above' if the target lies beyond the axis' first node or its last one (at most `top`);
        MissingStates (`gap_missing`) where the crossing lies in cells not built. `near`, where
        the caller expects the crossing (a path's previous point), names only the cells around it
        while they are not built (`near_missing`); it never changes a value found."""
        xs = self._u_list if axis == "u" else self._dp_list
        last, ok, nodes = self.line(axis, fixed, top)
        if not nodes:                  # no readable cell: the states not built come first
            guessed = self.near_missing(axis, fixed, near, 0, max(last, 1) - 1)
            if guessed:
                self.unreadable(guessed, f"along {axis} at {fixed:.6g}: nothing built near {near:.6g}")
            cells = [self.cell_missing(axis, k, fixed) for k in range(max(last, 1))]
            unsolved = sorted({n for c in cells for n in c if not self.solved[n]})
            self.unreadable(unsolved or cells[0], f"along {axis} at {fixed:.6g}: nothing built")
        sign = 1.0 if rising else -1.0
        at = lambda k: min(xs[k], top)                                    # noqa: E731
        g = lambda k: sign * (value(at(k)) - target)                       # noqa: E731
        lo, hi = 0, len(nodes) - 1
        g_lo, g_hi = g(nodes[lo]), g(nodes[hi])
        if g_lo > 0:
            if nodes[lo] == 0:
                return "below"
            gap = (0, nodes[lo] - 1, "down")
        elif g_hi < 0:
            if nodes[hi] == last:
                return "above"
            gap = (nodes[hi], last - 1, "up")
        elif g_hi == 0:
            return at(nodes[hi]), at(nodes[hi])
        else:
            while hi - lo > 1:                                             # g(nodes[lo]) <= 0 < g(nodes[hi])
                mid = (lo + hi) // 2
                g_mid = g(nodes[mid])
                lo, hi, g_lo = (mid, hi, g_mid) if g_mid <= 0 else (lo, mid, g_lo)
            k = nodes[lo]
            if g_lo == 0:
                return at(k), at(k)
            if nodes[hi] == k + 1 and ok[k]:
                return at(k), at(k + 1)
            gap = (k, nodes[hi] - 1, "")
        where = f"along {axis} at {fixed:.6g}, where the value crosses {target:.6g}"
        self.unreadable(self.near_missing(axis, fixed, near, *gap[:2]) or self.gap_missing(axis, fixed, *gap), where)

    def near_missing(self, axis: str, fixed: float, near: float | None, a: int, b: int) -> list[tuple[int, int]]:
        """The missing nodes of the cells a ... b of a line that lie within NEAR_CELLS cells of
        the one holding `near` (none without `near`, or where those are built: then the gap's
        own rule, `gap_missing`, bisects or fills it). A path moves little from one point to the
        next, so its next crossing lies next to its last one far more often than anywhere in a
        gap; each round still adds cells of the gap, so the gap closes either way."""
        if near is None or not math.isfinite(near):
            return []
        xs = self._u_list if axis == "u" else self._dp_list
        k = min(max(bisect.bisect_right(xs, near) - 1, 0), len(xs) - 2)
        cells = range(max(a, k - NEAR_CELLS), min(b, k + NEAR_CELLS) + 1)
        return sorted({n for c in cells for n in self.cell_missing(axis, c, fixed) if not self.solved[n]})

    def gap_missing(self, axis: str, fixed: float, a: int, b: int, runs: str = "") -> list[tuple[int, int]]:
        """The missing nodes of the cells a ... b of a line in which a crossing lies unseen: of
        the cells next to built ones (the gap `runs` 'down' to the line's start or 'up' to its
        end: only b, or only a, is) and the middle one (a builder bisects a long gap); every cell
        of a gap of at most 24 cells (a short gap is filled in one round)."""
        if b - a <= 24:                                   # a short gap: all of it, in one round
            cells = set(range(a, b + 1))
        else:
            cells = {(a + b) // 2} | ({b} if runs == "down" else {a} if runs == "up" else {a, b})
        return sorted({n for k in cells for n in self.cell_missing(axis, k, fixed)})


def u_at(cc: Any, F1: float, dp: float) -> float:
    """`CoupledCavity.u_at`: u with F1(u, dp) = F1 (F1 falls with u)."""
    found = cc._holes.root_cell("u", dp, lambda u: cc.F1(u, dp), F1, rising=False)
    if isinstance(found, tuple):
        return brentq(lambda u: cc.F1(u, dp) - F1, *found, xtol=1e-15, rtol=1e-13)
    end = cc._u[0] if found == "below" else cc._u[-1]
    edge = cc.F1(end, dp)
    if abs(F1 - edge) <= 1e-9 * max(abs(edge), 1.0):
        return float(end)
    raise ValueError(f"F1 = {F1:.4g} N at dp = {dp / 1e3:.4g} kPa lies {found} the table's "
                     f"{edge:.4g} N at u = {1e3 * end:.4g} mm")


def dp_low(cc: Any, F1: float) -> float:
    """The low-dp end of the F1 branch (`CoupledCavity._dp_range`): F1(u_min, dp) = F1; 0 if
    the branch reaches dp = 0, nan if F1 is more than the table's top dp holds."""
    u0 = cc._u[0]
    found = cc._holes.root_cell("dp", u0, lambda d: cc.F1(u0, d), F1, rising=True, top=cc._dp_top)
    if isinstance(found, tuple):
        return brentq(lambda d: cc.F1(u0, d) - F1, *found, xtol=1e-9)
    return 0.0 if found == "below" else math.nan


def start_dp(cc: Any, u_start_m: float) -> float:
    """dp of the cup released at u_start with F1 = 0 (`CoupledCavity.start`)."""
    top = cc._dp_top
    found = cc._holes.root_cell("dp", u_start_m, lambda d: cc.F1(u_start_m, d), 0.0, rising=True, top=top)
    if not isinstance(found, tuple):
        raise ValueError(f"u_start: the table's dp <= {top / 1e3:.4g} kPa cannot hold the cup "
                         f"released at u = {1e3 * u_start_m:.4g} mm" if found == "above" else
                         f"u_start: the cup released at u = {1e3 * u_start_m:.4g} mm pulls at dp = 0")
    return brentq(lambda d: cc.F1(u_start_m, d), *found, xtol=1e-9)


def holding_dp(cc: Any, F1: float, N0: float, lo: float) -> float:
    """dp of the F1 branch's state holding N0 (`CoupledCavity.loaded`), bracketed between the
    grid's dp values from lo up (N falls with dp above the fold and rises below it, so the first
    value under N0 closes the bracket of the one crossing)."""
    top = cc._dp_top
    prev = lo
    for d in [float(d) for d in cc._dp if lo < d < top] + [top]:
        if cc.content(F1, d)[1] < N0:
            return brentq(lambda x: cc.content(F1, x)[1] - N0, prev, d, xtol=1e-10 * max(top, 1.0))
        prev = d
    raise ValueError(f"F1 = {F1:g} N: the branch holds more than the start content up to the "
                     f"table's top dp = {top / 1e3:.4g} kPa; extend the table")


def force_cell(cc: Any, holds: Callable[[float], bool]) -> tuple[float, float] | float:
    """For `CoupledCavity._largest_force`: the pulls (F_a, F_b) at the ends of the built cell of
    the smallest u's row between which `holds` turns false (the largest force lies there), or the
    force itself where it is the table's top (0 where nothing holds); MissingStates where that
    cell is not built."""
    u0, top, holes = cc._u[0], cc._dp_top, cc._holes
    last, ok, nodes = holes.line("dp", u0, top)
    force = lambda k: cc.F1(u0, min(float(cc._dp[k]), top))          # noqa: E731
    if not nodes:
        holes.unreadable(holes.cell_missing("dp", 0, u0), "on the smallest u's row")
    a, b = 0, len(nodes) - 1
    if holds(force(nodes[b])):
        if nodes[b] == last:
            return force(nodes[b])
        gap = (nodes[b], last - 1, "up")
    elif not holds(force(nodes[a])):
        if nodes[a] == 0:
            return (0.0, force(0)) if force(0) > 0 else 0.0
        gap = (0, nodes[a] - 1, "down")
    else:
        while b - a > 1:
            mid = (a + b) // 2
            a, b = (mid, b) if holds(force(nodes[mid])) else (a, mid)
        k = nodes[a]
        if nodes[b] == k + 1 and ok[k]:
            return force(k), force(k + 1)
        gap = (k, nodes[b] - 1, "")
    holes.unreadable(holes.gap_missing("dp", u0, *gap), "where the largest holdable force lies")
