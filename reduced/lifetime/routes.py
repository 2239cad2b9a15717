"""The lifetime's one entry point over a registry of routes, in the shape of scipy's solve_ivp.

A route turns a `LeakageModel` and a pull force into a `Lifetime`. Registered:

- "paper":   eqs (3)-(10) with eq 6's uniform strip (`reduced.lifetime.paper`); option cup_laws:
             'cone' (the rigid cone, eqs 3-5) or 'curve' (r, V, l from the stiffness curve).
- "profile": the same force balance on the curve's laws, the leak through the curve's contact-
             pressure profiles (`reduced.seal.ProfileSeal`); option exact (False: tabulated flows).
- "coupled": the cup's state from its FEM suction table (`reduced.coupled`); options samples,
             radial, along_u, u_start_m.

A new route is an object with `name`, `options` (name -> default), `check(model, options)`,
`solve(model, force_N, run, options)` and `largest_force(model, options)`, handed to
`register_route`; the entry point does not change.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from reduced.lifetime.result import Lifetime, _PaperRecord
from reduced.model import LeakageModel

# each route imports its machinery when it first runs: a paper-route lifetime loads no coupled
# cavity, a coupled one no force balance

__all__ = ["Route", "Run", "ROUTES", "register_route", "solve_lifetime", "largest_holdable_force"]

_COMMON = ("force_N", "lifetime_s", "reason", "sealed", "message")


@dataclass(frozen=True)
class Run:
    """The integration settings every route receives: horizon [s], relative tolerance, output
    points per step, and the progress callback (fraction, message)."""

    t_max_s: float = 1e12
    rtol: float = 1e-6
    refine: int = 1
    progress: Callable[[float, str], None] | None = None


class Route(Protocol):
    """What the entry point calls on a route (module docstring)."""

    name: str
    options: Mapping[str, Any]

    def check(self, model: LeakageModel, options: Mapping[str, Any]) -> None: ...

    def solve(self, model: LeakageModel, force_N: float, run: Run, options: Mapping[str, Any]) -> Lifetime: ...

    def largest_force(self, model: LeakageModel, options: Mapping[str, Any]) -> float: ...


def _details(summary: dict) -> dict:
    """A route record's summary without the entries every `Lifetime.summary` has."""
    return {k: v for k, v in summary.items() if k not in _COMMON}


def _needs(model: LeakageModel, name: str, what: str, route: str) -> None:
    if getattr(model, name) is None:
        raise ValueError(f"{name}: the {route} route needs {what}")


class _StripOrProfile:
    """The paper and profile routes: the force balance of eqs (3)-(8) on a stiffness curve."""

    name = ""
    seal = "strip"
    options: Mapping[str, Any] = {}

    def laws(self, model: LeakageModel, options: Mapping[str, Any]) -> str:
        raise NotImplementedError

    def check(self, model: LeakageModel, options: Mapping[str, Any]) -> None:
        _needs(model, "stiffness", "a stiffness curve F0(u) (StiffnessCurve)", self.name)
        _needs(model, "u_c", "a critical gap u_c(p/E) (e.g. a UcTable)", self.name)

    def core(self, model: LeakageModel, options: Mapping[str, Any]):
        from reduced.force_balance import force_balance
        return force_balance(model, self.laws(model, options), self.seal, exact=options.get("exact", False))

    def solve(self, model: LeakageModel, force_N: float, run: Run, options: Mapping[str, Any]) -> Lifetime:
        from reduced.lifetime.paper import integrate
        record = integrate(self.core(model, options), force_N, t_max_s=run.t_max_s,
                           rtol=run.rtol, refine=run.refine, progress=run.progress)
        return self.result(record, model, run, {**options, "cup_laws": self.laws(model, options)})

    def largest_force(self, model: LeakageModel, options: Mapping[str, Any]) -> float:
        return float(self.core(model, options).initial[3])

    def result(self, record: _PaperRecord, model: LeakageModel, run: Run, options: dict) -> Lifetime:
        return Lifetime(route=self.name, force_N=record.force_N, lifetime_s=record.lifetime_s,
                        reason=record.reason, message=record.message,
                        largest_force_N=record.largest_force_N, trajectory=record.trajectory_columns(),
                        details=_details(record.summary()), steps=record.steps,
                        provenance={"route": self.name, "options": options, "model": model.label,
                                    "t_max_s": run.t_max_s, "rtol": run.rtol, "refine": run.refine})


