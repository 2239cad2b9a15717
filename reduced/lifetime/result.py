"""The one result type of every lifetime route (`Lifetime`), the one vocabulary of how a lifetime
ends (`REASONS`), and the paper integrator's own record (`_PaperRecord`, SI arrays), private to
the paper and profile routes, which turn it into a `Lifetime`."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

__all__ = ["Lifetime", "REASONS"]

#: How a lifetime ends, on every route:
#: "reached_r1"  the contact radius reached r1: the cup let go (paper and profile routes)
#: "table_edge"  u reached the suction table's smallest u: the end of the data (coupled route)
#: "fold"        the force balance lost its equilibrium: no state holds more gas (static fold), or
#:               with relaxation the dynamic singularity where rdot diverges in eq (10)
#: "over_force"  F1 is at or above the largest holdable force: detached at t = 0
#: "sealed"      u_c = 0 on the way: no leak, the lifetime is infinite
#: "horizon"     still holding at t_max_s (lifetime_s is inf)
REASONS = ("reached_r1", "table_edge", "fold", "over_force", "sealed", "horizon")


def _frozen_columns(columns: Mapping[str, Any]) -> Mapping[str, np.ndarray]:
    out = {}
    for name, values in columns.items():
        a = np.array(values, dtype=float)
        a.flags.writeable = False
        out[name] = a
    return MappingProxyType(out)


@dataclass(frozen=True, eq=False)
class Lifetime:
    """The lifetime of one cup under one pull force, on one route (solve_ivp-shaped: the outcome,
    why it ended, the trajectory and how it was obtained).

    route: the route's name. force_N: the pull F1. lifetime_s: time to detachment (inf when sealed
    or beyond the horizon, 0 for an over-force). reason: one of `REASONS`. message: one line for a
    person. largest_force_N: the largest F1 the cup holds at t = 0 on this route. trajectory: the
    state over time, columns named with their units (t_s, p_b_Pa, N or V_liquid_mm3, and the
    route's own: r_mm, h_mm on the paper and profile routes, u_mm on the coupled route, phi_s with
    relaxation ...). details: the route's scalar summary entries (final state, ballistic share,
    N0, ...). provenance: the route, its options and the model's label. steps: accepted
    integration steps (0 for a quadrature).
    """

    route: str
    force_N: float
    lifetime_s: float
    reason: str
    message: str
    largest_force_N: float
    trajectory: Mapping[str, np.ndarray]
    details: Mapping[str, Any] = field(default_factory=dict)
    provenance: Mapping[str, Any] = field(default_factory=dict)
    steps: int = 0

    def __reduce__(self):
        """Pickle by the constructor's fields, the read-only mappings as plain dicts (a
        MappingProxyType does not pickle; the constructor wraps them again)."""
        import dataclasses
        values = [getattr(self, f.name) for f in dataclasses.fields(self) if f.init]
        return type(self), tuple(dict(v) if isinstance(v, MappingProxyType) else v for v in values)

    def __post_init__(self) -> None:
        if self.reason not in REASONS:
            raise ValueError(f"reason: {self.reason!r} is not one of {', '.join(REASONS)}")
        object.__setattr__(self, "trajectory", _frozen_columns(self.trajectory))
        object.__setattr__(self, "details", MappingProxyType(dict(self.details)))
        object.__setattr__(self, "provenance", MappingProxyType(dict(self.provenance)))

    @property
    def sealed(self) -> bool:
        return self.reason == "sealed"

    def summary(self) -> dict:
        """JSON-ready summary (lifetime_s null when infinite): the outcome, the route's details, the message."""
        return {"force_N": self.force_N,
                "lifetime_s": self.lifetime_s if math.isfinite(self.lifetime_s) else None,
                "reason": self.reason, "sealed": self.sealed, **self.details, "message": self.message}

    def trajectory_columns(self) -> dict[str, np.ndarray]:
        """Trajectory arrays under CSV column names that carry their units."""
        return dict(self.trajectory)


@dataclass(frozen=True, eq=False)
class _PaperRecord:
    """Lifetime and trajectories (SI). lifetime_s is inf when sealed or beyond the horizon."""

    force_N: float
    lifetime_s: float
    reason: str
    message: str
    largest_force_N: float
    N0: float
    t_s: np.ndarray
    r_m: np.ndarray
    h_m: np.ndarray
    p_b_Pa: np.ndarray
    p_Pa: np.ndarray
    u_c_m: np.ndarray
    N: np.ndarray
    N_dot_per_s: np.ndarray
    phi_s: np.ndarray
    ballistic_share_t: np.ndarray
    force_residual: np.ndarray
    steps: int = 0
    fluid: str = "air"

    @property
    def sealed(self) -> bool:
        return self.reason == "sealed"

    @property
    def ballistic_share(self) -> float:
        """Share of the leaked molecules that went through eq (19)'s ballistic term."""
        if self.t_s.size < 2:
            return float(self.ballistic_share_t[0])
        total = _trapezoid(self.N_dot_per_s, self.t_s)
        if total <= 0:
            return float(self.ballistic_share_t[0])
        return float(_trapezoid(self.ballistic_share_t * self.N_dot_per_s, self.t_s) / total)

    def summary(self) -> dict:
        """JSON-ready summary (lifetime_s null when infinite)."""
        return {"force_N": self.force_N,
                "lifetime_s": self.lifetime_s if math.isfinite(self.lifetime_s) else None,
                "reason": self.reason, "sealed": self.sealed,
                "ballistic_share": self.ballistic_share,
                "largest_force_N": self.largest_force_N if math.isfinite(self.largest_force_N) else None,
                "r_final_mm": 1e3 * float(self.r_m[-1]), "p_b_final_Pa": float(self.p_b_Pa[-1]),
                "steps": self.steps, "message": self.message}

    def trajectory_columns(self) -> dict[str, np.ndarray]:
        """Trajectory arrays under CSV column names that carry their units."""
        return {"t_s": self.t_s, "r_mm": 1e3 * self.r_m, "h_mm": 1e3 * self.h_m,
                "p_b_Pa": self.p_b_Pa, "p_Pa": self.p_Pa, "u_c_nm": 1e9 * self.u_c_m,
                **({"N": self.N, "N_dot_per_s": self.N_dot_per_s} if self.fluid == "air" else
                   {"V_liquid_mm3": 1e9 * self.N, "V_dot_mm3_per_s": 1e9 * self.N_dot_per_s}),
                "phi_s": self.phi_s, "ballistic_share": self.ballistic_share_t}


def _trapezoid(y: np.ndarray, t: np.ndarray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))
