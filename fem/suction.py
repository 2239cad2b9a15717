"""The cup under suction: its response on a grid of plate displacement u and cavity pressure dp.

    grid = suction_grid(mesh, NeoHookean(), u_m=[-1e-3, 0.5e-3, 1e-3, 2e-3], dp_Pa=[0, 2e4, 5e4, 1e5])
    grid.F1_N[i, j], grid.V_m3[i, j], grid.seal_r_m[i, j], grid.profiles[i][j], grid.sealed[i, j]

For every u_i > 0 the cup is pressed to u_i with no suction (one displacement-controlled path
through all the u_i), then, with the plate held, dp = p_a - p_b is ramped through the dp_j on
the cavity surface (`fem.cavity`: the conservative load dp V_cav). At u <= 0 the plate is at or
above the free cup's touching height: without suction the rim does not touch, so a ramp in dp
there would start from a cavity that is not closed. Such a state (u, dp) is reached the way the
sealed cup gets there: from the state at the same dp and the next larger u (ultimately from the
row u_anchor > 0, pressed and ramped as above), the plate raised at fixed dp. Each grid value is a
converged state reached exactly (the paths are cut at the grid points), so no interpolation
enters here.

Sealed (the criterion): a state is sealed when at least one node of the cavity chain lies on the
plane (`fem.cavity`'s tolerance), as the FEM branch at fixed N decides that its seal opened
(`fem.gas_branch`). At u > 0 every state is. At u <= 0 and small dp the rim hangs above the plane:
the load dp V_cav then acts on a cavity closed only by the vertical drop from the rim to the
plane, which no seal holds; `sealed` is False there and the numbers of such a state are not a
cup under suction (the hand-off gives them as no-seal markers, `validation.bridge.coupled.table`).

The state (u, dp) is what the coupled reduced model needs (`reduced.coupled`): the pull on the
handle F1 = dp pi r_k^2 - N (eq. 5 with the FEM's contact force N and seal radius r_k), the gas
volume V, and the contact-pressure profile through which the gas leaks. Frictionless contact is
path independent, so the order of loading (press, then suck, then raise) does not matter; with
sticking or Coulomb contact it does, and the grid is the response to that order.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from skfem import Mesh

from .branch_end import plate_floor_m
from .cavity import CavitySurface, PressurizedMechanics
from .contact import PressureProfile
from .cup import CupSetup, _joined, _measure, cup_height
from .integrity import StateRejected, check_state
from .interface import ContactLaw
from .material import NeoHookean
from .solver import ConvergenceError, SolverOptions, SolverStats, StepResult, follow_path

__all__ = ["SuctionGrid", "SuctionStates", "plate_floor_of", "suction_grid"]


@dataclass(frozen=True, eq=False)
class SuctionGrid:
    """The cup's converged states on the grid (module docstring); arrays are [len(u), len(dp)]."""

    h1_m: float
    contact: str                # the law's name (`contact_law`: the law with its mu)
    friction: float             # Coulomb's mu (0 for the other laws)
    material: NeoHookean
    u_m: np.ndarray
    dp_Pa: np.ndarray
    F1_N: np.ndarray            # pull on the handle (> 0 pulls the cup off the plane)
    contact_force_N: np.ndarray  # N: the plane's reaction less dp on the zone beyond the seal
    V_m3: np.ndarray            # cavity volume (geometric)
    seal_r_m: np.ndarray        # r_k: radius of the seal node (the cavity's edge)
    cut_r_m: np.ndarray         # outer end of the outermost contact zone (the load's extent)
    r_c_m: np.ndarray           # inner contact radius of the pressure profile
    potential_J: np.ndarray     # W + dp V_cav at the state (its dp-derivative is V_cav)
    sealed: np.ndarray          # bool: a node of the cavity chain on the plane (module docstring)
    profiles: tuple[tuple[PressureProfile, ...], ...] = field(repr=False)
    stats: SolverStats = field(repr=False)
    # the plane's reactions (r [m], lambda [N]) at the held nodes of each state (`RigidPlane.held_reactions`)
    reactions: tuple[tuple[tuple[np.ndarray, np.ndarray], ...], ...] = field(repr=False, default=())

    @property
    def contact_law(self) -> ContactLaw:
        """The contact law of the grid, with Coulomb's mu."""
        return ContactLaw(self.contact, self.friction)


