"""The sealed cup's path in the FEM: pressed with the gas escaping, sealed, pulled, leaked into.

    cup = CupWithGas.of(mesh, NeoHookean(), contact="sticking")
    pressed = cup.press(3e-3)                      # plate down 3 mm, p_b = p_a (the gas escapes)
    pulled = cup.move_plate(pressed[-1], 2e-3)     # plate back up to u = 2 mm, N fixed at the seal
    leaked = cup.let_in(pulled[-1], 1.2 * pulled[-1].N)   # plate held, N grows
    [(s.u_m, s.N, s.p_b_Pa, s.F1_N, s.V_m3, s.seal_r_m, s.r_c_m) for s in pressed + pulled + leaked]

Each stage is one `fem.solver` path that starts from the last converged state of the one before,
so the contact state (the sticking anchors, Coulomb's slips) is carried along: with friction the
states depend on this history, frictionless they do not (the tests compare them with the
dp-driven states of `fem.suction`). While pressed the cavity is open (p_b = p_a, no load from the
gas; N is the content at ambient pressure, p_a V / k_B T); from the seal on the gas is part of the
state (`fem.trapped_gas`): the plate may move at fixed N, or N change at a held plate (the leak,
whose rate this module does not know). `cup_path` strings the four stages together.

Every state is measured as `fem.suction` measures its grid: the pull on the handle F1 = -F0 (the
plate's reaction, with the roof's share of the suction), the contact force N_c less the suction on
the flat zone beyond the seal, so that F1 + N_c = dp pi r_k^2, the geometric cavity volume, the
seal radius r_k, the inner contact radius and the contact-pressure profile (the gap at p_b).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from skfem import Mesh

from .cavity import CavitySurface
from .contact import PressureProfile
from .interface import ContactLaw
from .cup import CupSetup, _joined, cup_height
from .integrity import check_state
from .material import NeoHookean
from .solver import SolverOptions, SolverStats, StepResult, follow_path
from .suction import _outputs
from .trapped_gas import K_B, GasMechanics, TrappedGas, follow_gas_path

__all__ = ["GasState", "CupWithGas", "CupPath", "cup_path"]


@dataclass(frozen=True, eq=False)
class GasState:
    """One converged state of the cup with its gas (module docstring); SI units."""

    stage: str                  # "pressed" (open cavity), "pulled" (fixed N), "leaked" (N moved),
    #                             "sealed", "held" (`fem.gas_branch`: at a given pull)
    u_m: float                  # plate displacement down from touching (h = h1 - u)
    N: float                    # molecules in the cavity
    p_b_Pa: float               # gas pressure, N k_B T / V
    dp_Pa: float                # p_a - p_b
    F1_N: float                 # pull on the handle (> 0 pulls the cup off the plane)
    contact_force_N: float      # N_c: the plane's reaction less dp on the zone beyond the seal
    V_m3: float                 # cavity volume (geometric)
    seal_r_m: float             # r_k: radius of the seal node
    cut_r_m: float              # outer end of the outermost contact zone (the suction's extent)
    r_c_m: float                # inner contact radius of the pressure profile
    profile: PressureProfile = field(repr=False)
    state: StepResult = field(repr=False)     # the solver's state, to continue the path from


@dataclass(frozen=True, eq=False)
class CupWithGas:
    """The cup, its cavity and the gas's temperature and ambient pressure; the path's stages
    (module docstring). Each stage returns its converged states, the start state first."""

    mesh: Mesh
    cup: CupSetup
    cavity: CavitySurface
    T_K: float = 293.15
    p_a_Pa: float = 1e5
    options: SolverOptions = SolverOptions()
    costs: list = field(default_factory=list, repr=False)     # SolverStats of every stage run

    @classmethod
    def of(cls, mesh: Mesh, material: NeoHookean,
           contact: Literal["frictionless", "sticking", "coulomb"] = "frictionless",
           friction: float = 0.0, T_K: float = 293.15, p_a_Pa: float = 1e5,
           **solver_opts: Any) -> "CupWithGas":
        """Check the law, mu, material (`fem.cup.CupSetup.of`) and the gas's T and p_a
        (ValueError) and build the cup."""
        TrappedGas(1.0, T_K, p_a_Pa)
        return cls(mesh, CupSetup.of(mesh, material, contact, friction), CavitySurface.of(mesh),
                   float(T_K), float(p_a_Pa), SolverOptions(**solver_opts))

    @property
    def h1_m(self) -> float:
        return cup_height(self.mesh)

    @property
    def stats(self) -> SolverStats | None:
        """The cost of every stage run so far, as one path."""
        total = None
        for s in self.costs:
            total = s if total is None else _joined(total, s)
        return total

    def press(self, u_m: float, start: GasState | None = None) -> list[GasState]:
        """Press the plate down to u_m with the cavity open (p_b = p_a), from the undeformed cup
        or from an open state `start`."""
        u0 = 0.0 if start is None else start.u_m
        if start is not None and start.stage != "pressed":
            raise ValueError(f"start: pressing needs an open cavity, got a {start.stage} state")
        if not (u0 < u_m <= self.h1_m):
            raise ValueError(f"u_m: the plate must move down, within ({u0 * 1e3:.4g}, "
                             f"{self.h1_m * 1e3:.4g}] mm, got {u_m * 1e3:.4g} mm")
        mech = self.cup.mech
        return self._run(lambda on_step: follow_path(
            mech, self._plate(u0, +1.0), u_m - u0, plane=self.cup.plane, options=self.options,
            on_step=on_step, start=None if start is None else start.state, name="u [m]"),
            lambda s: (mech, u0 + s.t, "pressed"), skip_first=start is not None)

    def press_to(self, *, u_m: float | None = None, force_N: float | None = None,
                 r_start_m: float | None = None, du_m: float = 0.25e-3,
                 u_tol_m: float = 1e-7) -> list[GasState]:
        """Press with the cavity open until one target is met: the plate displacement u_m, the
        pressing force F0 = -F1 = force_N, or the inner contact radius r_c = r_start_m (it falls
        as the cup is pressed). The plate moves in steps of du_m until the target is passed, then
        the crossing is bisected in u to u_tol_m, each trial continuing the path from the last
        state short of the target (so the contact history is the pressing path's). The last
        state is the one to seal (`move_plate`, `fem.gas_branch`: N0 = p_a V / k_B T); r_c is
        resolved to the mesh's node spacing, so r_start is met to that resolution."""
        given = {k: v for k, v in (("u_m", u_m), ("force_N", force_N), ("r_start_m", r_start_m))
                 if v is not None}
        if len(given) != 1:
            raise ValueError(f"press_to: give exactly one of u_m, force_N, r_start_m, got {sorted(given) or 'none'}")
        (name, target), = given.items()
        if not (isinstance(target, (int, float)) and np.isfinite(target) and target > 0.0):
            raise ValueError(f"{name}: must be a number > 0, got {target!r}")
        if name == "u_m":
            return self.press(float(target))
        if not (np.isfinite(du_m) and 0.0 < du_m <= 0.1 * self.h1_m):
            raise ValueError(f"du_m: must be in (0, {0.1 * self.h1_m * 1e3:.4g}] mm, got {du_m * 1e3:.4g} mm")

        def short(s: GasState) -> bool:                 # the target not yet reached
            return -s.F1_N < target if name == "force_N" else s.r_c_m > target
        stepper = replace(self, options=replace(self.options, initial_step=1.0, max_step=1.0),
                          costs=self.costs)        # one load step per call unless it must cut
        states = stepper.press(du_m)
        while short(states[-1]):
            if states[-1].u_m + du_m > self.h1_m:
                raise ValueError(f"{name}: {target:.6g} is not reached by pressing the plate to "
                                 f"h1 = {self.h1_m * 1e3:.4g} mm")
            states.append(stepper.press(states[-1].u_m + du_m, start=states[-1])[-1])
        over = states.pop()
        while over.u_m - states[-1].u_m > u_tol_m:
            mid = stepper.press(0.5 * (states[-1].u_m + over.u_m), start=states[-1])[-1]
            if short(mid):
                states.append(mid)
            else:
                over = mid
        return states + [over]

    def move_plate(self, start: GasState, u_m: float, N: float | None = None) -> list[GasState]:
        """Move the plate from start's position to u_m (up: u_m smaller) with N molecules sealed
        in (default: start's N; a "pressed" start is sealed there, at p_a)."""
        sign = 1.0 if u_m > start.u_m else -1.0
        if u_m == start.u_m or not (0.0 < u_m <= self.h1_m):
            raise ValueError(f"u_m: the plate must move, within (0, {self.h1_m * 1e3:.4g}] mm, "
                             f"from {start.u_m * 1e3:.4g} mm, got {u_m * 1e3:.4g} mm")
        mech = GasMechanics(self.cup.mech, self.cavity, self._gas(start.N if N is None else N))
        return self._gas_stage(mech, self._plate(start.u_m, sign), abs(u_m - start.u_m), start,
                               lambda t: start.u_m + sign * t, "pulled")

    def let_in(self, start: GasState, N_end: float) -> list[GasState]:
        """Change N linearly from start's N to N_end at the held plate (the leak)."""
        N0 = start.N
        if not (np.isfinite(N_end) and N_end > 0.0 and N_end != N0):
            raise ValueError(f"N_end: must be > 0 and differ from the start's N = {N0:.6g}, got {N_end!r}")
        mech = GasMechanics(self.cup.mech, self.cavity, self._gas(N0),
                            schedule=lambda t: N0 + t * (N_end - N0))
        return self._gas_stage(mech, self._plate(start.u_m, 0.0), 1.0, start,
                               lambda t: start.u_m, "leaked")

    def measure(self, step: StepResult, mech, u_m: float, stage: str) -> GasState:
        """The `GasState` of a converged solver state (module docstring); mech: the cup's body
        (open cavity) or its `GasMechanics`."""
        check_state(self.mesh, step.u, u_m, 0, u_m)     # contact kept between the nodes, no fold
        if isinstance(mech, GasMechanics):
            loaded, gas = mech.pressurized(step.u), mech.gas
        else:
            loaded, gas = mech, None
        F1, Nc, V, r_k, r_cut, r_c, _, profile = _outputs(step, loaded, self.cup, self.cavity)
        if gas is None:
            gas = self._gas(self.p_a_Pa * V / (K_B * self.T_K))
        p_b = gas.pressure_Pa(V)
        return GasState(stage, float(u_m), gas.N, p_b, self.p_a_Pa - p_b, F1, Nc, V, r_k, r_cut,
                        r_c, profile, step)

    def _gas(self, N: float) -> TrappedGas:
        return TrappedGas(float(N), self.T_K, self.p_a_Pa)

    def _plate(self, u0_m: float, sign: float) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
        """The plate u_r = 0, u_z = -(u0 + sign t): down (+1), up (-1) or held (0)."""
        top = self.cup.top
        dofs, zeros = np.concatenate([2 * top, 2 * top + 1]), np.zeros(len(top))
        return lambda t: (dofs, np.concatenate([zeros, np.full(len(top), -(u0_m + sign * t))]))

    def _gas_stage(self, mech: GasMechanics, plate, t_max: float, start: GasState,
                   u_at: Callable[[float], float], stage: str) -> list[GasState]:
        return self._run(lambda on_step: follow_gas_path(
            mech, plate, t_max, plane=self.cup.plane, start=start.state, options=self.options,
            on_step=on_step), lambda s: (mech.at(s.t), u_at(s.t), stage), skip_first=True,
            first=start)

    def _run(self, run, describe, skip_first: bool, first: GasState | None = None) -> list[GasState]:
        """Run a stage and measure its converged states; the start state is `first` (or the
        stage's own t = 0 state)."""
        steps: list[StepResult] = []
        self.costs.append(run(steps.append))
        states = [] if first is None else [first]
        for k, s in enumerate(steps):
            if k == 0 and skip_first:
                continue
            states.append(self.measure(s, *describe(s)))
        return states


@dataclass(frozen=True, eq=False)
class CupPath:
    """The states of `cup_path`, in order, the contact law and the cost of the whole path."""

    states: tuple[GasState, ...]
    stats: SolverStats
    contact: ContactLaw

    def column(self, name: str) -> np.ndarray:
        """One field of every state as an array, e.g. column("p_b_Pa")."""
        return np.array([getattr(s, name) for s in self.states])


def cup_path(mesh: Mesh, material: NeoHookean, u_press_m: float, u_pulled_m: float,
             N_end_ratio: float, contact: Literal["frictionless", "sticking", "coulomb"] = "frictionless",
             friction: float = 0.0, T_K: float = 293.15, p_a_Pa: float = 1e5,
             **solver_opts: Any) -> CupPath:
    """Pressed to u_press_m with the gas escaping, sealed there, the plate raised to u_pulled_m
    (< u_press_m) at fixed N, then N raised by N_end_ratio (> 1) at the held plate: the states
    along the whole path (module docstring)."""
    if not (0.0 < u_pulled_m < u_press_m):
        raise ValueError(f"u_pulled_m: must be in (0, u_press_m = {u_press_m * 1e3:.4g} mm), got "
                         f"{u_pulled_m * 1e3:.4g} mm")
    if not (np.isfinite(N_end_ratio) and N_end_ratio > 1.0):
        raise ValueError(f"N_end_ratio: the leak lets gas in, so it must be > 1, got {N_end_ratio!r}")
    cup = CupWithGas.of(mesh, material, contact, friction, T_K, p_a_Pa, **solver_opts)
    pressed = cup.press(u_press_m)
    pulled = cup.move_plate(pressed[-1], u_pulled_m)
    leaked = cup.let_in(pulled[-1], N_end_ratio * pulled[-1].N)
    return CupPath(tuple(pressed + pulled[1:] + leaked[1:]), cup.stats, cup.cup.plane.law.contact)
