"""The lifetime of a suction cup: one entry point (`solve_lifetime`) over a registry of routes.

- `routes`: the entry point, the registry and the three routes (paper, profile, coupled).
- `result`: `Lifetime`, the one result type, and `REASONS`, the one vocabulary of endings.
- `paper`: the integrator of the paper and profile routes (eqs 3-10 in time), private to them.
- `quadrature`: the same lifetime without relaxation as a quadrature, a second method.

The model (`LeakageModel`) lives in `reduced.model`.
"""

from reduced.lifetime.quadrature import lifetime_by_quadrature
from reduced.lifetime.result import REASONS, Lifetime
from reduced.lifetime.routes import ROUTES, Route, Run, largest_holdable_force, register_route, solve_lifetime
from reduced.model import LeakageModel, reference_model

__all__ = ["LeakageModel", "reference_model", "solve_lifetime", "largest_holdable_force", "Lifetime",
           "REASONS", "ROUTES", "Route", "Run", "register_route", "lifetime_by_quadrature"]