def suction_grid(mesh: Mesh, material: NeoHookean, u_m: Sequence[float], dp_Pa: Sequence[float],
                 contact: ContactLaw | str = ContactLaw(),
                 friction: float = 0.0, wetting_m: float = 0.0,
                 progress: Callable[[float, str], None] | None = None, anchor_m: float | None = None,
                 **solver_opts: Any) -> SuctionGrid:
    """The cup's response at every (u_i, dp_j) (module docstring). u_m: increasing, in
    [u_floor, h1] (u <= 0: raised, module docstring; u_floor = h1 - 2 L, the plate's floor of the
    held cup's walk, `fem.branch_end.plate_floor_m`); dp_Pa: increasing, starting at 0. contact:
    a `fem.interface.ContactLaw`, or the law's name with Coulomb's mu as `friction` (as
    `fem.cup.compress_cup`). Raises ValueError for bad input, `fem.solver.ConvergenceError` naming
    u and dp where a pressed state cannot be reached, and `fem.integrity.StateRejected` (one) where
    a converged pressed state violates contact between the nodes or folds onto itself; a raised
    state no raise reaches holds no seal (`SuctionStates._raised`)."""
    states = SuctionStates(mesh, material, contact, friction, wetting_m, anchor_m, **solver_opts)
    return states.grid(u_m, dp_Pa, progress=progress)


