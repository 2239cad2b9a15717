"""The suction cup as a rigid truncated cone: parameters (Table 1) and the cone laws, eqs (3)-(5).

The cup is a cone of half-opening angle 90 deg - alpha whose rim touches the substrate; the top
plate has radius r0 and the undeformed rim radius is r1 (Fig. 3). With h the height of the top
plate above the substrate and r the inner radius of the contact annulus,

    r / r0 = 1 + h / h0,            h0 = r0 tan(alpha)                (3)
    V = V0 [(r / r0)^3 - 1],        V0 = pi r0^2 h0 / 3               (4)
    l = l0 + l_a (1 - r / r0),      l_a = (l1 - l0) / (1 - r1 / r0)   (5)

so h = (r - r0) tan(alpha) and the undeformed height (r = r1) is h1 = (r1 - r0) tan(alpha).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["CupParameters", "CUP_A", "CUP_B", "CUPS", "cup_by_name"]


@dataclass(frozen=True)
class CupParameters:
    """Geometry of a suction cup (Table 1), SI units.

    r0_m: top-plate radius; r1_m: undeformed rim radius; alpha_deg: cone angle with the substrate;
    r_start_m: inner contact radius after pressing on, before any pull force (sets the trapped gas);
    l0_m, l1_m: contact-strip widths at r = r0 and r = r1 (eq 5); beta: share of the pressure
    difference p_a - p_b carried by the contact strip (eq 6), in [0, 1].
    """

    r0_m: float
    r1_m: float
    alpha_deg: float
    r_start_m: float
    l0_m: float
    l1_m: float
    beta: float
    name: str = "custom"

    def __post_init__(self) -> None:
        _check(self.r0_m > 0, f"r0_m: top-plate radius must be > 0 m, got {self.r0_m}")
        _check(self.r1_m > self.r0_m, f"r1_m: rim radius must exceed r0 = {self.r0_m} m, got {self.r1_m}")
        _check(0 < self.alpha_deg < 90,
               f"alpha_deg: cone angle must be in (0, 90) degrees, got {self.alpha_deg}")
        _check(self.r0_m < self.r_start_m < self.r1_m,
               f"r_start_m: start radius must be in ({self.r0_m}, {self.r1_m}) m, got {self.r_start_m}")
        _check(self.l0_m > 0 and self.l1_m > 0,
               f"l0_m, l1_m: contact-strip widths must be > 0 m, got {self.l0_m}, {self.l1_m}")
        _check(0 <= self.beta <= 1, f"beta: must be in [0, 1], got {self.beta}")

    # ------------------------------------------------------------------ eq (3)
    @property
    def tan_alpha(self) -> float:
        return math.tan(math.radians(self.alpha_deg))

    @property
    def h0_m(self) -> float:
        """h0 = r0 tan(alpha), the height of the cone's apex above the top plate (eq 3)."""
        return self.r0_m * self.tan_alpha

    @property
    def h1_m(self) -> float:
        """Undeformed cup height h1 = (r1 - r0) tan(alpha) (eq 3 at r = r1)."""
        return (self.r1_m - self.r0_m) * self.tan_alpha

    @property
    def h_start_m(self) -> float:
        """Cup height at r = r_start (eq 3)."""
        return self.height(self.r_start_m)

    def radius(self, h_m: float) -> float:
        """Inner contact radius r(h) = r0 (1 + h/h0), eq (3)."""
        return self.r0_m * (1.0 + h_m / self.h0_m)

    def height(self, r_m: float) -> float:
        """Cup height h(r) = (r - r0) tan(alpha), eq (3) inverted."""
        return (r_m - self.r0_m) * self.tan_alpha

    # ------------------------------------------------------------------ eq (4)
    @property
    def V0_m3(self) -> float:
        """V0 = pi r0^2 h0 / 3 (eq 4)."""
        return math.pi * self.r0_m ** 2 * self.h0_m / 3.0

    def volume(self, r_m: float) -> float:
        """Cavity volume V(r) = V0 [(r/r0)^3 - 1], eq (4)."""
        return self.V0_m3 * ((r_m / self.r0_m) ** 3 - 1.0)

    # ------------------------------------------------------------------ eq (5)
    @property
    def l_a_m(self) -> float:
        """l_a = (l1 - l0) / (1 - r1/r0), eq (5)."""
        return (self.l1_m - self.l0_m) / (1.0 - self.r1_m / self.r0_m)

    def contact_width(self, r_m: float) -> float:
        """Contact-strip width l(r) = l0 + l_a (1 - r/r0), eq (5)."""
        return self.l0_m + self.l_a_m * (1.0 - r_m / self.r0_m)


def _check(ok: bool, message: str) -> None:
    if not ok:
        raise ValueError(message)


#: Table 1, cup A (alpha = 33 deg).
CUP_A = CupParameters(r0_m=5e-3, r1_m=19e-3, alpha_deg=33.0, r_start_m=12e-3,
                      l0_m=4e-3, l1_m=0.8e-3, beta=0.8, name="A")
#: Table 1, cup B (alpha = 21 deg).
CUP_B = CupParameters(r0_m=5e-3, r1_m=19e-3, alpha_deg=21.0, r_start_m=12e-3,
                      l0_m=5e-3, l1_m=2e-3, beta=0.8, name="B")
CUPS = {"A": CUP_A, "B": CUP_B}


def cup_by_name(name: str) -> CupParameters:
    """The Table 1 preset called `name` ('A' or 'B')."""
    try:
        return CUPS[name.upper()]
    except KeyError:
        raise ValueError(f"cup: unknown cup '{name}', allowed: {', '.join(CUPS)}") from None
