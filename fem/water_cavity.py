"""Water in the cavity as part of the FEM state: an incompressible volume V_w (eq 24's liquid).

    cup = CupWithWater.of(mesh, NeoHookean())
    pressed = cup.press(3e-3)                      # plate down 3 mm, p_b = p_a (the water is expelled)
    pulled = cup.move_plate(pressed[-1], 2e-3)     # plate back up to u = 2 mm, V_w fixed at the seal
    leaked = cup.let_in(pulled[-1], 1.01 * pulled[-1].V_w_m3)   # plate held, water flows in
    [(s.u_m, s.V_w_m3, s.p_b_Pa, s.F1_N, s.V_m3, s.seal_r_m) for s in pressed + pulled + leaked]

Sealed, the cavity holds the water volume V_w: the state is the minimum of the body's energy W(u)
under the constraint V_cav(u) = V_w, and the cavity pressure is its Lagrange multiplier,
dp = p_a - p_b (the ambient pushes on the outside, the water on the inside; p_b may fall below
zero, the liquid under tension: no cavitation is modelled). It is solved by the augmented
Lagrangian: at a multiplier estimate dp_lam the potential

    Pi_w(V) = dp_lam (V - V_w) + (c / 2) (V - V_w)^2,      dPi_w/dV = dp_lam + c (V - V_w) = dp,

is added to W (`WaterMechanics`), with its exact tangent K + dp Hess(V) + c grad V grad V^T (the
trapped gas's rank-one form, `fem.trapped_gas.GasTangent`, solved by Sherman-Morrison on the
body's factor), so the solver stays an energy minimization with its line search and contact
problem; then dp_lam <- dp (Uzawa) until c |V - V_w| is below UZAWA_TOL rtol max(p_a, |dp|), or
stalls below STALL times that (the solver's own resolution). Each update leaves 1 / (1 + c s) of
the last constraint error (s = dV/d(dp), the cup's compliance), so from the second update on
the multiplier goes to the limit of their geometric series (Aitken): two or three per state. The
penalty c = AL_FACTOR p_a / V_w is the stiffness of a gas at AL_FACTOR times the ambient pressure:
it holds the wall where at fixed dp it would snap, as the gas does, while a much stiffer one slows
the Newton iteration's line search. A bordered Newton (dp an unknown beside u) would give the same
states, but the solver's line search needs an energy, which the saddle point has not. A converged
state is the constrained one: r + dp dV/du = 0 on the free dofs and V = V_w to that tolerance.

The stages are those of `fem.gas_path.CupWithGas` (whose pressing, measuring and cost keeping
this cup inherits): pressed with the cavity open (the water expelled, V_w = V, p_b = p_a), the
plate moved at fixed V_w (`move_plate`), V_w changed at a held plate (`let_in`, the inflow whose
rate this module does not know). The branch at a held pull is `fem.water_branch`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from skfem import Mesh

from .cavity import CavitySurface, PressurizedMechanics
from .contact import PressureProfile
from .cup import CupSetup, _joined
from .forms import Mechanics
from .condensation import make_solver
from .gas_path import CupWithGas
from .integrity import check_state
from .material import NeoHookean
from .solver import SolverOptions, SolverStats, StepResult, follow_path
from .suction import _outputs
from .trapped_gas import GasTangent, RankOneSolver, _sparse_part

__all__ = ["WaterMechanics", "WaterState", "CupWithWater", "AL_FACTOR", "UZAWA_TOL"]

#: the augmented Lagrangian's penalty c = AL_FACTOR p_a / V_w [Pa/m^3] (module docstring)
AL_FACTOR = 100.0
#: the multiplier update c |V - V_w| below which the constraint is met, as a share of the
#: solver's rtol times max(p_a, |dp|) (0.01 Pa at rtol 1e-6 and dp <= p_a: the solver resolves dp
#: to ~1e-3 Pa there)
UZAWA_TOL = 0.1
UZAWA_MAX = 12
#: ... or below STALL times that where an update no longer halves it (the solver's resolution:
#: the Newton iteration accepts a state whose residual the update leaves below rtol)
STALL = 100.0


@dataclass
class WaterMechanics:
    """`fem.forms.Mechanics` of the cup with the water volume V_w_m3 in its cavity at the
    multiplier estimate dp_lam_Pa and penalty c_Pa_per_m3 (module docstring): energy W + Pi_w(V),
    force r + dp dV/du, tangent K + dp d2V/du2 + c dV dV^T with dp = dp_lam + c (V - V_w).

    schedule: V_w as a function of the path parameter t (water let in along the path)."""

    body: Mechanics
    cavity: CavitySurface
    V_w_m3: float
    dp_lam_Pa: float
    c_Pa_per_m3: float
    schedule: Callable[[float], float] | None = None
    _load: PressurizedMechanics | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if self.cavity.wetting_m != 0.0:
            raise ValueError(f"wetting_m: the water volume is the geometric cavity volume "
                             f"(wetting_m = 0), got {self.cavity.wetting_m}")
        if not (math.isfinite(self.V_w_m3) and self.V_w_m3 > 0.0):
            raise ValueError(f"V_w_m3: must be a volume > 0, got {self.V_w_m3!r}")
        if not (math.isfinite(self.c_Pa_per_m3) and self.c_Pa_per_m3 > 0.0):
            raise ValueError(f"c_Pa_per_m3: must be > 0, got {self.c_Pa_per_m3!r}")
        if self._load is None:
            self._load = PressurizedMechanics(self.body, self.cavity, 0.0)

    def make_solver(self, pattern, coordinates: np.ndarray, mesh=None) -> RankOneSolver:
        """The body's sparse factor with the penalty's rank-one term (`fem.trapped_gas`)."""
        return RankOneSolver(make_solver(_sparse_part(pattern), coordinates, mesh))

    def at(self, t: float) -> "WaterMechanics":
        if self.schedule is None:
            return self
        return replace(self, V_w_m3=float(self.schedule(t)), schedule=None)

    @property
    def kin(self):
        return self.body.kin

    @property
    def material(self):
        return self.body.material

    def coordinates(self, u: np.ndarray) -> np.ndarray:
        return self._load.coordinates(u)

    def volume_m3(self, u: np.ndarray) -> float:
        """V_cav(u) [m^3]."""
        return self.cavity.volume(self.coordinates(u))

    def dp_Pa(self, u: np.ndarray) -> float:
        """dp = dp_lam + c (V_cav(u) - V_w) [Pa]: the cavity pressure difference at the state u."""
        return self.dp_lam_Pa + self.c_Pa_per_m3 * (self.volume_m3(u) - self.V_w_m3)

    def pressurized(self, u: np.ndarray) -> PressurizedMechanics:
        """The dp-loaded mechanics at the state's dp (same force at u), as `fem.suction` measures."""
        return replace(self._load, dp_Pa=self.dp_Pa(u), schedule=None)

    def energy(self, u: np.ndarray) -> float:
        dV = self.volume_m3(u) - self.V_w_m3
        return self.body.energy(u) + self.dp_lam_Pa * dV + 0.5 * self.c_Pa_per_m3 * dV * dV

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return self.evaluate(u)[1]

    def linearize(self, u: np.ndarray):
        return self.evaluate(u)[1:]

    def evaluate(self, u: np.ndarray) -> tuple[float, np.ndarray, GasTangent]:
        V, (dofs, grad), hess, pairs = self.cavity.derivatives(self.coordinates(u))
        dV = V - self.V_w_m3
        dp = self.dp_lam_Pa + self.c_Pa_per_m3 * dV
        W, r, K = self.body.evaluate(u)
        g = np.bincount(dofs, grad, minlength=r.size)
        data = K.data + dp * np.bincount(self._load._positions(K, pairs), hess, minlength=K.nnz)
        energy = W + self.dp_lam_Pa * dV + 0.5 * self.c_Pa_per_m3 * dV * dV
        return energy, r + dp * g, GasTangent.of(K, data, self.c_Pa_per_m3, g)