class SuctionStates:
    """The cup's converged suction states, solved on demand and kept, so that a grid can grow by
    rows and columns (an adaptive table) without solving a state twice. A new u is pressed from
    the kept pressed state just below it, a new dp at u is ramped from the kept state just below
    it in that row; asked in increasing u and dp, as `grid` does, the solves are exactly
    `suction_grid`'s. Frictionless contact is path independent, so any order reaches the same
    states to the solver's tolerance; with sticking or Coulomb contact a state is the response
    to the path that reached it. A state at u <= 0 is raised from the kept state at the same dp
    and the next larger u up to `anchor_m` (default 0.001 h1, the default grid's smallest u > 0).
    For frictionless contact Newton starts a raise (a dp interval) on the secant of the two kept
    states above it at that dp (below it in that row): neighbouring states differ little and
    nearly linearly, so this halves the iterations (tests/test_suction_adaptive.py)."""

    def __init__(self, mesh: Mesh, material: NeoHookean, contact: ContactLaw | str = ContactLaw(),
                 friction: float = 0.0, wetting_m: float = 0.0, anchor_m: float | None = None,
                 **solver_opts: Any):
        self.mesh, self.material = mesh, material
        self.h1_m = cup_height(mesh)
        # the row u > 0 from which the states at u <= 0 are raised (module docstring)
        self.anchor_m = 1e-3 * self.h1_m if anchor_m is None else float(anchor_m)
        if not 0.0 < self.anchor_m <= self.h1_m:
            raise ValueError(f"anchor_m: must lie in (0, h1] = (0, {self.h1_m * 1e3:.4g} mm], got {anchor_m}")
        self._cup = CupSetup.of(mesh, material, contact, friction)
        self._options = SolverOptions(**solver_opts)
        # a dp interval is one load step unless it needs cutting: the grid itself is the sampling
        self._ramp_options = replace(self._options, initial_step=1.0, max_step=1.0)
        self._cavity = CavitySurface.of(mesh, wetting_m)
        # the lowest plate position of a raised row: the held cup's floor (fem.branch_end)
        self.floor_m = plate_floor_m(self)
        self._pressed: dict[float, StepResult] = {}
        self._rows: dict[float, dict[float, tuple[StepResult, tuple]]] = {}
        #: raised states no raise reaches (`_raised`): (u, dp) -> the cause
        self.unreached: dict[tuple[float, float], str] = {}
        self._unreached_below: dict[float, float] = {}
        self.stats: SolverStats | None = None     # the cost of every state solved so far

    @property
    def cavity(self) -> CavitySurface:
        """The cavity's surface (its chain of nodes from the plate's edge to the rim)."""
        return self._cavity

    @property
    def solved(self) -> int:
        """How many states (u, dp) have been solved."""
        return sum(len(row) for row in self._rows.values())

    def has(self, u: float, dp: float) -> bool:
        return dp in self._rows.get(u, {})

    def grid(self, u_m: Sequence[float], dp_Pa: Sequence[float],
             progress: Callable[[float, str], None] | None = None) -> SuctionGrid:
        """The states on u_m x dp_Pa (as `suction_grid`), solving only those not kept."""
        u = np.asarray(u_m, float)
        dp = np.asarray(dp_Pa, float)
        _check_axes(u, dp, self.h1_m, self.floor_m, self.material)
        todo = sum(not self.has(float(a), float(b)) for a in u for b in dp[1:])
        done = 0
        outputs = np.empty((u.size, dp.size), dtype=object)
        # pressed rows upwards in u, then the raised rows (u <= 0) downwards, each from the last
        order = [i for i in range(u.size) if u[i] > 0] + [i for i in range(u.size) if u[i] <= 0][::-1]
        for i in order:
            u_i = u[i]
            for j, dp_j in enumerate(dp):
                new = not self.has(float(u_i), float(dp_j))
                outputs[i, j] = self.state(float(u_i), float(dp_j))
                if new and j > 0 and progress:
                    done += 1
                    progress(done / max(todo, 1), f"u = {u_i * 1e3:.4g} mm, dp = {dp_j / 1e3:.4g} kPa")
        take = np.vectorize(lambda o, k: o[k], otypes=[float])
        cup = self._cup
        return SuctionGrid(
            h1_m=self.h1_m, contact=cup.plane.law.name, friction=cup.plane.law.mu, material=self.material,
            u_m=u, dp_Pa=dp, F1_N=take(outputs, 0), contact_force_N=take(outputs, 1), V_m3=take(outputs, 2),
            seal_r_m=take(outputs, 3), cut_r_m=take(outputs, 4), r_c_m=take(outputs, 5),
            potential_J=take(outputs, 6), sealed=take(outputs, 8).astype(bool),
            profiles=tuple(tuple(o[7] for o in row) for row in outputs), stats=self.stats,
            reactions=tuple(tuple(o[9] for o in row) for row in outputs))

    def state(self, u: float, dp: float) -> tuple:
        """(F1, N, V, r_k, r_cut, r_c, W + dp V, profile, sealed, reactions) at (u, dp), solved if
        not kept (reactions: `RigidPlane.held_reactions`)."""
        if u <= 0.0:
            return self._raised(u, dp)
        row = self._rows.setdefault(u, {})
        if dp not in row:
            below = [d for d in row if d < dp]
            if not below:
                state = self._press(u)
                row[0.0] = (state, _measured(state, self._cup.mech, self._cup, self._cavity))
                below = [0.0]
            if dp > 0.0:
                lo = max(below)
                return self._ramp(u, dp, lo, [d for d in below if d < lo])
        return row[dp][1]

    def _raised(self, u: float, dp: float) -> tuple:
        """The state at u <= 0: the plate raised at fixed dp from the kept state at dp with the
        next larger u (the anchor row's if none is kept; module docstring). Where that raise
        cannot reach u (the wall folds onto itself, `fem.integrity`, or Newton fails) no cup state
        is there: the state is returned as holding no seal, with nan numbers and no profile, and
        kept in `unreached` with its cause, as is every state at that dp above which it lies.
        For frictionless contact, where no kept state at dp lies within RAISE_REACH_H1 h1 above
        but a sealed one at a dp at most RAMP_REACH_E E smaller lies in this row, the state is
        ramped from that one instead (`_ramped`): the same state, without a long raise from far
        above (cup A, 6.9 mm raised at 80 kPa: 3 Newton iterations from 79 kPa against 170 from
        the anchor row; a ramp over 10 kPa near u = 0 costs more than a raise over 0.12 h1)."""
        row = self._rows.setdefault(u, {})
        if dp not in row and u <= self._unreached_below.get(dp, -np.inf):
            return _UNREACHED
        if dp not in row:
            above = [a for a, r in self._rows.items() if a > u and dp in r and a <= self.anchor_m]
            if not above:
                self.state(self.anchor_m, dp)
                above = [self.anchor_m]
            a = min(above)
            lower = [d for d, kept in row.items() if dp - RAMP_REACH_E * self.material.E_Pa <= d < dp and _sealed(kept)]
            if a - u > RAISE_REACH_H1 * self.h1_m and lower and self._cup.plane.law.name == "frictionless":
                ramped = self._ramped(u, dp, max(lower))
                if ramped is not None:
                    return ramped
            start = self._rows[a][dp][0]
            mech = (PressurizedMechanics(self._cup.mech, self._cavity, dp, schedule=lambda t, dp=dp: dp)
                    if dp > 0.0 else self._cup.mech)
            where = f"plate raised from u = {a * 1e3:.4g} to {u * 1e3:.4g} mm at dp = {dp / 1e3:.4g} kPa"
            further = [b for b in above if b > a]
            predict = None if not further else _secant(self._rows[min(further)][dp][0].u, start.u, min(further) - a,
                                                       a - u, RAISE_REACH_H1 * self.h1_m, 1.0)
            try:
                state = self._guessed(mech, _raising(self._cup, a), a - u, start, u, where, predict, self._options)
            except ConvergenceError as err:             # StateRejected included
                self.unreached[(u, dp)] = str(err)
                self._unreached_below[dp] = max(u, self._unreached_below.get(dp, -np.inf))
                return _UNREACHED
            row[dp] = (state, _measured(state, mech.at(1.0) if dp > 0.0 else mech, self._cup, self._cavity))
        return row[dp][1]

    def _ramped(self, u: float, dp: float, lo: float) -> tuple | None:
        """The raised state at (u, dp) ramped at the held plate from the kept sealed state (u, lo),
        lo < dp (`_raised`), or None where that ramp fails."""
        lower = [d for d, kept in self._rows[u].items() if d < lo and _sealed(kept)]
        try:
            return self._ramp(u, dp, lo, lower, " (raised)")
        except ConvergenceError:
            return None

    def _ramp(self, u: float, dp: float, lo: float, lower: list[float], label: str = "") -> tuple:
        """The state at (u, dp) reached by a dp ramp at the held plate from the kept state (u, lo),
        lo < dp, and kept; Newton starts on the secant of the kept states at max(`lower`) and lo
        (`_secant`; the ramp's t runs to 1 over dp - lo)."""
        row = self._rows[u]
        mech = PressurizedMechanics(self._cup.mech, self._cavity, dp, schedule=lambda t: lo + t * (dp - lo))
        predict = None if not lower else _secant(row[max(lower)][0].u, row[lo][0].u, lo - max(lower), dp - lo,
                                                 RAMP_REACH_E * self.material.E_Pa, dp - lo)
        state = self._guessed(mech, self._cup.plate_at(u, moving=False), 1.0, row[lo][0], u,
                              f"u = {u * 1e3:.4g} mm{label}, dp from {lo / 1e3:.4g} to {dp / 1e3:.4g} kPa", predict)
        row[dp] = (state, _measured(state, mech.at(1.0), self._cup, self._cavity))
        return row[dp][1]

    def _press(self, u: float) -> StepResult:
        """The cup pressed to u without suction, from the kept pressed state just below u."""
        below = [a for a in self._pressed if a < u]
        u_prev = max(below) if below else 0.0
        start = self._pressed[u_prev] if below else None
        state = self._segment(self._cup.mech, self._cup.plate_at(u_prev), u - u_prev, start, u,
                              f"pressing to u = {u * 1e3:.4g} mm")
        self._pressed[u] = state
        return state

    def _guessed(self, mech, dirichlet, t_max, start, u_plate, where, predict, options=None) -> StepResult:
        """`_segment` with Newton started on `predict`'s guess (None: on the start), and where that
        fails, without it: the guess only saves iterations, the state is the one the path reaches
        (for frictionless contact only, whose states do not depend on the path; with friction the
        guess is not used). Where the path converged but its state is rejected (the wall folds onto
        itself, `fem.integrity.StateRejected`) it is not repeated: that is the state the path
        reaches (cup A and B's builds: every such path repeated without the guess was rejected
        again, at 2-5 s each)."""
        if predict is not None and self._cup.plane.law.name == "frictionless":
            try:
                return self._segment(mech, dirichlet, t_max, start, u_plate, where, options, predict)
            except StateRejected:
                raise
            except ConvergenceError:
                pass
        return self._segment(mech, dirichlet, t_max, start, u_plate, where, options)

    def _segment(self, mech, dirichlet, t_max, start, u_plate, where, options=None, predict=None) -> StepResult:
        """The converged state at the end of one path (pressing, a dp interval at u_plate, or a
        raise at fixed dp); predict: Newton's first iterate of each step (`fem.solver.follow_path`)."""
        last: list[StepResult] = []
        if options is None:
            options = self._ramp_options if isinstance(mech, PressurizedMechanics) else self._options
        try:
            stats = follow_path(mech, dirichlet, t_max, plane=self._cup.plane, start=start,
                                options=options, on_step=last.append, predict=predict)
        except RuntimeError as err:
            err.args = (f"{where}: {err}",)
            raise
        self.stats = stats if self.stats is None else _joined(self.stats, stats)
        end = last[-1]
        check_state(self.mesh, end.u, u_plate, 0, u_plate)     # contact kept between the nodes
        return StepResult(0.0, end.u, end.r_int, end.energy_J, end.contact, 0)


