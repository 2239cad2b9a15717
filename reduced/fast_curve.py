"""Scalar evaluators for the reduced model's hot path: PCHIP on floats, no numpy per call.

`StiffnessCurve` interpolates with scipy's `PchipInterpolator`, which costs tens of microseconds
per scalar call. `ScalarPchip` takes that interpolant's piecewise-cubic coefficients once and
evaluates them with `bisect` and Horner's rule on Python floats: the same interpolant, about a
microsecond per call. Outside the sampled range it raises `CurveRangeError` (never clamps).
"""

from __future__ import annotations

from bisect import bisect_right

import numpy as np
from scipy.interpolate import PchipInterpolator

__all__ = ["CurveRangeError", "ScalarPchip"]


class CurveRangeError(ValueError):
    """The state left the sampled range of an input curve."""


class ScalarPchip:
    """value_and_slope(x) of the PCHIP interpolant through (x, y), on Python floats."""

    __slots__ = ("x", "c0", "c1", "c2", "c3", "lo", "hi", "name", "unit_scale", "unit", "pp")

    def __init__(self, x, y, name: str = "curve", unit_scale: float = 1e3, unit: str = "mm"):
        pp = PchipInterpolator(np.asarray(x, float), np.asarray(y, float), extrapolate=False)
        self.pp = pp
        self.x = [float(v) for v in pp.x]
        c = np.asarray(pp.c, float)
        self.c3, self.c2, self.c1, self.c0 = ([float(v) for v in row] for row in c)
        self.lo, self.hi = self.x[0], self.x[-1]
        self.name, self.unit_scale, self.unit = name, unit_scale, unit

    def value_and_slope(self, x: float) -> tuple[float, float]:
        i = self._index(x)
        d = x - self.x[i]
        c1, c2, c3 = self.c1[i], self.c2[i], self.c3[i]
        return self.c0[i] + d * (c1 + d * (c2 + d * c3)), c1 + d * (2.0 * c2 + 3.0 * d * c3)

    def values_and_slopes(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Vectorised value_and_slope (numpy arrays), same range check."""
        x = np.asarray(x, dtype=float)
        if x.size and not (x.min() >= self.lo - 1e-12 * (self.hi - self.lo)
                           and x.max() <= self.hi + 1e-12 * (self.hi - self.lo)):
            bad = x[(x < self.lo) | (x > self.hi)][0]
            self._index(float(bad))          # raises with the message
        x = np.clip(x, self.lo, self.hi)
        return self.pp(x), self.pp(x, 1)

    def value(self, x: float) -> float:
        i = self._index(x)
        d = x - self.x[i]
        return self.c0[i] + d * (self.c1[i] + d * (self.c2[i] + d * self.c3[i]))

    def _index(self, x: float) -> int:
        if not (self.lo <= x <= self.hi):
            tol = 1e-12 * (self.hi - self.lo)
            if self.lo - tol <= x <= self.hi + tol:
                return 0 if x < self.lo + tol else len(self.x) - 2
            s = self.unit_scale
            raise CurveRangeError(
                f"{self.name}: the state reached {s * x:.6g} {self.unit}, outside the curve's sampled "
                f"range [{s * self.lo:.6g}, {s * self.hi:.6g}] {self.unit}; extend the curve")
        i = bisect_right(self.x, x) - 1
        return i if i < len(self.x) - 1 else i - 1
