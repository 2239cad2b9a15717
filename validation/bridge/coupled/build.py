"""The FEM suction table of a design, built once and kept: the input of the coupled route.

`SuctionGridSpec` names the (u, dp) grid: the default one (`DEFAULT_GRID`: 105 u values graded towards
u = 0 up to 0.8 h1, u = 0, and below them 540 raised rows, where the plate is above the free cup's
touching height and the seal is held by the suction alone, evenly down to the plate's floor
h1 - 2 L (`fem.branch_end`: every 0.045 mm for cups A and B), below every detachment the held cup's
walk can give; a build around the paths solves only the rows they reach; dp = 0, 1, ..., 100 kPa. Halving the
pressed rows' u spacing moves cup A's lifetimes by <= 0.2 %, the dp spacing by <= 0.8 %,
benchmarks/bench_coupled.py; the raised rows': benchmarks/bench_coupled_raised.py) and a coarse one
for quick checks (`QUICK_GRID`, pressed rows only: its branches end at the table's edge, u > 0).
`suction_table_for` runs `fem.suction.suction_grid` on a design and converts it to the reduced
model's `SuctionTable`; with a cache directory the table goes through `validation.bridge.cache`, keyed by the
design, the law, the grid and a hash of the sources that make it (`fem`, `validation.bridge.coupled` and
the table's data types in `reduced`), so a second call computes nothing and a change to that code
recomputes (a change to the leak, which reads the table, does not).
With a `SuctionGoal` (the model and the pull forces the table is for) it builds only the states
of the grid that those lifetimes read: a table with holes around their paths
(`validation.bridge.coupled.around`, the default), or the rows and columns of a tensor grid
(`AdaptiveSpec`, `validation.bridge.coupled.adaptive`); the goal and the whole of `reduced` are
then part of the key.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from validation.bridge.coupled.adaptive import AdaptiveSpec, SuctionGoal, adaptive_axes
from validation.bridge.coupled.around import AroundSpec, around_paths

if TYPE_CHECKING:
    from fem.interface import ContactLaw

__all__ = ["SuctionGridSpec", "DEFAULT_GRID", "PRESSED_GRID", "QUICK_GRID", "SuctionGoal", "AdaptiveSpec", "AroundSpec",
           "around_table", "full_rows", "suction_table_for"]

_U_COARSE = (0.001, 0.0025, 0.005, 0.0075, 0.01, 0.0175, 0.025, 0.0375, 0.05, 0.075, 0.1, 0.125,
             0.15, 0.175, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8)


@dataclass(frozen=True)
class SuctionGridSpec:
    """Plate displacements as fractions of the cup's height h1, pressure differences [kPa], and
    `raised_rows` rows below u = 0 evenly down to the plate's floor u_floor = h1 - 2 L
    (`fem.branch_end.plate_floor_m`: u = k u_floor / raised_rows, k = 1 ... raised_rows), where
    the raised cup's branches end at the latest."""

    u_fractions: tuple[float, ...]
    dp_kPa: tuple[float, ...]
    raised_rows: int = 0

    def __post_init__(self) -> None:
        if not (isinstance(self.raised_rows, int) and self.raised_rows >= 0):
            raise ValueError(f"raised_rows: need an integer >= 0, got {self.raised_rows!r}")

    def u_m(self, h1_m: float, floor_m: float | None = None) -> np.ndarray:
        """The u axis [m] of a cup of height h1_m whose plate floor is floor_m (< 0; needed with
        raised_rows)."""
        u = np.minimum(np.array(self.u_fractions) * h1_m, h1_m)
        if not self.raised_rows:
            return u
        if floor_m is None or not floor_m < 0:
            raise ValueError(f"floor_m: the raised rows need the plate's floor (< 0), got {floor_m}")
        raised = floor_m * np.arange(self.raised_rows, 0, -1) / self.raised_rows
        return np.unique(np.concatenate([raised, u]))

    def halved_raised(self) -> "SuctionGridSpec":
        """The same grid with the raised rows' spacing halved."""
        return SuctionGridSpec(self.u_fractions, self.dp_kPa, 2 * self.raised_rows)

    @property
    def dp_Pa(self) -> np.ndarray:
        return 1e3 * np.array(self.dp_kPa)

    def describe(self) -> str:
        raised = f" (and {self.raised_rows} raised down to the floor)" if self.raised_rows else ""
        return f"{len(self.u_fractions)} u{raised} x {len(self.dp_kPa)} dp"


