"""Geometry sources: where the model takes r(h), V(h) and l(h) from.

One mechanism with two sources, both answering `at(h) -> (r, dr/dh, V, dV/dh, l)` on floats:

- `ConeGeometry`: the rigid-cone laws of the paper, eqs (3), (4) and (5).
- `CurveGeometry`: the inner contact radius, cavity volume and strip width that a stiffness curve
  carries (e.g. from the FEM), interpolated by PCHIP over u = h1 - h. A strip width of 0 is a
  line contact (the FEM resolves no strip there): eq (6) then gives an unbounded pressure, and
  the lifetime model treats the interface there as sealed.

The cup detaches when r reaches r1, i.e. at the undeformed height (u = 0): `h_detach_m`. The plate
displacement u = h_ref_m - h is measured from `h_ref_m`, the source's undeformed height.
"""

from __future__ import annotations

import numpy as np

from reduced.cup import CupParameters
from reduced.fast_curve import CurveRangeError, ScalarPchip
from reduced.roots import brentq
from reduced.stiffness_curve import StiffnessCurve

__all__ = ["ConeGeometry", "CurveGeometry", "geometry_source"]


class ConeGeometry:
    """r(h) eq (3), V(h) eq (4), l(h) eq (5) of a rigid truncated cone."""

    name = "cone"
    line_contact = False          # eq (5) gives l > 0 on (0, h1]

    def __init__(self, cup: CupParameters):
        self.cup = cup
        self.r0, self.h0, self.V0 = cup.r0_m, cup.h0_m, cup.V0_m3
        self.l0, self.la = cup.l0_m, cup.l_a_m
        self.h_detach_m = self.h_ref_m = cup.h1_m
        self.h_min_m = 0.0
        self.h_start_m = cup.h_start_m

    def at(self, h: float) -> tuple[float, float, float, float, float]:
        if h > self.h_detach_m * (1 + 1e-12) or h <= 0.0:
            raise CurveRangeError(f"geometry: cup height {1e3 * h:.6g} mm outside the cone's "
                                  f"(0, {1e3 * self.h_detach_m:.6g}] mm")
        x = 1.0 + h / self.h0            # r / r0
        rp = self.r0 / self.h0           # dr/dh
        return (self.r0 * x, rp, self.V0 * (x * x * x - 1.0), 3.0 * self.V0 * x * x / self.h0,
                self.l0 + self.la * (1.0 - x))      # eq (5)

    def at_array(self, h: np.ndarray) -> tuple[np.ndarray, ...]:
        """`at` on an array of heights inside (0, h1]."""
        x = 1.0 + np.asarray(h, dtype=float) / self.h0
        return (self.r0 * x, np.full_like(x, self.r0 / self.h0), self.V0 * (x ** 3 - 1.0),
                3.0 * self.V0 * x * x / self.h0, self.l0 + self.la * (1.0 - x))


class CurveGeometry:
    """r_c(h), V(h), l(h) from a stiffness curve that carries them (PCHIP in u = h1 - h; r_c as
    `StiffnessCurve.contact_edge_m`, monotone once a strip has formed)."""

    name = "curve"

    def __init__(self, cup: CupParameters, curve: StiffnessCurve):
        missing = [c for c in ("r_c_m", "l_m", "V_m3") if not curve.has(c)]
        if missing:
            raise ValueError(f"geometry: 'curve' needs the stiffness curve's columns r_c_mm, l_mm, "
                             f"V_mm3; '{curve.provenance.get('source', '?')}' lacks "
                             f"{', '.join(m[:-2] + '_mm' for m in missing)}")
        self.cup = cup
        self.line_contact = bool(np.any(curve.l_m <= 0))     # somewhere l = 0: sealed there
        self.h1 = self.h_ref_m = curve.h1_m
        self._r = ScalarPchip(curve.u_m, curve.contact_edge_m, "stiffness curve (u for r_c)")
        self._V = ScalarPchip(curve.u_m, curve.V_m3, "stiffness curve (u for V)")
        self._l = ScalarPchip(curve.u_m, curve.l_m, "stiffness curve (u for l)")
        self.h_detach_m = curve.h1_m - float(curve.u_m[0])
        self.h_min_m = curve.h1_m - float(curve.u_m[-1])
        r_lo, r_hi = self._r.value(float(curve.u_m[-1])), self._r.value(float(curve.u_m[0]))
        if not r_lo < cup.r_start_m < r_hi:
            raise ValueError(f"r_start_m: {1e3 * cup.r_start_m:g} mm is outside the curve's contact "
                             f"radii [{1e3 * r_lo:.4g}, {1e3 * r_hi:.4g}] mm")
        self.h_start_m = brentq(lambda h: self.at(h)[0] - cup.r_start_m, self.h_min_m,
                                self.h_detach_m, xtol=1e-15)

    def at(self, h: float) -> tuple[float, float, float, float, float]:
        u = self.h1 - h
        r, dr_du = self._r.value_and_slope(u)
        V, dV_du = self._V.value_and_slope(u)
        return r, -dr_du, V, -dV_du, self._l.value(u)

    def at_array(self, h: np.ndarray) -> tuple[np.ndarray, ...]:
        u = self.h1 - np.asarray(h, dtype=float)
        r, dr_du = self._r.values_and_slopes(u)
        V, dV_du = self._V.values_and_slopes(u)
        return r, -dr_du, V, -dV_du, self._l.values_and_slopes(u)[0]


def geometry_source(kind: str, cup: CupParameters, curve: StiffnessCurve):
    """'cone' (eqs 3-5) or 'curve' (the stiffness curve's r_c, V, l)."""
    if kind == "cone":
        return ConeGeometry(cup)
    if kind == "curve":
        return CurveGeometry(cup, curve)
    raise ValueError(f"geometry: unknown source '{kind}', allowed: cone, curve")
