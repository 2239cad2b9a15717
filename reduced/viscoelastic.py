"""Viscoelastic relaxation: E_eff(t) (Sec. 5.2) and the contact-time state phi, eq (10).

`RelaxationModulus` is a table (t_s, E_Pa) interpolated in log-log (`reduced.loglog`), and extrapolated
in log-log beyond its last sample (the relaxation continues as the last power law).

t -> 0: the data start at 1 s (the DMA creep test), and a power law diverges as t -> 0, so
below the first sample the modulus is held at its first value, E_eff(t < t_first) = E_eff(t_first).
That is explicit and continuous; it means contact times shorter than the first sample see the
1 s modulus (which is what the paper itself uses for fast contact, "E_eff ~ 4 MPa at 1 s").

The default law is the power law through the paper's two statements, 4.4 MPa at 1 s and
1.8 MPa at 3e4 s: E_eff = 4.4 MPa (t / 1 s)^(-n), n = ln(4.4/1.8)/ln(3e4) = 0.0867.

The stiffness was measured at a constant plate speed hdot ~ 0.12 mm/s (Fig. 1distance.2force),
i.e. rdot = hdot / tan(alpha) (eq 3); a point of the cup then stays in the contact strip for
phi0 = l / rdot (eq 10 at steady state). For cup A at r_start = 12 mm: l = 2.4 mm (eq 5),
rdot = 0.185 mm/s, phi0 = 13.0 s. See `measurement_contact_time`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reduced.cup import CupParameters
from reduced.loglog import LogLogPchip, elementwise, read_two_columns

__all__ = ["RelaxationModulus", "default_relaxation", "measurement_contact_time",
           "contact_time_rate", "PAPER_PLATE_SPEED_M_S"]

#: plate speed of the paper's stiffness measurement, 0.12 mm/s
PAPER_PLATE_SPEED_M_S = 0.12e-3
_HEADER = "t_s,E_Pa"


@dataclass(frozen=True, eq=False)
class RelaxationModulus:
    """E_eff(t): log-log interpolation of (t_s, E_Pa); constant below t_s[0]; log-log beyond t_s[-1]."""

    t_s: np.ndarray
    E_Pa: np.ndarray
    provenance: str = ""
    _law: LogLogPchip = field(init=False, repr=False)

    def __post_init__(self) -> None:
        t = np.array(self.t_s, dtype=float).reshape(-1)
        E = np.array(self.E_Pa, dtype=float).reshape(-1)
        if t.size != E.size or t.size < 2:
            raise ValueError(f"E_Pa: need >= 2 samples matching t_s, got {t.size} and {E.size}")
        if not (np.all(np.isfinite(t)) and np.all(t > 0) and np.all(np.diff(t) > 0)):
            raise ValueError("t_s: times must be finite, > 0 and strictly increasing")
        if not (np.all(np.isfinite(E)) and np.all(E > 0)):
            raise ValueError("E_Pa: moduli must be finite and > 0")
        for name, arr in (("t_s", t), ("E_Pa", E)):
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "_law", LogLogPchip(t, E))

    def modulus_and_log_slope(self, t: float) -> tuple[float, float]:
        """(E_eff(t) [Pa], d ln E / d ln t); the slope is 0 on the short-time plateau."""
        if t <= self.t_s[0]:
            return float(self.E_Pa[0]), 0.0
        return self._law.value_and_slope(t)

    def __call__(self, t_s):
        """E_eff(t) [Pa] (float or array)."""
        return elementwise(lambda t: self.modulus_and_log_slope(t)[0], t_s)

    @classmethod
    def from_csv(cls, path: str | os.PathLike) -> RelaxationModulus:
        t, E, _ = read_two_columns(path, _HEADER, "relaxation")
        return cls(t, E, provenance=f"csv:{Path(path).name}")


def default_relaxation() -> RelaxationModulus:
    """Power law through 4.4 MPa at 1 s and 1.8 MPa at 3e4 s (Sec. 5.2)."""
    return RelaxationModulus(np.array([1.0, 3e4]), np.array([4.4e6, 1.8e6]),
                             provenance="power law through the paper's 4.4 MPa at 1 s and 1.8 MPa at 3e4 s")


def measurement_contact_time(cup: CupParameters, plate_speed_m_s: float = PAPER_PLATE_SPEED_M_S,
                             r_m: float | None = None) -> float:
    """phi0 = l / rdot of the stiffness measurement [s], rdot = hdot / tan(alpha) (eq 3), l from eq (5).

    l is taken at r = r_start unless `r_m` is given. Cup A: 13.0 s.
    """
    if not plate_speed_m_s > 0:
        raise ValueError(f"plate_speed_m_s: must be > 0, got {plate_speed_m_s}")
    r = cup.r_start_m if r_m is None else r_m
    return cup.contact_width(r) * cup.tan_alpha / plate_speed_m_s


def contact_time_rate(phi_s: float, r_dot_m_s: float, l_m: float) -> float:
    """phi_dot = 1 - rdot phi / l, eq (10)."""
    return 1.0 - r_dot_m_s * phi_s / l_m
