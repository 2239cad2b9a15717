"""The paper route's lifetime without relaxation as a quadrature: a second method for the integrator.

Without relaxation the state is one-dimensional (the gas content N on the equilibrium branch), so
the time to move along the branch is t = int (dN_eq/dh) / Ndot(h) dh, with no time stepping.
"""

from __future__ import annotations

import math

from reduced.lifetime.paper import sealed_on_branch, start_height
from reduced.lifetime.routes import _resolve
from reduced.model import LeakageModel

__all__ = ["lifetime_by_quadrature"]


def lifetime_by_quadrature(model: LeakageModel, force_N: float, *, route: str = "paper",
                           epsrel: float = 1e-10, **route_options) -> float:
    """Reference-mode lifetime as t = int_{h(0+)}^{h_end} (dN_eq/dh) / Ndot(h) dh (no time stepping).

    An independent evaluation for checking `solve_lifetime` on `route` ('paper' or 'profile', with
    their options, e.g. cup_laws='curve' or exact=True): without relaxation the state is
    one-dimensional and the time to move along the equilibrium branch is a quadrature.
    Returns inf if u_c vanishes on the branch and 0 for an over-force.
    """
    if not model.reference:
        raise ValueError("lifetime_by_quadrature: only without relaxation (reference mode)")
    impl, options = _resolve(model, route, route_options)
    if not hasattr(impl, "core"):
        raise ValueError(f"route: the quadrature follows the paper and profile routes' force balance, "
                         f"not route {route!r}")
    core = impl.core(model, options)
    F1 = float(force_N)
    if not (math.isfinite(F1) and F1 > 0):
        raise ValueError(f"force_N: pull force must be > 0 N, got {force_N}")
    hs, N0, kappa0, Fmax, hm = core.initial
    if F1 >= Fmax:
        return 0.0
    h0 = start_height(core, F1)
    h_end, _ = core.branch_end(h0, 1.0, F1)

    def integrand(h: float) -> float:
        N, dN = core.n_eq(h, 1.0, F1)
        Ndot = core.state(h, N, 1.0, core.m.E_Pa, F1)[0]
        return math.inf if Ndot <= 0 else dN / Ndot

    if sealed_on_branch(core, h0, h_end, F1) is not None:
        return math.inf
    t_bubble = 0.0
    if core.liquid and N0 < core.n_eq(h0, 1.0, F1)[0]:    # the vapour bubble refills at h_c
        t_bubble = (core.n_eq(h0, 1.0, F1)[0] - N0) / core.state(h0, N0, 1.0, core.m.E_Pa, F1)[0]
    # the PCHIP breakpoints are kinks of higher derivatives: hand them to quad
    knots = sorted(x for x in (core.h1 - u for u in core.F0.x) if h0 < x < h_end)
    from scipy.integrate import quad        # only here: a lifetime by integration never imports it

    t, err = quad(integrand, h0, h_end, epsabs=0.0, epsrel=epsrel, limit=4 * len(knots) + 200,
                  points=knots[:: max(1, len(knots) // 100)] or None)
    return t_bubble + t