def _halved(u: tuple[float, ...]) -> tuple[float, ...]:
    """The values with the midpoint of every interval added."""
    return tuple(sorted(set(u) | {0.5 * (a + b) for a, b in zip(u, u[1:])}))


#: the raised rows (u < 0) of the default grid: evenly down to the plate's floor h1 - 2 L (cup A:
#: every 0.045 mm, 0.005 h1, to -24.3 mm; cup B: every 0.046 mm to -24.6 mm)
RAISED_ROWS = 540

DEFAULT_GRID = SuctionGridSpec((0.0,) + _halved(_halved(_U_COARSE)), tuple(float(x) for x in range(0, 101)),
                               raised_rows=RAISED_ROWS)
#: the default grid's pressed rows only (u > 0): its branches end at the table's edge u > 0
PRESSED_GRID = SuctionGridSpec(_halved(_halved(_U_COARSE)), DEFAULT_GRID.dp_kPa)
QUICK_GRID = SuctionGridSpec(_U_COARSE, tuple(float(x) for x in range(0, 101, 5)))


def suction_table_for(geometry, *, fidelity: str = "coarse", contact: ContactLaw | None = None,
                      E_Pa: float = 4e6, nu: float = 0.49,
                      grid: SuctionGridSpec = DEFAULT_GRID, cache_dir: str | Path | None = None,
                      progress: Callable[[float, str], None] | None = None,
                      goal: SuctionGoal | None = None, adaptive: AroundSpec | AdaptiveSpec = AroundSpec()):
    """The `SuctionTable` of a design (`fem.geometry.CupGeometry` or a preset name 'A', 'B') at a
    mesh level, contact law (a `fem.interface.ContactLaw`, None: frictionless) and grid (module
    docstring); with a `goal`, only the part of the grid the goal's lifetimes need, chosen as
    `adaptive` says (`AroundSpec`: the states around the paths, a table with holes; `AdaptiveSpec`:
    a tensor sub-grid). `progress(fraction, message)` while the FEM runs. Raises
    `fem.solver.ConvergenceError` where a state does not converge."""
    from fem.geometry import cup_geometry
    from fem.interface import ContactLaw
    from validation.bridge.cache import Cache, source_hash

    if isinstance(geometry, str):
        geometry = cup_geometry(geometry)
    contact = ContactLaw() if contact is None else contact
    if not isinstance(contact, ContactLaw):
        raise ValueError(f"contact: expected a fem.interface.ContactLaw, got {type(contact).__name__}")
    if goal is not None:
        build = Cache(cache_dir).cached(_build_around if isinstance(adaptive, AroundSpec) else _build_adaptive,
                                        ignore=["progress"])
        code = source_hash("fem", "validation/bridge/coupled", "reduced")
        return build(geometry, fidelity, contact, E_Pa, nu, grid, goal, adaptive, code, progress=progress)
    build = Cache(cache_dir).cached(_build, ignore=["progress"])
    code = source_hash("fem", "validation/bridge/coupled", *_TABLE_TYPES)
    return build(geometry, fidelity, contact, E_Pa, nu, grid, code, progress=progress)


#: the `reduced` modules a table is made of (part of its key; the rest of `reduced`, the leak
#: included, only reads tables; an entry that no longer loads is recomputed by joblib)
_TABLE_TYPES = ("reduced/suction_table.py", "reduced/stiffness_curve.py", "reduced/coupled_seal.py")


def _build_adaptive(geometry, fidelity, contact, E_Pa, nu, grid, goal, adaptive, code, progress=None):
    from fem.material import NeoHookean
    from fem.mesh import cup_mesh
    from fem.suction import SuctionStates
    from validation.bridge.coupled.table import suction_table

    mesh = cup_mesh(geometry, fidelity)
    states = SuctionStates(mesh, NeoHookean(E_Pa=E_Pa, nu=nu), contact)
    u, dp = full_rows(grid, mesh), grid.dp_Pa
    provenance = {"geometry": geometry.describe(), "fidelity": fidelity}

    def table_on(iu: tuple[int, ...], jd: tuple[int, ...]):
        if progress:
            progress(0.0, f"{states.solved} states solved; table {len(iu)} u x {len(jd)} dp")
        return suction_table(states.grid(u[list(iu)], dp[list(jd)], progress=progress), provenance)

    axes = adaptive_axes(table_on, u.size, dp.size, goal, adaptive)
    final = states.grid(u[list(axes.u_index)], dp[list(axes.dp_index)])
    return suction_table(final, {**provenance, "grid": axes.describe(), "lattice": grid.describe(),
                                 "states_solved": states.solved, "forces_N": list(goal.forces_N)})