class PaperRoute(_StripOrProfile):
    """Eqs (3)-(10) with the uniform strip of eq (6); cup_laws 'cone' (the default; None is the
    same) or 'curve'."""

    name = "paper"
    options = {"cup_laws": "cone"}

    def laws(self, model: LeakageModel, options: Mapping[str, Any]) -> str:
        return options["cup_laws"] or "cone"

    def check(self, model: LeakageModel, options: Mapping[str, Any]) -> None:
        super().check(model, options)
        if options["cup_laws"] not in (None, "cone", "curve"):
            raise ValueError(f"cup_laws: expected 'cone' or 'curve', got {options['cup_laws']!r}")


class ProfileRoute(_StripOrProfile):
    """The force balance on the curve's laws, the leak through its contact-pressure profiles;
    option exact: solve every flow through a profile directly (the reference for the flow tables,
    `reduced.seal.PbTable`, used without relaxation)."""

    name = "profile"
    seal = "profile"
    options = {"exact": False}

    def laws(self, model: LeakageModel, options: Mapping[str, Any]) -> str:
        return "curve"

    def check(self, model: LeakageModel, options: Mapping[str, Any]) -> None:
        super().check(model, options)
        if not isinstance(options["exact"], bool):
            raise ValueError(f"exact: expected True or False, got {options['exact']!r}")
        if model.stiffness.profiles is None:
            raise ValueError("stiffness: the profile route needs a curve with contact-pressure "
                             "profiles (an FEM curve from `cupcheck stiffness`)")


class CoupledRoute:
    """The cup's state from its FEM suction table; the leak through each state's own profile."""

    name = "coupled"
    options = {"samples": 801, "radial": "annulus", "along_u": "pchip", "u_start_m": None}

    def __init__(self) -> None:
        self._cavities: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

    def check(self, model: LeakageModel, options: Mapping[str, Any]) -> None:
        _needs(model, "suction", "a suction table F1, V over (u, dp) (SuctionTable, `cupcheck suction`)",
               self.name)
        _needs(model, "u_c", "a critical gap u_c(p/E) (e.g. a UcTable)", self.name)
        if model.fluid != "air":
            raise ValueError(f"fluid: the coupled route models a gas-filled cavity only, got '{model.fluid}'")
        u_start = options["u_start_m"]
        if u_start is not None and not math.isfinite(u_start):
            raise ValueError(f"u_start_m: must be finite, got {u_start}")

    def cavity(self, model: LeakageModel, options: Mapping[str, Any]) -> tuple[Any, float, dict]:
        """(the `reduced.coupled.CoupledCavity`, u_start [m], cache) for `model` and `options`,
        built once per pair."""
        from reduced.coupled import CoupledCavity
        from reduced.viscoelastic import measurement_contact_time
        key = tuple(sorted(options.items()))
        per_model = self._cavities.setdefault(model, {})
        if key not in per_model:
            relaxed = model.relaxation is not None
            phi0 = (model.phi0_s if model.phi0_s is not None else measurement_contact_time(model.cup)) \
                if relaxed else None
            cc = CoupledCavity(model.suction, model.u_c, model.gas, model.p_a_Pa, kappa=model.kappa,
                               interface=model.interface, radial=options["radial"],
                               samples=options["samples"], along_u=options["along_u"],
                               relaxation=model.relaxation, phi0_s=phi0)
            h1 = model.suction.h1_m
            u_start = options["u_start_m"]
            if u_start is None:
                u_start = (h1 if math.isfinite(h1) else model.cup.h1_m) - model.cup.h_start_m
            per_model[key] = (cc, float(u_start), {})
        return per_model[key]

    def largest_force(self, model: LeakageModel, options: Mapping[str, Any]) -> float:
        cc, u_start, cache = self.cavity(model, options)
        if "largest" not in cache:
            cache["largest"] = float(cc.largest_force(u_start))
        return cache["largest"]

    def solve(self, model: LeakageModel, force_N: float, run: Run, options: Mapping[str, Any]) -> Lifetime:
        if run.refine != 1:
            raise ValueError(f"refine: the coupled route has no dense output, got {run.refine}")
        from reduced.lifetime.paper import check_run
        check_run(force_N, run.t_max_s, run.rtol, run.refine)
        cc, u_start, _ = self.cavity(model, options)
        record = cc.lifetime(force_N, u_start, t_max_s=run.t_max_s, rtol=run.rtol)
        if run.progress:
            run.progress(1.0, f"F1 = {record.force_N:g} N: {record.reason}")
        return Lifetime(route=self.name, force_N=record.force_N, lifetime_s=record.lifetime_s,
                        reason=record.reason, message=record.message,
                        largest_force_N=self.largest_force(model, options),
                        trajectory=record.trajectory_columns(), details=_details(record.summary()),
                        steps=record.steps,
                        provenance={"route": self.name, "options": dict(options), "model": model.label,
                                    "u_start_mm": 1e3 * u_start, "t_max_s": run.t_max_s, "rtol": run.rtol})