@dataclass(frozen=True, eq=False)
class WaterState:
    """One converged state of the cup with water in its cavity; SI units (as `fem.gas_path.GasState`,
    with the water volume in place of the molecules)."""

    stage: str                  # "pressed" (open cavity), "pulled" (fixed V_w), "leaked" (V_w moved),
    #                             "held" (`fem.water_branch`: at a given pull)
    u_m: float                  # plate displacement down from touching (h = h1 - u)
    V_w_m3: float               # water in the cavity
    p_b_Pa: float               # water pressure (< 0: under tension)
    dp_Pa: float                # p_a - p_b, the constraint's multiplier
    F1_N: float                 # pull on the handle (> 0 pulls the cup off the plane)
    contact_force_N: float      # N_c: the plane's reaction less dp on the zone beyond the seal
    V_m3: float                 # cavity volume (geometric; = V_w once sealed)
    seal_r_m: float             # r_k: radius of the seal node
    cut_r_m: float              # outer end of the outermost contact zone
    r_c_m: float                # inner contact radius of the pressure profile
    profile: PressureProfile = field(repr=False)
    state: StepResult = field(repr=False)

    @property
    def N(self) -> float:
        """The cavity's content in the branch walk's coordinate (`fem.gas_branch`): V_w [m^3]."""
        return self.V_w_m3