#: how far above a raised state [h1] a kept state at its dp may lie to be raised from (`SuctionStates._raised`):
#: two rows of the default grid; farther, a sealed state in its own row at a dp at most RAMP_REACH_E
#: (of the modulus E; 2 kPa, two columns of the default grid, at E = 4 MPa) smaller is ramped instead
RAISE_REACH_H1 = 0.011
RAMP_REACH_E = 5e-4


def plate_floor_of(mesh: Mesh, wetting_m: float = 0.0) -> float:
    """The plate's floor u_floor = h1 - 2 L [m] of the cup of `mesh` (`fem.branch_end.plate_floor_m`),
    the lowest u of a raised row."""
    return plate_floor_m(_MeshCavity(mesh, CavitySurface.of(mesh, wetting_m)))


@dataclass(frozen=True)
class _MeshCavity:
    """A mesh and its cavity surface (what `fem.branch_end.plate_floor_m` reads of a cup)."""

    mesh: Mesh
    cavity: CavitySurface


#: the outputs of a raised state no raise reaches (`SuctionStates._raised`): no seal, no numbers
_UNREACHED = (*(np.nan,) * 7, None, False, (np.zeros(0), np.zeros(0)))


def _secant(u_far: np.ndarray, u_near: np.ndarray, base: float, step: float, reach: float, per_t: float
            ) -> Callable[[float, np.ndarray, float], np.ndarray] | None:
    """Newton's first iterate along a path of length `step` (`fem.solver.follow_path`'s
    predict(t0, u0, t1), its t a length per_t per unit: a raise's t is its length, a ramp's runs
    to 1): the start u_near moved on by the secant of it and
    u_far, the kept state `base` before it on the same line (a raise at fixed dp, a dp ramp in a
    row). None where base or step exceed `reach`: over longer distances the states are far from
    linear and the guess costs iterations (cup A, rows 0.12 h1 apart: 825 against 462). The
    prescribed dofs move exactly as prescribed, so the guess only saves iterations: a
    frictionless state does not depend on how it was reached."""
    if not (0 < base <= reach and 0 < step <= reach):
        return None
    slope = (u_near - u_far) * (per_t / base)
    return lambda t0, u0, t1: u0 + (t1 - t0) * slope


