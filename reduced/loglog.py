"""Piecewise power laws: tables interpolated linearly in log-log, and their two-column CSVs.

Shared by the critical-gap table u_c(p/E) and the relaxation modulus E_eff(t). Evaluation is on
Python floats (the reduced model's hot path); beyond either end the first or last segment's power
law continues.
"""

from __future__ import annotations

import math
import os
from bisect import bisect_right
from collections.abc import Callable
from pathlib import Path

import numpy as np


class LogLogSegments:
    """y(x) linear in (ln x, ln y) between samples, extrapolated with the end segments' slopes."""

    def __init__(self, x: np.ndarray, y: np.ndarray):
        self.lx = [math.log(v) for v in x]
        self.ly = [math.log(v) for v in y]

    def value_and_slope(self, x: float) -> tuple[float, float]:
        """(y(x), d ln y / d ln x) for x > 0."""
        lx, ly = self.lx, self.ly
        t = math.log(x)
        i = min(max(bisect_right(lx, t) - 1, 0), len(lx) - 2)
        slope = (ly[i + 1] - ly[i]) / (lx[i + 1] - lx[i])
        return math.exp(ly[i] + slope * (t - lx[i])), slope


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
    lines = [ln.strip() for ln in path.read_text().splitlines()]
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
