"""The coupled route's suction table built around the paths: only the states its lifetimes read.

Scheme, and why. The cup's paths at the asked forces are curves in the (u, dp) plane; a tensor
grid carries every row through every force's dp window, but `reduced.coupled` reads a table with
holes (`reduced.coupled_holes`): states only where the interpolation of a visited point reads
them, an error (`MissingStates`, naming the states) where it would read a hole. The table lives
on the full grid's axes (the lattice, `DEFAULT_GRID`), so every value the lifetimes read is the
full table's own and so are the lifetimes (to the root finders' tolerance and the FEM solver's:
a state reached by another dp ramp is the same state for frictionless contact). The build:

1. the seed: the goal's paths (its forces, the start and the largest holdable force) on the
   tensor sub-grid of every `u_every`-th u and `dp_every`-th dp: cheap, and within a few
   lattice cells of the full table's paths; or, where the goal gives a hint (points near which
   the paths are expected, e.g. another route's trajectories), the cells around those points
   (a row and four dp columns either side);
2. on the lattice, the states the interpolation of those paths reads, widened by `margin` cells;
3. the goal's lifetimes and largest holdable force on that table; where they read a hole, the
   missing states (widened by `margin`) are added and they are computed again, until they run
   through. A walk names the states next to its last point first (`reduced.coupled_holes`:
   `Holes.near_missing`), not the whole line or gap it would otherwise have to search. A missing
   state brings with it the `reach` rows below it, in its column and the next either side: the
   paths run down in u (the plate rising as the gas leaks in; at nearly constant dp in the raised
   rows, climbing in dp through cup B's pressed rows), and a round that adds one row at a time
   would need one round per row. What they read then is built, and nothing else is asked of the
   table.

The cost and the lifetimes against the full grid: benchmarks/bench_coupled.py --around.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from validation.bridge.coupled.adaptive import SuctionGoal

__all__ = ["AroundSpec", "AroundBuild", "around_paths", "holed_subtable"]


@dataclass(frozen=True)
class AroundSpec:
    """The seed's sub-grid (every `u_every`-th u and `dp_every`-th dp of the lattice, its raised
    rows only down to u = -seed_depth_h1 h1: the rows below, down to the plate's floor, are
    reached by the rounds where the paths go), the cells added around each path point and each
    missing state, and a bound on the rounds."""

    u_every: int = 24
    dp_every: int = 5
    margin: int = 0
    max_rounds: int = 100
    reach: int = 4
    seed_depth_h1: float = 1.0

    def __post_init__(self) -> None:
        if not all(isinstance(k, int) and k >= 1 for k in (self.u_every, self.dp_every, self.max_rounds)):
            raise ValueError(f"u_every, dp_every, max_rounds: need integers >= 1, got "
                             f"{self.u_every}, {self.dp_every}, {self.max_rounds}")
        if not (isinstance(self.margin, int) and self.margin >= 0):
            raise ValueError(f"margin: need an integer >= 0, got {self.margin}")
        if not (isinstance(self.reach, int) and self.reach >= 0):
            raise ValueError(f"reach: need an integer >= 0, got {self.reach}")
        if not self.seed_depth_h1 >= 0:
            raise ValueError(f"seed_depth_h1: need a depth >= 0 (in h1), got {self.seed_depth_h1}")


@dataclass(frozen=True, eq=False)
class AroundBuild:
    """The table with holes, the states asked of the lattice (the seed's included), and per
    round the states built and how many were missing."""

    table: Any
    asked: np.ndarray
    rounds: tuple[tuple[int, int], ...]


def holed_subtable(table, built: np.ndarray):
    """`table` with holes wherever `built` is False (what a build around the paths gets from the
    same states; tests and benchmarks use it with the full table as the oracle)."""
    from reduced.suction_table import SuctionTable

    cut = {name: np.where(built, getattr(table, name), np.nan) for name in ("F1_N", "V_m3", "seal_r_m", "cut_r_m")}
    return SuctionTable(u_m=table.u_m, dp_Pa=table.dp_Pa, **cut, E_Pa=table.E_Pa,
                        profiles=tuple(tuple(p if built[i, j] else None for j, p in enumerate(row))
                                       for i, row in enumerate(table.profiles)),
                        provenance=table.provenance, sealed=table.sealed | ~built,
                        seal_rings=None if table.seal_rings is None else
                        tuple(tuple(x if built[i, j] else None for j, x in enumerate(row))
                              for i, row in enumerate(table.seal_rings)))


def around_paths(table_on: Callable[[np.ndarray], Any], n_u: int, n_dp: int, goal: SuctionGoal,
                 spec: AroundSpec = AroundSpec()) -> AroundBuild:
    """The table with holes the goal's lifetimes read (module docstring). table_on(built) returns
    the `SuctionTable` on the lattice with the states `built` [n_u, n_dp] (solving what it lacks)."""
    asked = np.zeros((n_u, n_dp), dtype=bool)
    memo: dict = {}                                   # node conductances, shared by the rounds
    built = np.zeros_like(asked)
    if goal.hint:                                     # the paths' expected points: no seed grid
        lattice = table_on(asked)
        reads = _Reads(lattice.u_m, goal.model.kappa * lattice.dp_Pa)
        for u, dp in goal.hint:
            _widen(built, reads(u, dp), max(spec.margin, 1), cols=4)
    else:
        empty = table_on(asked)
        # the seed's deepest raised row (all of them if the table does not record h1)
        deep = 0 if math.isnan(empty.h1_m) else int(np.flatnonzero(empty.u_m >= -spec.seed_depth_h1 * empty.h1_m)[0])
        U = sorted(set(range(deep, n_u, spec.u_every)) | {n_u - 1})
        D = sorted(set(range(0, n_dp, spec.dp_every)) | {n_dp - 1})
        asked[np.ix_(U, D)] = True
        lattice = table_on(asked)
        reads = _Reads(lattice.u_m, goal.model.kappa * lattice.dp_Pa)
        for u, dp in _path_points(goal, _compressed(lattice, U, D), memo):
            _widen(built, reads(u, dp), spec.margin)
    rounds = []
    # the lifetimes, then (unless the goal leaves it out) the largest force
    every = list(range(len(goal.forces_N) + int(goal.largest)))
    pending = every
    for _ in range(spec.max_rounds):
        asked |= built
        table = table_on(built)
        ran = pending
        missing, pending = _missing(goal, table, memo, ran)
        if not missing and ran != every:              # all of them once more, on the last table
            missing, pending = _missing(goal, table, memo, every)
        rounds.append((int(built.sum()), len(missing)))
        if not missing:
            return AroundBuild(table, asked, tuple(rounds))
        _widen(built, missing, spec.margin)
        _reach_down(built, missing, spec.reach)
    raise RuntimeError(f"suction table around the paths: states still missing after {spec.max_rounds} rounds")


class _Reads:
    """The lattice nodes the interpolation of a point reads (every one, built or not)."""

    def __init__(self, u: np.ndarray, dp: np.ndarray):
        from reduced.coupled_holes import Holes

        self.holes = Holes(np.zeros((u.size, dp.size), dtype=bool), u, dp, "pchip")

    def __call__(self, u: float, dp: float) -> list[tuple[int, int]]:
        return self.holes.missing(u, dp)


def _reach_down(built: np.ndarray, nodes, reach: int) -> None:
    """Mark the `reach` rows below each missing node (the paths run down in u as the gas leaks in)
    in its column and the next either side."""
    for i, j in nodes:
        built[max(i - reach, 0):i + 1, max(j - 1, 0):min(j + 2, built.shape[1])] = True


def _widen(built: np.ndarray, nodes, margin: int, cols: int | None = None) -> None:
    """Mark `nodes` and every node within `margin` cells of one as built (`cols` along dp, if
    given)."""
    n_u, n_dp = built.shape
    c = margin if cols is None else cols
    for i, j in nodes:
        built[max(i - margin, 0):min(i + margin + 1, n_u), max(j - c, 0):min(j + c + 1, n_dp)] = True


def _compressed(table, U: list[int], D: list[int]):
    """The complete table on the rows U and columns D of a lattice table (all built there)."""
    from validation.bridge.coupled.adaptive import lattice_subtable

    return lattice_subtable(table, U, D)


def _cavity(goal: SuctionGoal, table, memo: dict):
    """The route's cavity of the goal on `table`, sharing the node conductances in `memo`."""
    from reduced.lifetime.routes import ROUTES

    route = ROUTES["coupled"]
    options = dict(route.options, **({} if goal.u_start_m is None else {"u_start_m": goal.u_start_m}))
    cavity, u_start, _ = route.cavity(replace(goal.model, suction=table), options)
    return replace(cavity, conductances=memo), u_start


def _path_points(goal: SuctionGoal, table, memo: dict) -> list[tuple[float, float]]:
    """Every (u, dp) the goal's paths visit on a complete table: the lifetimes' trajectories, the
    start and the cup raised at its start content (the largest holdable force's path)."""
    cavity, u_start = _cavity(goal, table, memo)
    dp_start, N0 = cavity.start(u_start)
    points = [(u_start, dp_start)]
    for F in goal.forces_N:
        try:
            r = cavity.lifetime(F, u_start)
        except ValueError:          # the coarse table fails where the lattice may not: no seed
            continue
        points += list(zip(r.u_m.tolist(), r.dp_Pa.tolist()))
    us, dps, _, _ = cavity._raised_at(N0, u_start)
    points += list(zip(us.tolist(), dps.tolist()))
    return points


def _missing(goal: SuctionGoal, table, memo: dict, pending: list[int]) -> tuple[list[tuple[int, int]], list[int]]:
    """(the states the pending computations (index k < len(forces): the k-th lifetime, else the
    largest holdable force) read and the table lacks, the computations that lacked some). Each is
    computed on its own, so that one round finds the holes of all of them; one that ran through
    reads only built states, which added states do not change."""
    from reduced.suction_table import MissingStates

    cavity, u_start = _cavity(goal, table, memo)
    forces = goal.forces_N
    missing: set[tuple[int, int]] = set()
    failed = []
    for k in pending:
        try:
            cavity.lifetime(forces[k], u_start) if k < len(forces) else cavity.largest_force(u_start)
        except MissingStates as err:
            missing |= set(err.nodes)
            failed.append(k)
    return sorted(missing), failed
