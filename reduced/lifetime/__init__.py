"""The lifetime of a suction cup: one entry point (`solve_lifetime`) over a registry of routes.

- `routes`: the entry point, the registry and the three routes (paper, profile, coupled).
- `result`: `Lifetime`, the one result type, and `REASONS`, the one vocabulary of endings.
- `paper`: the integrator of the paper and profile routes (eqs 3-10 in time), private to them.
- `quadrature`: the same lifetime without relaxation as a quadrature, a second method.

The model (`LeakageModel`) lives in `reduced.model`. The names are loaded on first use (PEP 562)
and a route loads its own modules when it first runs, so a paper-route lifetime imports nothing
of the coupled route.
"""

from __future__ import annotations

from reduced._lazy import lazy_exports

#: public name -> the module that defines it
_WHERE = {
    "lifetime_by_quadrature": "reduced.lifetime.quadrature",
    "REASONS": "reduced.lifetime.result", "Lifetime": "reduced.lifetime.result",
    **{name: "reduced.lifetime.routes" for name in ("ROUTES", "Route", "Run", "largest_holdable_force",
                                                     "register_route", "solve_lifetime")},
    "LeakageModel": "reduced.model", "reference_model": "reduced.model",
}

__all__ = ["LeakageModel", "reference_model", "solve_lifetime", "largest_holdable_force", "Lifetime",
           "REASONS", "ROUTES", "Route", "Run", "register_route", "lifetime_by_quadrature"]


__getattr__, __dir__ = lazy_exports("reduced.lifetime", _WHERE, globals())
