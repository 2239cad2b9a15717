"""The route "fem": the cup's whole life in the FEM, registered into `reduced.ROUTES`.

    from validation.bridge.fem_route import FemCup
    life = reduced.solve_lifetime(model, 10.0, route="fem", cup=FemCup("A", contact=ContactLaw("coulomb", 0.5)))

The cup (`FemCup`: design, wall, contact law, mesh level) is pressed with the gas escaping
(`fem.gas_path.CupWithGas.press_to`: to the model's r_start by default, or a plate displacement or
a pressing force, `Press`) and sealed there (N0 = p_a V / k_B T). Under the pull F1 the cup follows
its equilibrium branch (`fem.gas_branch.equilibrium_branch`: the plate raised at N0 until the pull
is F1, then the states holding F1 with N rising), which ends at the detachment: the fold (the
largest N held at F1: reason "fold") or the seal opening at the rim (reason "reached_r1"). A
branch that ends without a detachment is a failure (`FemRouteError`), never a lifetime.

At each branch state the leak Q [1/s] flows through that state's own contact traction at its
p_b, as the coupled route reads its table (`reduced.coupled`): the solid pressure is the FEM's
less the interface gas's rise over p_b across the zone [r_k, r_cut] (the model's `interface`),
averaged over the u_c table's patch length, a node touching alone entering by its reaction
(`validation.bridge.fem_leak`), its rings' gaps u_c(p / E) in series (`reduced.profile_leak`).
The lifetime is t = int_{N0}^{N_max} dN / Q by the trapezoid in N over the branch states: N rises
monotonically along the branch whereas u turns where the branch does (the walk switches to N as
its parameter there), and 1/Q is smooth in N except where the
seal's contact narrows to its last ring and Q falls several times within a plate step: there
states are added midway (`refine_branch`). The change when the plate step is halved measures the
quadrature and branch error (benchmarks/bench_fem_route.py, docs/lifetime.md).

The largest holdable force is the largest pull along the plate raised at fixed N0 from the sealed
state (`fem.gas_pull`: the branch at a larger F1 does not start, the cup lets go at once).

Water (model.fluid = "water"): the cavity is full of incompressible water (`fem.water_cavity`:
V_cav = V_w, the cavity pressure its multiplier, which may fall below zero: a metastable liquid,
no cavitation). Pressed, the cup expels water (V_w follows V); sealed, V_w0 = V; under F1 it follows
`fem.water_branch` (the same walk, V_w in place of N) to the fold (largest V_w held at F1) or the
seal opening. The inflow Q_w [m^3/s] is eq (24) ring by ring in series through each state's profile
(`reduced.profile_leak.profile_liquid_rate`, the model's liquid viscosity), the solid pressure as
for the gas; t = int dV_w / Q_w by the same trapezoid. The largest holdable force is the largest
pull along the plate raised at fixed V_w0 (`fem.water_branch.largest_pull`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from validation.bridge.fem_leak import state_leak_rate

if TYPE_CHECKING:
    from fem.gas_path import CupWithGas, GasState
    from fem.interface import ContactLaw
    from reduced.lifetime import LeakageModel, Lifetime, Run

__all__ = ["FemCup", "Press", "FemRoute", "FemRouteError", "state_leak_rate", "register"]

#: the default plate step along the branch [m] (`equilibrium_branch`'s du_m)
DEFAULT_DU_M = 0.25e-3


class FemRouteError(RuntimeError):
    """The FEM path ended without a detachment (the branch stopped or ran out of plate)."""


def _law() -> ContactLaw:
    from fem.interface import ContactLaw
    return ContactLaw()


@dataclass(frozen=True)
class FemCup:
    """The FEM cup of the route: the design (a `fem.geometry.CupGeometry` or a preset name), the
    wall's neo-Hookean material (E [Pa], nu), the contact law with the plane and the mesh level
    (default medium: the coarsest whose lifetimes are within 1 % of the next finer level's,
    benchmarks/fem_route_mesh_study.md)."""

    geometry: Any = "A"
    fidelity: str = "medium"
    E_Pa: float = 4e6
    nu: float = 0.49
    contact: Any = field(default_factory=_law)

    def describe(self) -> dict[str, Any]:
        geometry = self.geometry if isinstance(self.geometry, str) else self.geometry.describe()
        return {"geometry": geometry, "fidelity": self.fidelity, "E_Pa": self.E_Pa, "nu": self.nu,
                **self.contact.describe()}

    def build(self, T_K: float, p_a_Pa: float, fluid: str = "air") -> CupWithGas:
        """The FEM cup with gas (fluid "air") or water ("water") in its cavity."""
        from fem.gas_path import CupWithGas
        from fem.water_cavity import CupWithWater
        from fem.geometry import cup_geometry
        from fem.mesh import cup_mesh
        from validation.bridge.pipeline import neo_hookean

        geometry = cup_geometry(self.geometry) if isinstance(self.geometry, str) else self.geometry
        mesh = cup_mesh(geometry, self.fidelity)
        if fluid == "water":
            return CupWithWater.of(mesh, neo_hookean(self.E_Pa, self.nu), self.contact.law,
                                   self.contact.friction, p_a_Pa=p_a_Pa)
        return CupWithGas.of(mesh, neo_hookean(self.E_Pa, self.nu), self.contact.law,
                             self.contact.friction, T_K=T_K, p_a_Pa=p_a_Pa)


@dataclass(frozen=True)
class Press:
    """How the cup is pressed before it is sealed: to an inner contact radius ("r_start_m"), a
    plate displacement ("u_m") or a pressing force ("force_N"), `fem.gas_path.CupWithGas.press_to`."""

    kind: str
    value: float

    def __post_init__(self) -> None:
        if self.kind not in ("r_start_m", "u_m", "force_N"):
            raise ValueError(f"press: expected 'r_start_m', 'u_m' or 'force_N', got {self.kind!r}")
        if not (isinstance(self.value, (int, float)) and math.isfinite(self.value) and self.value > 0):
            raise ValueError(f"press: {self.kind} must be a number > 0, got {self.value!r}")


@dataclass(frozen=True, eq=False)
class Sealed:
    """The pressed and sealed cup: the FEM cup with its gas and the sealed state."""

    cup: CupWithGas
    state: GasState
    E_Pa: float


class FemRoute:
    """The route "fem" (module docstring). Options: cup (a `FemCup`, required), press (a `Press`;
    None: the model's r_start), du_m (the plate step along the branch [m]), radial (the rings'
    geometry, `reduced.profile_leak`), largest (whether the lifetime also reports the largest
    pull the sealed cup holds, `fem.gas_pull`: often the larger part of the cost; False leaves
    largest_force_N NaN and says so in the details)."""

    name = "fem"
    options = {"cup": None, "press": None, "du_m": DEFAULT_DU_M, "radial": "annulus", "largest": True}

    def __init__(self) -> None:
        self._sealed: dict[tuple, Sealed] = {}
        # id(Sealed) -> it, its largest pull [N], the solver's message if that is a lower bound
        self._largest: dict[int, tuple[Sealed, float, str | None]] = {}

    def check(self, model: LeakageModel, options: Mapping[str, Any]) -> None:
        from fem.interface import ContactLaw

        if not isinstance(options["cup"], FemCup):
            raise ValueError("cup: the fem route needs the FEM cup, a "
                             "validation.bridge.fem_route.FemCup")
        if not isinstance(options["cup"].contact, ContactLaw):
            raise ValueError("cup: its contact must be a fem.interface.ContactLaw")
        if options["press"] is not None and not isinstance(options["press"], Press):
            raise ValueError(f"press: expected a Press or None, got {type(options['press']).__name__}")
        du = options["du_m"]
        if not (isinstance(du, (int, float)) and math.isfinite(du) and du > 0):
            raise ValueError(f"du_m: the plate step must be a number > 0 m, got {du!r}")
        if not isinstance(options["largest"], bool):
            raise ValueError(f"largest: expected True or False, got {options['largest']!r}")
        if options["radial"] not in ("annulus", "strip"):
            raise ValueError(f"radial: expected 'annulus' or 'strip', got {options['radial']!r}")
        if model.u_c is None:
            raise ValueError("u_c: the fem route needs a critical gap u_c(p/E) (e.g. a UcTable)")
        if model.fluid == "water" and model.cavitation_pressure_Pa is not None:
            raise ValueError("cavitation_pressure_Pa: the fem route's water is a metastable liquid (no "
                             "cavitation); drop it")
        if model.relaxation is not None or model.kappa != 1.0:
            raise ValueError("relaxation, kappa: the fem route's wall is the FEM's elastic one; "
                             "drop relaxation and kappa")

    def seal(self, model: LeakageModel, options: Mapping[str, Any],
             progress: Callable[[float, str], None] | None = None) -> Sealed:
        """The cup pressed with the gas escaping and sealed, once per (cup, press, gas)."""
        press = options["press"] or Press("r_start_m", model.cup.r_start_m)
        key = (options["cup"], press, model.gas.T_K, model.p_a_Pa, model.fluid)
        if key not in self._sealed:
            if progress:
                progress(0.0, f"pressing the cup to {press.kind} = {press.value:g}")
            cup = options["cup"].build(model.gas.T_K, model.p_a_Pa, model.fluid)
            state = cup.press_to(**{press.kind: float(press.value)})[-1]
            self._sealed[key] = Sealed(cup, state, options["cup"].E_Pa)
        return self._sealed[key]

    def largest_force(self, model: LeakageModel, options: Mapping[str, Any]) -> float:
        """The largest pull the sealed cup holds (`fem.gas_pull`), once per sealed cup."""
        return self._largest_checked(model, options)[0]

    def _largest_checked(self, model: LeakageModel, options: Mapping[str, Any]) -> tuple[float, str | None]:
        sealed = self.seal(model, options)
        kept = self._largest.get(id(sealed))
        if kept is None or kept[0] is not sealed:
            from fem.gas_pull import largest_pull_checked
            from fem.water_branch import largest_pull as largest_pull_water

            largest = largest_pull_water if model.fluid == "water" else largest_pull_checked
            kept = self._largest[id(sealed)] = (sealed, *largest(sealed.cup, sealed.state))
        return kept[1], kept[2]

    def solve(self, model: LeakageModel, force_N: float, run: Run, options: Mapping[str, Any]) -> Lifetime:
        from fem.branch_end import up_to_most_gas
        from fem.gas_branch import equilibrium_branch, state_between
        from fem.water_branch import water_branch, water_state_between
        from reduced.lifetime import Lifetime
        from reduced.lifetime.paper import check_run

        check_run(force_N, run.t_max_s, run.rtol, run.refine)
        if run.refine != 1:
            raise ValueError(f"refine: the fem route has no dense output, got {run.refine}")
        sealed = self.seal(model, options, run.progress)
        water = model.fluid == "water"
        branch = (water_branch if water else equilibrium_branch)(
            sealed.cup, sealed.state, float(force_N), du_m=float(options["du_m"]),
            progress=_branch_progress(run.progress, force_N, sealed, "V_w" if water else "N"))
        largest, partial = self._largest_checked(model, options) if options["largest"] else (math.nan, None)
        s0 = sealed.state
        provenance = {"route": self.name, "options": {**options, "cup": options["cup"].describe(),
                                                       "press": options["press"] and vars(options["press"])},
                      "model": model.label, "t_max_s": run.t_max_s}
        common = dict(route=self.name, force_N=float(force_N), largest_force_N=largest,
                      provenance=provenance)
        content = {"V_w0_mm3": 1e9 * s0.N} if water else {"N0": s0.N}
        base = {**content, "u_sealed_mm": 1e3 * s0.u_m, "r_start_mm": 1e3 * s0.r_c_m,
                "seal_r_sealed_mm": 1e3 * s0.seal_r_m, "branch_reason": branch.reason}
        if partial is not None:       # the pull was still rising where the solver stopped
            base["largest_force_lower_bound"] = partial
        if not options["largest"]:
            base["largest_force"] = "not computed (largest=False)"
        if branch.reason == "not held":
            return Lifetime(reason="over_force", lifetime_s=0.0, message=f"F1 = {force_N:g} N exceeds "
                            f"what the sealed cup holds: it detaches at once", trajectory={},
                            details=base, **common)
        if branch.detachment is None:
            raise FemRouteError(f"F1 = {force_N:g} N: the branch ended without a detachment "
                                f"({branch.reason}) after {len(branch.states)} states")
        leak = lambda s: state_leak_rate(s, model, sealed.E_Pa, options["radial"],  # noqa: E731
                                         plane=sealed.cup.cup.plane)
        # a fold lets go with the most gas held (`fem.branch_end.up_to_most_gas`)
        kept = up_to_most_gas(branch.states) if branch.reason == "fold" else list(branch.states)
        states, q, added = refine_branch(sealed.cup, kept, [leak(s) for s in kept],
                                         float(force_N), leak, water_state_between if water else state_between)
        N = np.array([s.N for s in states])
        columns = _columns(states, q, water)
        stats = branch.stats
        most = {"V_w_max_mm3": 1e9 * states[-1].N} if water else {"N_max": states[-1].N}
        details = {**base, **most, "states": len(states), "refined": added, "snaps": branch.snaps,
                   "newton_iterations": stats.newton_iterations, "wall_time_s": stats.wall_time_s,
                   "seal_r_final_mm": 1e3 * states[-1].seal_r_m, "p_b_final_Pa": states[-1].p_b_Pa,
                   "u_final_mm": 1e3 * states[-1].u_m}
        if np.any(q <= 0):
            k = int(np.argmax(q <= 0))
            cut = {k2: v[:k + 1] for k2, v in columns.items()}
            cut["t_s"] = np.concatenate([lifetime_integral(N[:k + 1], q[:k + 1])[:-1], [math.inf]]) \
                if k else np.array([math.inf])
            return Lifetime(reason="sealed", lifetime_s=math.inf, message=f"the interface seals at "
                            f"u = {1e3 * states[k].u_m:.4g} mm, p_b = {states[k].p_b_Pa / 1e3:.4g} kPa",
                            trajectory=cut, details=details, **common)
        t = lifetime_integral(N, q)
        if t[-1] > run.t_max_s:
            end = int(np.searchsorted(t, run.t_max_s, side="right"))
            cut = {k2: v[:end] for k2, v in columns.items()}
            cut["t_s"] = t[:end]
            return Lifetime(reason="horizon", lifetime_s=math.inf, message=f"still holding at "
                            f"t_max = {run.t_max_s:g} s", trajectory=cut, details=details, **common)
        columns["t_s"] = t
        reason = "fold" if branch.reason == "fold" else "reached_r1"
        where = ("the branch folds: no state holds more gas" if reason == "fold" else
                 f"the seal opened at the rim (r_k = {1e3 * states[-1].seal_r_m:.4g} mm)")
        if run.progress:
            run.progress(1.0, f"F1 = {force_N:g} N: {reason}")
        return Lifetime(reason=reason, lifetime_s=float(t[-1]), trajectory=columns, details=details,
                        message=f"detached at t = {t[-1]:.4g} s: {where}", **common)


#: the leak may change by at most this factor between neighbouring states where their interval
#: carries more than REFINE_SHARE of the lifetime (`refine_branch`)
REFINE_RATIO, REFINE_SHARE, REFINE_DEPTH = 2.0, 0.01, 3


def refine_branch(cup: CupWithGas, states: list, q: list, force_N: float,
                  leak: Callable[[Any], float], between: Callable | None = None) -> tuple[list, np.ndarray, int]:
    """The branch's states with states added where the trapezoid of 1/Q in N is not resolved:
    between neighbours whose leak differs by more than REFINE_RATIO and whose interval carries
    more than REFINE_SHARE of the lifetime (where the seal's last contact ring narrows, Q falls
    several times within one plate step), a state midway (`fem.gas_branch.state_between`, from
    the earlier state; `between`: its water counterpart), up to REFINE_DEPTH halvings. (states,
    Q [1/s], states added)."""
    from fem.gas_branch import state_between

    between = between or state_between

    states, q = list(states), list(q)
    added = 0
    for _ in range(REFINE_DEPTH):
        N, Q = np.array([s.N for s in states]), np.array(q)
        inv = np.where(np.isinf(Q), 0.0, 1.0 / np.where(Q > 0, Q, np.inf))
        if np.any(Q <= 0) or len(states) < 2:
            break
        share = np.maximum(inv[1:], inv[:-1]) * np.diff(N)
        total = float(lifetime_integral(N, Q)[-1])
        finite = np.isfinite(Q[1:]) & np.isfinite(Q[:-1])
        ratio = np.zeros(len(Q) - 1)
        ratio[finite] = np.abs(np.log(Q[1:][finite] / Q[:-1][finite]))
        todo = np.flatnonzero((ratio > math.log(REFINE_RATIO)) & (share > REFINE_SHARE * total))
        if len(todo) == 0:
            break
        for k in todo[::-1]:                      # from the end: the indices before stay valid
            mid = between(cup, states[k], states[k + 1], force_N)
            if mid is not None:
                states.insert(k + 1, mid)
                q.insert(k + 1, leak(mid))
                added += 1
    return states, np.array(q), added


def _branch_progress(report: Callable[[float, str], None] | None, force_N: float, sealed: Sealed,
                     content: str = "N"):
    """One progress line per branch state: the fraction is the plate's travel from the sealed
    position towards -h1 (the branch's end is not known before it is reached)."""
    if report is None:
        return None
    u0, N0, h1 = sealed.state.u_m, sealed.state.N, sealed.cup.h1_m
    report(0.1, f"F1 = {force_N:g} N: following the branch")

    def on_state(k: int, u_m: float, N: float) -> None:
        report(0.1 + 0.85 * min(max((u0 - u_m) / (u0 + h1), 0.0), 1.0),
               f"F1 = {force_N:g} N: branch state {k}, u = {1e3 * u_m:.3f} mm, {content} = {N / N0:.4g} {content}0")
    return on_state


def lifetime_integral(N: np.ndarray, q: np.ndarray) -> np.ndarray:
    """t(N) = int_{N_0}^{N} dN' / Q(N') [s] at every sample, by the trapezoid (1/Q = 0 where the
    seal is held open, Q = inf)."""
    inv = np.where(np.isinf(q), 0.0, 1.0 / q)
    return np.concatenate([[0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * np.diff(N))])


def _columns(states: list, q: np.ndarray, water: bool = False) -> dict[str, np.ndarray]:
    def col(name: str, scale: float = 1.0) -> np.ndarray:
        return scale * np.array([getattr(s, name) for s in states])
    if water:
        return {"V_w_mm3": col("N", 1e9), "p_b_Pa": col("p_b_Pa"), "u_mm": col("u_m", 1e3),
                "F_plate_N": col("F1_N"), "V_mm3": col("V_m3", 1e9), "r_c_mm": col("r_c_m", 1e3),
                "seal_r_mm": col("seal_r_m", 1e3), "r_out_mm": col("cut_r_m", 1e3), "Q_w_mm3_per_s": 1e9 * q}
    return {"N": col("N"), "p_b_Pa": col("p_b_Pa"), "u_mm": col("u_m", 1e3), "F_plate_N": col("F1_N"),
            "V_mm3": col("V_m3", 1e9), "r_c_mm": col("r_c_m", 1e3), "seal_r_mm": col("seal_r_m", 1e3),
            "r_out_mm": col("cut_r_m", 1e3), "N_dot_per_s": q}


def register() -> FemRoute:
    """Register the route "fem" into `reduced.ROUTES` (once; the registered route afterwards)."""
    from reduced.lifetime import ROUTES, register_route

    route = ROUTES.get("fem")
    return route if isinstance(route, FemRoute) else register_route(FemRoute())


register()
