"""Appendix A: the stiffness force F0(u) of a cone flattened onto the substrate.

Flattening the cone from x to x1 compresses it radially by eps = 1 - cos(alpha); with the wall
thickness d(x) = a + b x, U = E eps^2 V / 2 and u = (x1 - x) sin(alpha) give

    F0(u) = dU/du = pi (1 - cos a)^2 (cos a / sin a) E (a x + b x^2),  x = x1 - u / sin a,

with a = (d0 x1 - d1 x0)/(x1 - x0), b = (d1 - d0)/(x1 - x0).

Our reading (stated, since the paper leaves it open): x0 = r0 and x1 = r1 of the cup, d0 is the
wall thickness at r0 and d1 = 0 (the paper's worked example). Then for small u

    F0 ~ pi E d0 (1 - cos a)^2 cos a / sin^2 a * x1 / (x1 - x0) * u,

which for cup A (alpha = 33 deg, x0 = 5 mm, x1 = 19 mm), E = 4 MPa and d0 = 2 mm is 2.51 N/mm,
the paper's "F0 ~ (2.5 N/mm) u". The curve is sampled over the cup's whole stroke u in [0, h1].
"""

from __future__ import annotations

import math

import numpy as np

from reduced.cup import CupParameters
from reduced.stiffness_curve import StiffnessCurve

__all__ = ["appendix_a_force", "appendix_a_small_u_slope", "appendix_a_curve"]


def appendix_a_force(u_m, alpha_deg: float, E_Pa: float, d0_m: float, x0_m: float, x1_m: float,
                     d1_m: float = 0.0):
    """F0(u) [N] of Appendix A for the linear wall thickness d(x) = a + b x (floats or arrays)."""
    a_rad = math.radians(alpha_deg)
    s, c = math.sin(a_rad), math.cos(a_rad)
    a = (d0_m * x1_m - d1_m * x0_m) / (x1_m - x0_m)
    b = (d1_m - d0_m) / (x1_m - x0_m)
    x = x1_m - np.asarray(u_m, dtype=float) / s
    return math.pi * (1.0 - c) ** 2 * (c / s) * E_Pa * (a * x + b * x * x)


def appendix_a_small_u_slope(alpha_deg: float, E_Pa: float, d0_m: float, x0_m: float,
                             x1_m: float) -> float:
    """dF0/du at u -> 0 for d1 = 0 [N/m]: pi E d0 (1-cos a)^2 cos a / sin^2 a * x1/(x1-x0)."""
    a_rad = math.radians(alpha_deg)
    s, c = math.sin(a_rad), math.cos(a_rad)
    return math.pi * E_Pa * d0_m * (1.0 - c) ** 2 * c / (s * s) * x1_m / (x1_m - x0_m)


def appendix_a_curve(cup: CupParameters, E_Pa: float = 4e6, d0_m: float = 2e-3, d1_m: float = 0.0,
                     x0_m: float | None = None, x1_m: float | None = None,
                     samples: int = 401) -> StiffnessCurve:
    """The Appendix A force as a `StiffnessCurve` over u in [0, h1] (x0 = r0, x1 = r1 by default).

    `samples` points are enough for the PCHIP interpolant to reproduce the closed form to
    ~1e-7 relative (the curve is a parabola in u).
    """
    x0 = cup.r0_m if x0_m is None else x0_m
    x1 = cup.r1_m if x1_m is None else x1_m
    for name, value in (("E_Pa", E_Pa), ("d0_m", d0_m)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name}: must be > 0, got {value}")
    if not (0 <= d1_m and x1 > x0 > 0):
        raise ValueError(f"appendix-a: need d1_m >= 0 and x1 > x0 > 0, got d1={d1_m}, x0={x0}, x1={x1}")
    if samples < 2:
        raise ValueError(f"samples: need >= 2, got {samples}")
    u = np.linspace(0.0, cup.h1_m, samples)
    F0 = appendix_a_force(u, cup.alpha_deg, E_Pa, d0_m, x0, x1, d1_m)
    provenance = {"source": "appendix-a", "cup": cup.name, "E_Pa": E_Pa, "d0_m": d0_m, "d1_m": d1_m,
                  "x0_m": x0, "x1_m": x1, "alpha_deg": cup.alpha_deg}
    return StiffnessCurve(u_m=u, F0_N=F0, h1_m=cup.h1_m, provenance=provenance)
