"""Log-log interpolated tables and their two-column CSVs.

Shared by the critical-gap table u_c(p/E) and the relaxation modulus E_eff(t). ln y is interpolated
over ln x by the monotone piecewise cubic (PCHIP), so y(x) is C1 and exact for a power law; beyond
either end the power law with the end's log-log slope continues. C1 matters: the tabulated
functions are smooth, and a piecewise power law (C0 in log-log) puts a kink at every row, which
fools the lifetime integrator's error estimate (measured: lifetime errors ~100 rtol at the default
rtol, against ~rtol with this interpolant). Evaluation is on Python floats (the reduced model's hot
path).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from reduced.fast_curve import ScalarPchip


class LogLogPchip:
    """y(x) with ln y a PCHIP in ln x between samples, power laws beyond the ends."""

    def __init__(self, x: np.ndarray, y: np.ndarray):
        lx, ly = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
        self.n = len(lx)
        self.cubic = ScalarPchip(lx, ly, "log-log table")
        self._lo = (float(lx[0]), float(ly[0]), float(self.cubic.values_and_slopes(lx[:1])[1][0]))
        self._hi = (float(lx[-1]), float(ly[-1]), float(self.cubic.values_and_slopes(lx[-1:])[1][0]))

    def value_and_slope(self, x: float) -> tuple[float, float]:
        """(y(x), d ln y / d ln x) for x > 0."""
        t = math.log(x)
        if self._lo[0] <= t <= self._hi[0]:
            ly, slope = self.cubic.value_and_slope(t)
            return math.exp(ly), slope
        t_end, ly_end, slope = self._lo if t < self._lo[0] else self._hi
        return math.exp(ly_end + slope * (t - t_end)), slope


def elementwise(scalar: Callable[[float], float], x):
    """`scalar` on a float, or element by element on an array (same shape)."""
    if np.ndim(x) == 0:
        return scalar(float(x))
    return np.array([scalar(float(v)) for v in np.ravel(x)]).reshape(np.shape(x))


def read_two_columns(path: str | os.PathLike, header: str, what: str) -> tuple[np.ndarray, np.ndarray, str]:
    """The columns of a CSV that starts with `header` (after '#' comment lines), and the comments.

    Errors name `what` (the option or field) and the file.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{what}: no such file '{path}'")
    try:
        lines = [ln.strip() for ln in path.read_text(encoding="utf-8").splitlines()]
    except UnicodeDecodeError:
        raise ValueError(f"{what}: '{path}' is not a UTF-8 text file") from None
    body = [ln for ln in lines if ln and not ln.startswith("#")]
    if not body or [c.strip() for c in body[0].split(",")] != header.split(","):
        raise ValueError(f"{what}: '{path}' must start with the header '{header}'")
    try:
        data = np.array([[float(v) for v in ln.split(",")] for ln in body[1:]], dtype=float)
    except ValueError as exc:
        raise ValueError(f"{what}: '{path}' has a non-numeric entry ({exc})") from None
    if data.ndim != 2 or data.shape[1] != 2:
        raise ValueError(f"{what}: '{path}' needs two columns per row, {header}")
    comments = " ".join(ln[1:].strip() for ln in lines if ln.startswith("#"))
    return data[:, 0], data[:, 1], comments
