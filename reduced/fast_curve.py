"""Scalar evaluators for the reduced model's hot path: PCHIP on floats, no numpy per call.

`ScalarPchip` holds the piecewise-cubic coefficients of the monotone PCHIP interpolant (Fritsch &
Butland's weighted harmonic mean of the neighbouring secants inside, the one-sided three-point
formula at the ends, as scipy's `PchipInterpolator`; `pchip_coefficients`) and evaluates them
with `bisect` and Horner's rule on Python floats, about a microsecond per call; numpy arrays
likewise (`values_and_slopes`). Outside the sampled range it raises `CurveRangeError` (never
clamps). It is computed here, not by scipy.interpolate, whose import alone costs ~0.4 s of a
reduced-model command's start-up. So is `spline_coefficients`, the not-a-knot cubic spline of
scipy's `CubicSpline` (its tridiagonal system solved in the order of LAPACK's dgtsv, which
CubicSpline calls, and its coefficients formed as scipy forms them: bit for bit scipy's).
"""

from __future__ import annotations

from bisect import bisect_right

import numpy as np

__all__ = ["CurveRangeError", "ScalarPchip", "pchip_coefficients", "spline_coefficients"]


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
    x, y, h = _knots(x, y, 2)
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
    return x, _hermite(x, y, h, m, d)


def spline_coefficients(x, y) -> tuple[np.ndarray, np.ndarray]:
    """(x, c) of the cubic spline through (x, y) with not-a-knot ends (x strictly increasing, at
    least 4 points), laid out as `pchip_coefficients`: C2 at the knots, its third derivative also
    continuous at the second and the last but one (scipy's `CubicSpline(x, y)`, bit for bit)."""
    x, y, h = _knots(x, y, 4)
    m = np.diff(y) / h
    n = x.size
    # the slopes d at the knots: continuity of the second derivative inside, not-a-knot at the ends
    lower, diag, upper = np.zeros(n), np.zeros(n), np.zeros(n)
    diag[1:-1] = 2 * (h[:-1] + h[1:])
    upper[1:-1] = h[:-1]
    lower[:-2] = h[1:]
    rhs = np.empty(n)
    rhs[1:-1] = 3 * (h[1:] * m[:-1] + h[:-1] * m[1:])
    diag[0], upper[0] = h[1], x[2] - x[0]
    w = x[2] - x[0]
    rhs[0] = ((h[0] + 2 * w) * h[1] * m[0] + h[0] ** 2 * m[1]) / w
    diag[-1], lower[-2] = h[-2], x[-1] - x[-3]
    w = x[-1] - x[-3]
    rhs[-1] = (h[-1] ** 2 * m[-2] + (2 * w + h[-1]) * h[-2] * m[-1]) / w
    d = np.array(_tridiagonal_solve(lower[:-1].tolist(), diag.tolist(), upper[:-1].tolist(), rhs.tolist()))
    return x, _hermite(x, y, h, m, d)


def _tridiagonal_solve(dl: list[float], d: list[float], du: list[float], b: list[float]) -> list[float]:
    """The solution of the tridiagonal system with sub-, main and super-diagonal dl, d, du (lists,
    overwritten) and right-hand side b, by Gaussian elimination with partial pivoting, operation
    for operation LAPACK's dgtsv with one right-hand side, on Python floats: the result is the one
    scipy's solve_banded returns. dl[i] holds the second super-diagonal's fill-in after a row
    interchange, as in dgtsv."""
    n = len(d)
    for i in range(n - 1):
        if abs(d[i]) >= abs(dl[i]):           # no row interchange
            if d[i] == 0.0:
                raise ValueError("spline: singular system")
            fact = dl[i] / d[i]
            d[i + 1] = d[i + 1] - fact * du[i]
            b[i + 1] = b[i + 1] - fact * b[i]
            dl[i] = 0.0
        else:                                  # interchange rows i and i + 1
            fact = d[i] / dl[i]
            d[i] = dl[i]
            temp = d[i + 1]
            d[i + 1] = du[i] - fact * temp
            if i < n - 2:
                dl[i] = du[i + 1]
                du[i + 1] = -fact * dl[i]
            du[i] = temp
            temp = b[i]
            b[i] = b[i + 1]
            b[i + 1] = temp - fact * b[i + 1]
    if d[n - 1] == 0.0:
        raise ValueError("spline: singular system")
    b[n - 1] = b[n - 1] / d[n - 1]
    b[n - 2] = (b[n - 2] - du[n - 2] * b[n - 1]) / d[n - 2]
    for i in range(n - 3, -1, -1):
        b[i] = (b[i] - du[i] * b[i + 1] - dl[i] * b[i + 2]) / d[i]
    return b


def _knots(x, y, least: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x, y as float arrays and the knot spacing h, checked: 1D, equal length >= least, finite,
    x strictly increasing."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if x.ndim != 1 or x.shape != y.shape or x.size < least:
        raise ValueError(f"x, y: need two 1D arrays of equal length >= {least}, got {x.shape}, {y.shape}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ValueError("x, y: must be finite")
    h = np.diff(x)
    if np.any(h <= 0.0):
        raise ValueError("x: must be strictly increasing")
    return x, y, h


def _hermite(x: np.ndarray, y: np.ndarray, h: np.ndarray, m: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The coefficients c[k, i] of the cubic Hermite interpolant with slopes d at the knots
    (secants m), formed as scipy's CubicHermiteSpline forms them."""
    t = (d[:-1] + d[1:] - 2.0 * m) / h
    c = np.empty((4, x.size - 1))
    c[0] = t / h
    c[1] = (m - d[:-1]) / h - t
    c[2] = d[:-1]
    c[3] = y[:-1]
    return c


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