def _raising(cup: CupSetup, u_from: float) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
    """The plate raised from u_from: u_z = -(u_from - t) (`fem.solver.follow_path`'s dirichlet(t))."""
    dofs = np.concatenate([2 * cup.top, 2 * cup.top + 1])
    zeros = np.zeros(len(cup.top))
    return lambda t: (dofs, np.concatenate([zeros, np.full(len(cup.top), -(u_from - t))]))


def _outputs(state: StepResult, mech, cup: CupSetup, cavity: CavitySurface) -> tuple:
    """(F1, N, V, r_k, r_cut, r_c, W + dp V, profile) of a converged state. F1 = -F0, the plate's
    reaction, which with suction includes the roof's share dp pi r_0^2; N is the plane's
    reaction less the suction dp pi (r_cut^2 - r_k^2) that the load puts on the contact zones
    and pockets beyond the seal (`fem.cavity`), so F1 + N = dp pi r_k^2
    (`fem.cavity`). The profile is the plane's reaction per area (the gap at p_b)."""
    m = _measure(state, mech, cup.plane, cup.top, cup.path)
    x = mech.kin.node_coordinates() + np.stack([state.u[0::2], state.u[1::2]])
    dp = getattr(mech, "dp_Pa", 0.0)
    r_k = cavity.seal_radius(x)
    r_cut = float(x[0, cavity.nodes[cavity.cut_index(x)]])
    N = m.F0_contact_N - dp * np.pi * (r_cut**2 - r_k**2)
    return (-m.F0_N, N, cavity.volume(x), r_k, r_cut, m.r_c_m, state.energy_J, m.pressure)


