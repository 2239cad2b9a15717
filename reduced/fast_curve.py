"""Scalar evaluators for the reduced model's hot path: PCHIP on floats, no numpy per call.

`ScalarPchip` holds the piecewise-cubic coefficients of the monotone PCHIP interpolant (Fritsch &
Butland's weighted harmonic mean of the neighbouring secants inside, the one-sided three-point
formula at the ends, as scipy's `PchipInterpolator`; `pchip_coefficients`) and evaluates them
with `bisect` and Horner's rule on Python floats, about a microsecond per call; numpy arrays
likewise (`values_and_slopes`). Outside the sampled range it raises `CurveRangeError` (never
clamps). It is computed here, not by scipy.interpolate, whose import alone costs ~0.4 s of a
reduced-model command's start-up.
"""

from __future__ import annotations

from bisect import bisect_right

import numpy as np

__all__ = ["CurveRangeError", "ScalarPchip", "pchip_coefficients"]


class CurveRangeError(ValueError):
    """The state left the sampled range of an input curve."""


def _end_slope(h0: float, h1: float, m0: float, m1: float) -> float:
    """The one-sided three-point slope at an end, kept monotone (Fritsch & Carlson's rules)."""
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > abs(3.0 * m0):
        return 3.0 * m0
    return d


def pchip_coefficients(x, y) -> tuple[np.ndarray, np.ndarray]:
    """(x, c): the knots and the coefficients c[k, i] of (x - x_i)^(3-k) of the PCHIP interpolant
    through (x, y) (x strictly increasing, at least 2 points); c is laid out as scipy's PPoly."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if x.ndim != 1 or x.shape != y.shape or x.size < 2:
        raise ValueError(f"x, y: need two 1D arrays of equal length >= 2, got {x.shape}, {y.shape}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ValueError("x, y: must be finite")
    h = np.diff(x)
    if np.any(h <= 0.0):
        raise ValueError("x: must be strictly increasing")
    m = np.diff(y) / h                                       # the secants
    if x.size == 2:
        d = np.array([m[0], m[0]])
    else:
        d = np.empty_like(x)
        w1, w2 = 2.0 * h[1:] + h[:-1], h[1:] + 2.0 * h[:-1]
        same = (np.sign(m[1:]) == np.sign(m[:-1])) & (m[1:] != 0.0) & (m[:-1] != 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            harmonic = (w1 / m[:-1] + w2 / m[1:]) / (w1 + w2)
            d[1:-1] = np.where(same, 1.0 / harmonic, 0.0)
        d[0] = _end_slope(h[0], h[1], m[0], m[1])
        d[-1] = _end_slope(h[-1], h[-2], m[-1], m[-2])
    t = (d[:-1] + d[1:] - 2.0 * m) / h
    c = np.empty((4, x.size - 1))
    c[0] = t / h
    c[1] = (m - d[:-1]) / h - t
    c[2] = d[:-1]
    c[3] = y[:-1]
    return x, c


class ScalarPchip:
    """value_and_slope(x) of the PCHIP interpolant through (x, y), on Python floats."""

    __slots__ = ("x", "c0", "c1", "c2", "c3", "lo", "hi", "name", "unit_scale", "unit", "_knots", "_c")

    def __init__(self, x, y, name: str = "curve", unit_scale: float = 1e3, unit: str = "mm"):
        knots, c = pchip_coefficients(x, y)
        self._knots, self._c = knots, c
        self.x = [float(v) for v in knots]
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
        i = np.clip(np.searchsorted(self._knots, x, side="right") - 1, 0, len(self.x) - 2)
        d = x - self._knots[i]
        c3, c2, c1, c0 = self._c[:, i]
        d2 = d * d
        # the power form summed from the constant term up, as scipy's PPoly evaluates it: the
        # arrays agree with PchipInterpolator to the last bit (tests/test_fast_curve.py)
        return c0 + c1 * d + c2 * d2 + c3 * (d2 * d), c1 + (c2 * d) * 2.0 + (c3 * d2) * 3.0

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