def _build_around(geometry, fidelity, contact, E_Pa, nu, grid, goal, spec, code, progress=None):
    from fem.cup import cup_height
    from fem.material import NeoHookean
    from fem.mesh import cup_mesh
    from fem.suction import SuctionStates

    mesh = cup_mesh(geometry, fidelity)
    # a new row is pressed from the kept row below it in one step (cut where Newton needs it): the
    # rows are close, and a frictionless state does not depend on the path that reached it
    states = SuctionStates(mesh, NeoHookean(E_Pa=E_Pa, nu=nu), contact, initial_step=1.0, max_step=1.0)
    u, dp = grid.u_m(cup_height(mesh), states.floor_m), grid.dp_Pa
    return around_table(states, u, dp, goal, spec, contact, {"geometry": geometry.describe(), "fidelity": fidelity},
                        grid.describe(), progress)


def around_table(states, u_m: np.ndarray, dp_Pa: np.ndarray, goal: SuctionGoal, spec: AroundSpec, contact,
                 provenance: dict, lattice: str, progress: Callable[[float, str], None] | None = None):
    """The table with holes around the goal's paths on the lattice u_m x dp_Pa, its states solved
    by `states` (a `fem.suction.SuctionStates` of the law `contact`); `lattice` names the grid in
    the provenance."""
    from validation.bridge.coupled.table import holed_suction_table

    converted: dict = {}                 # the states' hand-off values, shared by the rounds' tables

    def table_on(built: np.ndarray):
        if progress:
            progress(0.0, f"{states.solved} states solved; table of {int(built.sum())}")
        return holed_suction_table(states, u_m, dp_Pa, built, contact, provenance, converted)

    done = around_paths(table_on, u_m.size, dp_Pa.size, goal, spec)
    return holed_suction_table(states, u_m, dp_Pa, done.table.built, contact,
                               {**provenance, "grid": f"{int(done.table.built.sum())} states around the paths on "
                                f"{lattice}", "lattice": lattice, "states_solved": states.solved,
                                "rounds": [list(r) for r in done.rounds], "forces_N": list(goal.forces_N)},
                               converted)


def _build(geometry, fidelity, contact, E_Pa, nu, grid, code, progress=None):
    from fem.material import NeoHookean
    from fem.mesh import cup_mesh
    from fem.suction import suction_grid
    from validation.bridge.coupled.table import suction_table

    mesh = cup_mesh(geometry, fidelity)
    result = suction_grid(mesh, NeoHookean(E_Pa=E_Pa, nu=nu), full_rows(grid, mesh), grid.dp_Pa,
                          contact=contact, progress=progress)
    return suction_table(result, {"geometry": geometry.describe(), "fidelity": fidelity,
                                  "grid": grid.describe()})


#: a full table (no goal) holds the raised rows down to u = -FULL_DEPTH_H1 h1 only: below, the
#: raised cup at large dp is pulled far past any path's use and each row costs all its dp; a build
#: around the paths reaches the floor where they go
FULL_DEPTH_H1 = 0.6


def full_rows(grid: SuctionGridSpec, mesh) -> np.ndarray:
    """The u axis [m] of a full table of `grid` on `mesh` (its raised rows down to -FULL_DEPTH_H1 h1)."""
    from fem.cup import cup_height

    h1 = cup_height(mesh)
    u = grid.u_m(h1, _floor(mesh) if grid.raised_rows else None)
    return u[u >= -FULL_DEPTH_H1 * h1 * (1 + 1e-12)]


def _floor(mesh) -> float:
    """The plate's floor [m] of the cup of `mesh` (`fem.branch_end.plate_floor_m`)."""
    from fem.suction import plate_floor_of

    return plate_floor_of(mesh)