@dataclass(frozen=True, eq=False)
class CupWithWater(CupWithGas):
    """The cup with water in its cavity (module docstring): `press` and `press_to` as the gas
    cup's, with the water expelled; `move_plate` and `let_in` at the constraint V_cav = V_w."""

    @classmethod
    def of(cls, mesh: Mesh, material: NeoHookean,
           contact: Literal["frictionless", "sticking", "coulomb"] = "frictionless",
           friction: float = 0.0, p_a_Pa: float = 1e5, **solver_opts: Any) -> "CupWithWater":
        """Check the law, mu, material (`fem.cup.CupSetup.of`) and p_a (ValueError); build the cup."""
        if not (isinstance(p_a_Pa, (int, float)) and math.isfinite(p_a_Pa) and p_a_Pa > 0):
            raise ValueError(f"p_a_Pa: must be a number > 0, got {p_a_Pa!r}")
        return cls(mesh, CupSetup.of(mesh, material, contact, friction), CavitySurface.of(mesh),
                   p_a_Pa=float(p_a_Pa), options=SolverOptions(**solver_opts))

    def penalty(self, V_w_m3: float) -> float:
        """c = AL_FACTOR p_a / V_w [Pa/m^3]."""
        return AL_FACTOR * self.p_a_Pa / V_w_m3

    def move_plate(self, start: WaterState, u_m: float, steps: int = 1) -> list[WaterState]:
        """Move the plate from start's position to u_m at start's V_w (a "pressed" start is sealed
        there, at p_a), in `steps` equal moves, each ending on the constraint."""
        if u_m == start.u_m or not (0.0 < u_m <= self.h1_m):
            raise ValueError(f"u_m: the plate must move, within (0, {self.h1_m * 1e3:.4g}] mm, "
                             f"from {start.u_m * 1e3:.4g} mm, got {u_m * 1e3:.4g} mm")
        return self._moves(start, np.linspace(start.u_m, u_m, steps + 1)[1:],
                           np.full(steps, start.V_w_m3), "pulled")

    def let_in(self, start: WaterState, V_end_m3: float, steps: int = 1) -> list[WaterState]:
        """Change V_w linearly from start's to V_end_m3 at the held plate (the inflow)."""
        if not (np.isfinite(V_end_m3) and V_end_m3 > 0.0 and V_end_m3 != start.V_w_m3):
            raise ValueError(f"V_end_m3: must be > 0 and differ from the start's V_w = "
                             f"{start.V_w_m3:.6g} m^3, got {V_end_m3!r}")
        return self._moves(start, np.full(steps, start.u_m),
                           np.linspace(start.V_w_m3, V_end_m3, steps + 1)[1:], "leaked")

    def _moves(self, start: WaterState, u: np.ndarray, V: np.ndarray, stage: str) -> list[WaterState]:
        states = [start]
        for u_k, V_k in zip(u, V):
            s = states[-1]
            step, dp, stats = self.solve_water(s.state, s.dp_Pa, s.u_m, float(u_k), s.V_w_m3, float(V_k))
            self.costs.append(stats)
            states.append(self.measure_water(step, float(V_k), dp, float(u_k), stage))
        return states

    def solve_water(self, start: StepResult, dp_start_Pa: float, u0_m: float, u1_m: float,
                    V0_m3: float, V1_m3: float, options: SolverOptions | None = None
                    ) -> tuple[StepResult, float, SolverStats]:
        """The state with the plate at u1_m and the water volume V1_m3, reached from `start` (at
        u0_m, V0_m3, dp_start_Pa) with the plate and V_w on a line at the multiplier dp_start,
        then the Uzawa updates at the held plate (module docstring). (state, dp [Pa], cost).
        Raises what `fem.solver.follow_path` raises, RuntimeError if the updates do not meet
        the constraint."""
        options = options or self.options
        c = self.penalty(V1_m3)
        body, plane = self.cup.mech, self.cup.plane
        mech = WaterMechanics(body, self.cavity, V0_m3, float(dp_start_Pa), c,
                              schedule=lambda t: V0_m3 + t * (V1_m3 - V0_m3))
        last: list[StepResult] = []
        stats = follow_path(mech, self._line(u0_m, u1_m), 1.0, plane=plane, start=start,
                            options=options, on_step=last.append)
        end, fixed = mech.at(1.0), replace(options, initial_step=1.0, max_step=1.0)
        before = math.inf
        for _ in range(UZAWA_MAX):
            dp = end.dp_Pa(last[-1].u)
            delta = dp - end.dp_lam_Pa
            update = abs(delta)
            tol = UZAWA_TOL * options.rtol * max(self.p_a_Pa, abs(dp))
            if update <= tol or (update <= STALL * tol and update > 0.5 * before):
                return last[-1], dp, stats
            rho = delta / before_signed if math.isfinite(before) else 0.0
            before, before_signed = update, delta
            # the updates shrink geometrically (ratio rho): go to their limit (Aitken)
            end = replace(end, dp_lam_Pa=dp + (delta * rho / (1.0 - rho) if 0.0 < rho < 0.5 else 0.0))
            more = follow_path(end, self._line(u1_m, u1_m), 1.0, plane=plane, start=last[-1],
                               options=fixed, on_step=last.append)
            stats = _joined(stats, more)
        raise RuntimeError(f"water: V_cav = V_w not met in {UZAWA_MAX} multiplier updates at "
                           f"u = {u1_m * 1e3:.6g} mm (c |V - V_w| = {update:.3g} Pa)")

    def measure_water(self, step: StepResult, V_w_m3: float, dp_Pa: float, u_m: float,
                      stage: str) -> WaterState:
        """The `WaterState` of a converged constrained state (V_cav = V_w_m3 at the multiplier dp_Pa)."""
        check_state(self.mesh, step.u, u_m, 0, u_m)
        loaded = PressurizedMechanics(self.cup.mech, self.cavity, float(dp_Pa))
        F1, Nc, V, r_k, r_cut, r_c, _, profile = _outputs(step, loaded, self.cup, self.cavity)
        return WaterState(stage, float(u_m), float(V_w_m3), self.p_a_Pa - dp_Pa, float(dp_Pa), F1, Nc,
                          V, r_k, r_cut, r_c, profile, step)

    def measure(self, step: StepResult, mech, u_m: float, stage: str) -> WaterState:
        """The `WaterState` of an open-cavity state (pressing: V_w = V, p_b = p_a)."""
        if isinstance(mech, WaterMechanics):
            return self.measure_water(step, mech.V_w_m3, mech.dp_Pa(step.u), u_m, stage)
        check_state(self.mesh, step.u, u_m, 0, u_m)
        F1, Nc, V, r_k, r_cut, r_c, _, profile = _outputs(step, mech, self.cup, self.cavity)
        return WaterState(stage, float(u_m), V, self.p_a_Pa, 0.0, F1, Nc, V, r_k, r_cut, r_c, profile, step)

    def _line(self, u0_m: float, u1_m: float):
        """The plate from u0 to u1 as t goes from 0 to 1 (u_r = 0, u_z = -u)."""
        top = self.cup.top
        dofs, zeros = np.concatenate([2 * top, 2 * top + 1]), np.zeros(len(top))
        return lambda t: (dofs, np.concatenate([zeros, np.full(len(top), -(u0_m + t * (u1_m - u0_m)))]))
