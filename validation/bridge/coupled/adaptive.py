"""The coupled route's suction table built for the lifetimes asked: only the states they need.

Scheme, and why. `reduced.coupled` interpolates a rectangular (u, dp) grid (monotone cubic along
u, linear along dp), so the table stays a tensor grid; its axes are chosen among those of a fine
lattice (the full grid, `DEFAULT_GRID`), so that wherever refinement reaches the lattice's spacing
the table holds the full grid's own states (`fem.suction.SuctionStates` keeps every solved state).
It starts on every 8th u and every 10th dp of the lattice, then:

- the band: the lifetimes of the asked forces (and the largest holdable force) on the current
  table give the (u, dp) paths the cup follows; u and dp beyond the band's top (plus one interval)
  are dropped: no path reads them;
- the error estimate: every interval of u or dp that a path crosses is split at its lattice
  midpoint, and the lifetime integrand dN / Ndot along the old path is evaluated on the old and the
  new table; the difference, per interval the path was in, relative to the lifetime, is that
  interval's error (the start and the end of each path, and the largest holdable force, charge
  the intervals they lie in with their whole change);
- an interval whose error is below `tol` is not split again; the others' halves are, while the
  paths cross them, down to the lattice.

The leak through a profile jumps where a node lands, so a path needs the grid's own u spacing
wherever it goes (coarser rows move the lifetimes by percents). A tensor grid's cost is every row
the paths cross times every column any force's path crosses; the table with holes around the
paths (`validation.bridge.coupled.around`, the default of `suction_table_for`) solves only the
states next to them. The lifetimes' error against the full grid and the cost of both:
benchmarks/bench_coupled.py --adaptive, --around.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

__all__ = ["AdaptiveSpec", "SuctionGoal", "Round", "AdaptiveAxes", "adaptive_axes", "goal_for", "lattice_subtable"]


@dataclass(frozen=True)
class AdaptiveSpec:
    """The refinement's start (every `u_every`-th u and `dp_every`-th dp of the lattice), the
    error per interval below which it stops splitting (a fraction of the lifetime), and a bound
    on the rounds."""

    u_every: int = 8
    dp_every: int = 10
    tol: float = 5e-4
    max_rounds: int = 10

    def __post_init__(self) -> None:
        if not (isinstance(self.u_every, int) and isinstance(self.dp_every, int)
                and self.u_every >= 1 and self.dp_every >= 1):
            raise ValueError(f"u_every, dp_every: need integers >= 1, got {self.u_every}, {self.dp_every}")
        if not self.tol >= 0:
            raise ValueError(f"tol: need a fraction >= 0 (0: refine to the lattice), got {self.tol}")


@dataclass(frozen=True)
class SuctionGoal:
    """What the table is for: a `reduced.LeakageModel` without its table (cup, u_c, gas, kappa,
    interface), the pull forces [N] whose lifetimes it must give, and the plate displacement [m]
    the cup is released at (None: the route's default, from the cup's h_start). For the build
    around the paths (`validation.bridge.coupled.around`): `hint`, points (u [m], dp [Pa]) near
    which the paths are expected (empty: found on a seed grid), and whether the largest holdable
    force is asked too (`largest`)."""

    model: Any
    forces_N: tuple[float, ...]
    u_start_m: float | None = None
    hint: tuple[tuple[float, float], ...] = ()
    largest: bool = True

    def __post_init__(self) -> None:
        forces = tuple(float(f) for f in self.forces_N)
        if not forces or not all(math.isfinite(f) and f > 0 for f in forces):
            raise ValueError(f"forces_N: need pull forces > 0 N, got {self.forces_N}")
        object.__setattr__(self, "forces_N", forces)
        object.__setattr__(self, "hint", tuple((float(u), float(dp)) for u, dp in self.hint))


@dataclass(frozen=True)
class Round:
    """One refinement round: the table's states, the goal's lifetimes [s] and largest holdable
    force [N] on it, the intervals (lattice index pairs) it split, and the error estimate of
    each split interval (the share of the lifetimes its midpoint changed)."""

    states: int
    lifetimes_s: tuple[float, ...]
    largest_N: float
    split_u: tuple[tuple[int, int], ...] = ()
    split_dp: tuple[tuple[int, int], ...] = ()
    error_u: dict = field(default_factory=dict)
    error_dp: dict = field(default_factory=dict)


@dataclass(frozen=True)
class AdaptiveAxes:
    """The chosen lattice indices of u and dp, and the rounds that chose them."""

    u_index: tuple[int, ...]
    dp_index: tuple[int, ...]
    rounds: tuple[Round, ...] = ()

    def describe(self) -> str:
        return f"adaptive {len(self.u_index)} u x {len(self.dp_index)} dp"


def goal_for(model, forces_N: Sequence[float], contact=None) -> SuctionGoal | None:
    """The goal of a lifetime job's table (`model`: its `reduced.LeakageModel`, any table;
    contact: the table's `fem.interface.ContactLaw`, None: frictionless), or None where the job
    needs the full grid: with relaxation the stiffness factor follows the contact time and the
    paths cross the table where the unrelaxed ones do not, and with sticking or Coulomb contact a
    state depends on the dp steps that reached it, which the adaptive table takes differently."""
    if model.relaxation is not None or model.fluid != "air":
        return None
    if contact is not None and contact.law != "frictionless":
        return None
    return SuctionGoal(replace(model, suction=None, stiffness=None), tuple(forces_N))


def lattice_subtable(table, u_index: Sequence[int], dp_index: Sequence[int]):
    """The `SuctionTable` on the rows u_index and columns dp_index of a full-lattice table (what an
    adaptive build gets from the same states; tests and benchmarks use it as the oracle)."""
    from reduced.suction_table import SuctionTable

    iu, jd = np.asarray(u_index), np.asarray(dp_index)
    cut = {name: getattr(table, name)[np.ix_(iu, jd)] for name in ("F1_N", "V_m3", "seal_r_m", "cut_r_m")}
    return SuctionTable(u_m=table.u_m[iu], dp_Pa=table.dp_Pa[jd], **cut, E_Pa=table.E_Pa,
                        profiles=tuple(tuple(table.profiles[i][j] for j in jd) for i in iu),
                        provenance=table.provenance, sealed=table.sealed[np.ix_(iu, jd)],
                        seal_rings=None if table.seal_rings is None else
                        tuple(tuple(table.seal_rings[i][j] for j in jd) for i in iu))


def adaptive_axes(table_on: Callable[[tuple[int, ...], tuple[int, ...]], Any], n_u: int, n_dp: int,
                  goal: SuctionGoal, spec: AdaptiveSpec = AdaptiveSpec()) -> AdaptiveAxes:
    """The lattice indices of the table the goal needs (module docstring). table_on(u_index,
    dp_index) returns the `SuctionTable` on those lattice rows and columns (solving what it
    lacks); n_u, n_dp: the lattice's sizes."""
    U = sorted(set(range(0, n_u, spec.u_every)) | {n_u - 1})
    D = sorted(set(range(0, n_dp, spec.dp_every)) | {n_dp - 1})
    settled: set[tuple[str, int, int]] = set()       # intervals whose last split changed little
    rounds = []
    paths = _Paths(goal, table_on, U, D)
    U, D = paths.band()
    paths = _Paths(goal, table_on, U, D)
    for _ in range(spec.max_rounds):
        split_u = [(a, b) for k, (a, b) in enumerate(zip(U, U[1:])) if b - a > 1
                   and ("u", a, b) not in settled and paths.crosses("u", k)]
        split_dp = [(a, b) for k, (a, b) in enumerate(zip(D, D[1:])) if b - a > 1
                    and ("dp", a, b) not in settled and paths.crosses("dp", k)]
        if not split_u and not split_dp:
            rounds.append(Round(len(U) * len(D), paths.lifetimes, paths.largest_N))
            break
        U2 = sorted(set(U) | {(a + b) // 2 for a, b in split_u})
        D2 = sorted(set(D) | {(a + b) // 2 for a, b in split_dp})
        new = _Paths(goal, table_on, U2, D2)
        err_u, err_dp = paths.errors_against(new)
        rounds.append(Round(len(U) * len(D), paths.lifetimes, paths.largest_N, tuple(split_u), tuple(split_dp),
                            {k: err_u.get(k, 0.0) for k in split_u}, {k: err_dp.get(k, 0.0) for k in split_dp}))
        for axis, intervals, err in (("u", split_u, err_u), ("dp", split_dp, err_dp)):
            for a, b in intervals:
                if err.get((a, b), 0.0) <= spec.tol:
                    m = (a + b) // 2
                    settled |= {(axis, a, m), (axis, m, b)}
        U, D = new.band()
        paths = new if (U, D) == (U2, D2) else _Paths(goal, table_on, U, D)
    else:
        rounds.append(Round(len(U) * len(D), paths.lifetimes, paths.largest_N))
    return AdaptiveAxes(tuple(U), tuple(D), tuple(rounds))


class _Paths:
    """The goal's lifetimes on one table: the paths, their integrand, and the table's axes."""

    def __init__(self, goal: SuctionGoal, table_on: Callable, U: list[int], D: list[int]):
        from reduced.lifetime import largest_holdable_force, solve_lifetime
        from reduced.lifetime.routes import ROUTES

        self.U, self.D = U, D
        self.table = table = table_on(tuple(U), tuple(D))
        self.model = replace(goal.model, suction=table)
        route = ROUTES["coupled"]
        self.cavity, self.u_start, _ = route.cavity(self.model, dict(route.options))
        self.records = [solve_lifetime(self.model, F, route="coupled") for F in goal.forces_N]
        self.largest_N = float(largest_holdable_force(self.model, route="coupled"))
        self.lifetimes = tuple(float(r.lifetime_s) for r in self.records)
        self.forces = goal.forces_N
        self.start_dp = self.cavity.start(self.u_start)[0]
        self.end_dp = self.cavity._dp_range(self.largest_N)[0]

    def _points(self) -> tuple[np.ndarray, np.ndarray]:
        """Every (u, dp) a path visits, its start and the largest force's end."""
        u = [np.array([self.u_start, self.table.u_m[0]])]
        dp = [np.array([self.start_dp, self.end_dp])]
        for r in self.records:
            if len(r.trajectory["t_s"]):
                u.append(1e-3 * np.asarray(r.trajectory["u_mm"]))
                dp.append(self.model.p_a_Pa - np.asarray(r.trajectory["p_b_Pa"]))
        return np.concatenate(u), np.concatenate(dp)

    def crosses(self, axis: str, k: int) -> bool:
        """Whether a path visits the k-th interval of the axis."""
        u, dp = self._points()
        x, grid = (u, self.table.u_m) if axis == "u" else (dp, self.table.dp_Pa)
        return bool(np.any((x >= grid[k]) & (x <= grid[k + 1])))

    def band(self) -> tuple[list[int], list[int]]:
        """The axes (lattice indices) cut one interval above the highest u and dp any path visits."""
        U, D = self.U, self.D
        u, dp = self._points()
        keep_u = int(np.searchsorted(self.table.u_m, u.max(), side="left")) + 2
        keep_dp = int(np.searchsorted(self.table.dp_Pa, dp.max(), side="left")) + 2
        return U[:max(keep_u, 2)], D[:max(keep_dp, 2)]

    def errors_against(self, new: "_Paths") -> tuple[dict, dict]:
        """Per interval of this table's u and dp axes (by lattice index), the share of the goal's
        lifetimes that changes when the new table's midpoints are added (module docstring)."""
        U, D = self.U, self.D
        err_u: dict = {}
        err_dp: dict = {}

        def intervals(u: np.ndarray, dp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            i = np.clip(np.searchsorted(self.table.u_m, u) - 1, 0, len(U) - 2)
            j = np.clip(np.searchsorted(self.table.dp_Pa, dp) - 1, 0, len(D) - 2)
            return i, j

        def charge(u: np.ndarray, dp: np.ndarray, amount: np.ndarray) -> None:
            """Add to each interval the shares of the points (u, dp) that lie in it."""
            i, j = intervals(np.atleast_1d(u), np.atleast_1d(dp))
            for err, index, axis in ((err_u, i, U), (err_dp, j, D)):
                for k in np.unique(index):
                    total = float(np.sum(np.atleast_1d(amount)[index == k]))
                    key = (axis[k], axis[k + 1])
                    err[key] = err.get(key, 0.0) + total

        for F, r, life, life_new in zip(self.forces, self.records, self.lifetimes, new.lifetimes):
            if not len(r.trajectory["t_s"]) or not (math.isfinite(life) and life > 0):
                continue
            u = 1e-3 * np.asarray(r.trajectory["u_mm"])
            dp = self.model.p_a_Pa - np.asarray(r.trajectory["p_b_Pa"])
            N, q = np.asarray(r.trajectory["N"]), np.asarray(r.trajectory["N_dot_per_s"])
            N2, q2 = new._along(F, dp)
            ok = np.isfinite(N2[1:]) & np.isfinite(N2[:-1]) & (q2[1:] > 0) & (q2[:-1] > 0)
            seg = 0.5 * (1 / q[1:] + 1 / q[:-1]) * np.diff(N)
            seg2 = np.where(ok, 0.5 * (1 / np.where(ok, q2[1:], 1) + 1 / np.where(ok, q2[:-1], 1)) * np.diff(N2), 0.0)
            charge(0.5 * (u[1:] + u[:-1]), 0.5 * (dp[1:] + dp[:-1]), np.abs(np.where(ok, seg2 - seg, -seg)) / life)
            ends = abs(life_new - life) / life
            charge(np.array([u[0], u[-1]]), np.array([dp[0], dp[-1]]), np.array([ends, ends]))
        ends = abs(new.largest_N - self.largest_N) / self.largest_N
        charge(np.array([self.u_start, self.table.u_m[0]]), np.array([self.start_dp, self.end_dp]),
               np.array([ends, ends]))
        return err_u, err_dp

    def _along(self, F: float, dp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N, Ndot) of this table's F branch at the pressure differences dp (nan outside it)."""
        N = np.full(dp.size, np.nan)
        q = np.full(dp.size, np.nan)
        for k, d in enumerate(dp):
            try:
                u, N[k] = self.cavity.content(F, float(d))
            except ValueError:
                continue
            q[k] = self.cavity.Ndot(u, float(d))
        return N, q
