"""Every lifetime of the toolkit, through one function: `lifetimes` runs `reduced.solve_lifetime`
for each pull force on one route and asks `reduced.largest_holdable_force` for the largest force
the fresh cup holds, so that commands, scenes, sweeps and cross-checks read one result type
(`reduced.Lifetime`) and name the route one way (the CLI's --route, a scene's stiffness.route).

`route_options` is the one rule from a route and the paper route's cup laws ("cone": eqs 3-5,
"curve": the stiffness curve's r, V, l) to the route's options.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:                          # importing this module imports no reduced
    from reduced.lifetime import LeakageModel, Lifetime

__all__ = ["ROUTES", "Lifetimes", "lifetimes", "route_options", "route_laws", "end_state_columns"]

#: the names of `reduced.ROUTES`, spelled out so that building the command line imports no reduced
#: model (a test pins them equal)
ROUTES = ("paper", "profile", "coupled", "fem")


@dataclass(frozen=True)
class Lifetimes:
    """The lifetimes of one model on one route: one `reduced.Lifetime` per pull force (in the order
    given) and the largest pull force [N] the freshly pressed cup holds."""

    route: str
    results: tuple[Lifetime, ...]
    largest_force_N: float

    def __iter__(self):
        return iter(self.results)

    def __len__(self) -> int:
        return len(self.results)

    def __getitem__(self, i: int) -> Lifetime:
        return self.results[i]


def route_laws(route: str, cup_laws: str | None = None) -> str:
    """Where r(h), V(h), l(h) come from on `route`: paper -> the cone laws unless cup_laws says
    'curve'; profile -> the curve's (cone refused); coupled -> the FEM's own, from its suction
    table ('curve'; cup_laws refused); fem -> its FEM states' ('curve'; cup_laws refused). ValueError names --cup-laws."""
    if route == "fem":
        if cup_laws is not None:
            raise ValueError("--cup-laws: the fem route takes r, V and the contact profile from its own "
                             "FEM states; drop --cup-laws")
        return "curve"
    if route == "coupled":
        if cup_laws is not None:
            raise ValueError("--cup-laws: the coupled route takes r and V from the FEM suction table; "
                             "drop --cup-laws")
        return "curve"
    if route == "profile":
        if cup_laws not in (None, "curve"):
            raise ValueError("--cup-laws: the profile route takes r and V from the FEM curve whose "
                             "profiles it crosses; drop --cup-laws cone")
        return "curve"
    return cup_laws or "cone"


def route_options(route: str, cup_laws: str | None = None) -> dict[str, Any]:
    """The options `reduced.solve_lifetime` takes on `route` for the cup laws (`route_laws`)."""
    laws = route_laws(route, cup_laws)
    return {"cup_laws": laws} if route == "paper" else {}


def lifetimes(model: LeakageModel, forces_N: Iterable[float], route: str, *, t_max_s: float = 1e12,
              rtol: float = 1e-6, refine: int = 1, progress: Callable[[float, str], None] | None = None,
              **options: Any) -> Lifetimes:
    """The lifetime of `model`'s cup under each pull force [N] on `route` (`reduced.ROUTES`), with
    the route's `options`, and its largest holdable force (computed first: it checks the model
    before any lifetime). `progress(fraction, message)` after each force. Bad input raises
    ValueError naming the field."""
    from reduced.lifetime import largest_holdable_force, solve_lifetime

    if route == "fem":                     # the FEM-in-the-loop route registers itself on first use
        from validation.bridge.fem_route import register
        register()
    largest = largest_holdable_force(model, route, **options)
    forces = [float(f) for f in forces_N]
    results = []
    for i, force in enumerate(forces):
        results.append(solve_lifetime(model, force, route=route, t_max_s=t_max_s, rtol=rtol, refine=refine,
                                      **options))
        if progress:
            progress((i + 1) / len(forces), f"F1 = {force:g} N")
    return Lifetimes(route, tuple(results), largest)


def end_state_columns(results: Lifetimes) -> dict[str, list]:
    """A lifetime table's route-specific columns, one value per force (units in the names): on
    the fem route the largest holdable force and the FEM's end state (plate displacement, cavity
    pressure, seal radius; empty where the cup held no state); on the paper and profile routes
    the ballistic share and the cone's end state (contact radius, cavity pressure)."""
    if results.route == "fem":
        def end(key: str) -> list:
            return [r.details.get(key, "") for r in results]
        return {"largest_force_N": [results.largest_force_N] * len(results), "u_final_mm": end("u_final_mm"),
                "p_b_final_Pa": end("p_b_final_Pa"), "seal_r_final_mm": end("seal_r_final_mm")}
    return {"ballistic_share": [r.details["ballistic_share"] for r in results],
            "r_final_mm": [float(r.trajectory["r_mm"][-1]) for r in results],
            "p_b_final_Pa": [float(r.trajectory["p_b_Pa"][-1]) for r in results]}
