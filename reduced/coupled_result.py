"""The coupled route's own record of one lifetime: the trajectory along the branch in SI units.

`reduced.lifetime.Lifetime` is the common result of every route; this record is what the coupled
cavity's quadrature and its relaxed integrator (`reduced.coupled`, `reduced.coupled_relax`) return.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__: list[str] = []


@dataclass(frozen=True, eq=False)
class _CoupledRecord:
    """Lifetime [s] (inf if the interface seals) and the trajectory along the branch (SI)."""

    force_N: float
    lifetime_s: float
    reason: str              # "table_edge", "fold", "reached_r1" (the seal opened), "sealed", "over_force"
    #                          (relaxed: also "horizon")
    message: str
    N0: float
    t_s: np.ndarray
    u_m: np.ndarray
    dp_Pa: np.ndarray        # p_a - p_b
    N: np.ndarray
    N_dot_per_s: np.ndarray
    V_m3: np.ndarray
    p_a_Pa: float = 1e5
    phi_s: np.ndarray | None = None     # with relaxation: the contact time of eq (10)
    kappa: np.ndarray | None = None     # with relaxation: the stiffness factor kappa(phi)
    steps: int = 0                      # with relaxation: accepted integration steps

    @property
    def p_b_Pa(self) -> np.ndarray:
        return self.p_a_Pa - self.dp_Pa

    def summary(self) -> dict:
        """JSON-ready summary (lifetime_s null when infinite)."""
        return {"force_N": self.force_N,
                "lifetime_s": self.lifetime_s if math.isfinite(self.lifetime_s) else None,
                "reason": self.reason, "sealed": self.reason == "sealed", "N0": self.N0,
                "u_final_mm": 1e3 * float(self.u_m[-1]) if self.u_m.size else None,
                "p_b_final_Pa": float(self.p_b_Pa[-1]) if self.dp_Pa.size else None,
                **({} if self.phi_s is None else
                   {"phi_final_s": float(self.phi_s[-1]) if self.phi_s.size else None,
                    "kappa_final": float(self.kappa[-1]) if self.kappa.size else None,
                    "steps": self.steps}),
                "message": self.message}

    def trajectory_columns(self) -> dict[str, np.ndarray]:
        """Trajectory arrays under CSV column names that carry their units."""
        return {"t_s": self.t_s, "u_mm": 1e3 * self.u_m, "p_b_Pa": self.p_b_Pa, "N": self.N,
                "N_dot_per_s": self.N_dot_per_s, "V_mm3": 1e9 * self.V_m3,
                **({} if self.phi_s is None else {"phi_s": self.phi_s, "kappa": self.kappa})}