ROUTES: dict[str, Route] = {}


def register_route(route: Route, *, replace: bool = False) -> Route:
    """Add `route` to `ROUTES` under `route.name` (ValueError if the name is taken, unless `replace`)."""
    name = getattr(route, "name", None)
    if not (isinstance(name, str) and name):
        raise ValueError("route: a route needs a non-empty string `name`")
    missing = [m for m in ("check", "solve", "largest_force") if not callable(getattr(route, m, None))]
    if missing or not isinstance(getattr(route, "options", None), Mapping):
        raise ValueError(f"route: '{name}' lacks {', '.join(missing) or 'an options mapping'}")
    if name in ROUTES and not replace:
        raise ValueError(f"route: '{name}' is registered already (replace=True to swap it)")
    ROUTES[name] = route
    return route


for _route in (PaperRoute(), ProfileRoute(), CoupledRoute()):
    register_route(_route)


def _resolve(model: LeakageModel, route: str | None, given: Mapping[str, Any]) -> tuple[Route, dict]:
    """The route object and its full options (defaults filled in); ValueError naming the field."""
    if not isinstance(model, LeakageModel):
        raise ValueError(f"model: expected a LeakageModel, got {type(model).__name__}")
    name = route if route is not None else "paper"
    impl = ROUTES.get(name) if isinstance(name, str) else None
    if impl is None:
        raise ValueError(f"route: unknown route {name!r}; registered: {', '.join(ROUTES)}")
    unknown = [k for k in given if k not in impl.options]
    if unknown:
        allowed = ", ".join(impl.options) or "none"
        raise ValueError(f"{unknown[0]}: not an option of route '{name}' (its options: {allowed})")
    options = {**impl.options, **given}
    impl.check(model, options)
    return impl, options


def solve_lifetime(model: LeakageModel, force_N: float, *, route: str | None = None,
                   t_max_s: float = 1e12, rtol: float = 1e-6, refine: int = 1,
                   progress: Callable[[float, str], None] | None = None, **route_options) -> Lifetime:
    """The lifetime of `model`'s cup under the pull force F1 = force_N [N] on `route` (a name in
    `ROUTES`; None: 'paper').

    t_max_s: the horizon; rtol: the integrator's relative tolerance; refine: output points per
    accepted step (dense output); route_options: the route's own (`ROUTES[name].options`). Bad
    input raises ValueError naming the field."""
    impl, options = _resolve(model, route, route_options)
    return impl.solve(model, force_N, Run(t_max_s, rtol, refine, progress), options)


def largest_holdable_force(model: LeakageModel, route: str | None = None, **route_options) -> float:
    """The largest F1 [N] the freshly pressed cup holds at t = 0 on `route` (as `solve_lifetime`)."""
    impl, options = _resolve(model, route, route_options)
    return impl.largest_force(model, options)