def _measured(state: StepResult, mech, cup: CupSetup, cavity: CavitySurface) -> tuple:
    """`_outputs`, whether the state is sealed (module docstring: a node of the cavity chain on
    the plane) and the plane's reactions at its held nodes (`fem.contact.RigidPlane.held_reactions`)."""
    x = mech.kin.node_coordinates() + np.stack([state.u[0::2], state.u[1::2]])
    return (*_outputs(state, mech, cup, cavity), bool(np.any(cavity.on_plane(x))),
            cup.plane.held_reactions(state))


def _sealed(kept: tuple) -> bool:
    """Whether a kept (state, `_measured`) pair holds a seal."""
    return kept[1][8]


def _check_axes(u: np.ndarray, dp: np.ndarray, h1: float, floor: float, material: NeoHookean) -> None:
    if u.ndim != 1 or u.size == 0 or not np.all(np.isfinite(u)) or np.any(np.diff(u) <= 0) \
            or u[0] < floor * (1 + 1e-12) or u[-1] > h1:
        raise ValueError(f"u_m: plate displacements must increase within [h1 - 2 L, h1] = ["
                         f"{floor * 1e3:.4g}, {h1 * 1e3:.4g} mm], got {np.round(u * 1e3, 4).tolist()} mm")
    if dp.ndim != 1 or dp.size == 0 or not np.all(np.isfinite(dp)) or dp[0] != 0.0 \
            or np.any(np.diff(dp) <= 0) or dp[-1] > 10.0 * material.E_Pa:
        raise ValueError(f"dp_Pa: cavity pressures must start at 0 and increase, at most 10 E = "
                         f"{10 * material.E_Pa:.4g} Pa, got {dp.tolist()}")
