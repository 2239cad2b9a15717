"""The branch of the relaxing coupled cavity at one stiffness factor kappa (`reduced.coupled_relax`).

At fixed pull F1 and kappa the cup's states form a branch in table coordinates (u, s = dp / kappa):
kappa F1_tab(u, s) = F1 and (p_a - kappa s) V_tab(u, s) = N kT. `Branch.solve` finds the state
that holds the gas content N (Newton with bisection, warm-started from the last state), or the
branch's end where no state holds N: its fold (dN/ds = 0, no state holds more gas) or the table's
smallest u (`edge`). `BranchPoint` carries the state and the slopes the dynamics needs.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from scipy.optimize import brentq

from reduced.suction_table import SuctionTable
from reduced.table_surface import TableSurface

__all__ = ["Branch", "BranchPoint", "safeguarded_newton"]


@dataclass(frozen=True)
class BranchPoint:
    """A state on the branch at one kappa (table coordinates) with what its derivatives need."""

    u: float
    s: float
    N: float
    dN_ds: float
    F: tuple[float, float, float]      # F1_tab and its u, s slopes
    V: tuple[float, float, float]


class Branch:
    """The branch of pull F1 at the current kappa: the state that holds N gas (module docstring)."""

    def __init__(self, table: SuctionTable, kT_J: float, p_a_Pa: float, F1: float,
                 surfaces: dict[str, TableSurface]):
        self.F1, self.S = F1, surfaces
        self.kT, self.pa = kT_J, p_a_Pa
        self.u_lo, self.u_hi = float(table.u_m[0]), float(table.u_m[-1])
        self.s_max = float(table.dp_Pa[-1])
        self.last_u, self.last_s = self.u_hi, 0.0
        self._edge: tuple[float | None, BranchPoint | None] = (None, None)

    def u_of(self, s: float, k: float) -> float:
        """u with k F1_tab(u, s) = F1 (F1 falls with u); u_lo where even u_lo cannot hold F1."""
        F = self.S["F1"]

        def f(u: float) -> tuple[float, float]:
            z, z_u, _ = F.value_and_slopes(u, s)
            return k * z - self.F1, k * z_u
        f_lo, f_hi = f(self.u_lo)[0], f(self.u_hi)[0]
        slack = 1e-9 * max(abs(self.F1), 1.0)
        if f_lo <= slack:
            return self.u_lo
        if f_hi > 0:
            if f_hi <= slack:
                return self.u_hi
            raise ValueError(f"F1 = {self.F1:g} N presses the cup beyond the table's u = "
                             f"{1e3 * self.u_hi:.4g} mm at dp = {k * s / 1e3:.4g} kPa; extend the table")
        u = safeguarded_newton(f, self.u_lo, self.u_hi, 1.0, self.last_u, 1e-13 * self.u_hi)
        self.last_u = u
        return u

    def point(self, s: float, k: float) -> BranchPoint:
        u = self.u_of(s, k)
        F, V = self.S["F1"].value_and_slopes(u, s), self.S["V"].value_and_slopes(u, s)
        g = self.pa - k * s
        det = k * F[1] * (g * V[2] - k * V[0]) - k * F[2] * g * V[1]
        return BranchPoint(u, s, g * V[0] / self.kT, det / (k * F[1] * self.kT), F, V)

    def edge(self, k: float) -> BranchPoint:
        """The branch's state at the table's smallest u (the end of the data)."""
        if self._edge[0] != k:
            top = self.s_top(k)
            g = lambda s: k * self.S["F1"](self.u_lo, s) - self.F1      # noqa: E731
            s = top if g(top) <= 0 else (0.0 if g(0.0) >= 0 else brentq(g, 0.0, top, xtol=1e-12 * top))
            self._edge = (k, self.point(s, k))
        return self._edge[1]

    def s_top(self, k: float) -> float:
        return min(self.s_max, self.pa / k)

    def solve(self, N: float, k: float) -> tuple[BranchPoint, str | None]:
        """(the state holding N, None), or (the branch's end, 'fold' or 'table_edge') if N lies
        beyond it (the dynamics is continued there with the end values)."""
        s_lo, s_hi = self.edge(k).s, self.s_top(k)
        P = self.point(min(max(self.last_s, s_lo), s_hi), k)
        if P.dN_ds >= 0:                                 # at or below a fold: the fold lies above
            P = self._fold(P, self._climb(P, k, s_hi), k)
            if P.N <= N:
                return self._keep(P), "fold"
        if P.N >= N:
            lo, hi = self._up(P, N, k, s_hi)
        else:
            lo, hi, end = self._down(P, N, k, s_lo)
            if end is not None:
                return self._keep(lo), end
        if lo.N == N:
            return self._keep(lo), None

        def f(x: float) -> tuple[float, float]:
            Q = self.point(x, k)
            return Q.N - N, Q.dN_ds
        s = safeguarded_newton(f, lo.s, hi.s, 1.0, lo.s + (N - lo.N) / lo.dN_ds if lo.dN_ds < 0 else lo.s,
                    1e-14 * self.s_max)
        return self._keep(self.point(s, k)), None

    def _keep(self, P: BranchPoint) -> BranchPoint:
        self.last_s, self.last_u = P.s, P.u
        return P

    def _step(self, P: BranchPoint, N: float) -> float:
        return max(2.0 * abs(N - P.N) / abs(P.dN_ds), 1e-6 * self.s_max) if P.dN_ds < 0 else 1e-3 * self.s_max

    def _down(self, P: BranchPoint, N: float, k: float, s_lo: float) -> tuple[BranchPoint, BranchPoint, str | None]:
        """Below P (N(P) < N): (lo, hi, None) with N(lo) >= N > N(hi), or (the fold or the edge,
        -, its name) if the branch ends before holding N."""
        step = self._step(P, N)
        while True:
            Q = self.point(max(P.s - step, s_lo), k)
            if Q.dN_ds >= 0:
                fold = self._fold(Q, P, k)
                return (fold, P, "fold" if fold.N < N else None)
            if Q.N >= N:
                return Q, P, None
            if Q.s <= s_lo:
                return Q, P, "table_edge"
            P, step = Q, 2.0 * step

    def _up(self, P: BranchPoint, N: float, k: float, s_hi: float) -> tuple[BranchPoint, BranchPoint]:
        """Above P (N(P) >= N): (lo, hi) with N(lo) >= N >= N(hi)."""
        step = self._step(P, N)
        while True:
            Q = self.point(min(P.s + step, s_hi), k)
            if Q.N <= N:
                return P, Q
            if Q.s >= s_hi:
                raise ValueError(f"suction table: the branch at F1 = {self.F1:g} N holds more than "
                                 f"N = {N:.6g} up to its top dp = {k * s_hi / 1e3:.4g} kPa; extend dp")
            P, step = Q, 2.0 * step

    def _climb(self, P: BranchPoint, k: float, s_hi: float) -> BranchPoint:
        """The first state above P on the stable side (dN/ds < 0)."""
        step = 1e-4 * self.s_max
        while True:
            Q = self.point(min(P.s + step, s_hi), k)
            if Q.dN_ds < 0:
                return Q
            if Q.s >= s_hi:
                raise ValueError(f"suction table: no stable state at F1 = {self.F1:g} N below "
                                 f"dp = {k * s_hi / 1e3:.4g} kPa")
            P, step = Q, 2.0 * step

    def _fold(self, below: BranchPoint, above: BranchPoint, k: float) -> BranchPoint:
        """The fold dN/ds = 0 between a state `below` (dN/ds >= 0) and one `above` (< 0)."""
        if below.dN_ds == 0:
            return below
        s = brentq(lambda x: self.point(x, k).dN_ds, below.s, above.s, xtol=1e-14 * self.s_max)
        return self.point(s, k)


def safeguarded_newton(f: Callable[[float], tuple[float, float]], lo: float, hi: float,
                       sign_lo: float, x0: float, xtol: float) -> float:
    """Root of f (value, slope) in [lo, hi], f having the sign of sign_lo at lo and the other at
    hi: Newton steps, bisection where one leaves the bracket."""
    x = min(max(x0, lo), hi)
    for _ in range(200):
        fx, dfx = f(x)
        if fx == 0.0:
            return x
        if (fx > 0) == (sign_lo > 0):
            lo = x
        else:
            hi = x
        step = x - fx / dfx if dfx != 0.0 else math.nan
        x_new = step if min(lo, hi) < step < max(lo, hi) else 0.5 * (lo + hi)
        if abs(x_new - x) <= xtol or abs(hi - lo) <= xtol:
            return x_new
        x = x_new
    raise RuntimeError(f"coupled branch: no convergence in [{lo:.6g}, {hi:.6g}]")
