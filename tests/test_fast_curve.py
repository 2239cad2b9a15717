"""`reduced.fast_curve` computes the PCHIP interpolant itself (so a reduced-model command need not
import scipy.interpolate): its coefficients and its array evaluation are scipy's
`PchipInterpolator`, bit for bit (a second implementation of the same published algorithm, Fritsch
& Butland's monotone slopes), and the scalar Horner path agrees with both to round-off. Its
not-a-knot cubic spline (the profile route's flow tables) is scipy's `CubicSpline`, bit for bit,
also where the tridiagonal solve interchanges rows, and reproduces a cubic exactly."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline, PchipInterpolator

from reduced.fast_curve import (CurveRangeError, ScalarPchip, _tridiagonal_solve, pchip_coefficients,
                                 spline_coefficients)
from reduced.seal import PbTable


def _cases(seed: int = 3, count: int = 120):
    """Knots and values: monotone, oscillating, with flat runs and with 2-3 points only."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        n = int(rng.integers(2, 40)) if k % 10 else int(rng.integers(2, 4))
        x = np.cumsum(rng.uniform(1e-3, 2.0, n)) * 10.0 ** rng.integers(-6, 3)
        y = np.cumsum(rng.uniform(0.0, 1.0, n)) if k % 3 == 0 else rng.normal(size=n)
        if k % 5 == 0 and n > 5:
            y[2:5] = y[2]                              # a flat run: slopes 0 there
        yield x, y


def test_the_coefficients_are_scipys_bit_for_bit():
    for x, y in _cases():
        knots, c = pchip_coefficients(x, y)
        pp = PchipInterpolator(x, y, extrapolate=False)
        assert np.array_equal(knots, pp.x) and np.array_equal(c, pp.c), (x, y)


def test_the_array_evaluation_is_scipys_bit_for_bit_and_the_scalar_one_agrees():
    rng = np.random.default_rng(4)
    for x, y in _cases(5, 60):
        pp, fast = PchipInterpolator(x, y, extrapolate=False), ScalarPchip(x, y)
        at = np.concatenate([x, rng.uniform(x[0], x[-1], 50)])
        values, slopes = fast.values_and_slopes(at)
        assert np.array_equal(values, pp(at)) and np.array_equal(slopes, pp(at, 1))
        scalar = np.array([fast.value_and_slope(float(v)) for v in at])
        scale = np.max(np.abs(y)) + 1e-300
        assert np.allclose(scalar[:, 0], values, rtol=1e-12, atol=1e-12 * scale)
        dscale = np.max(np.abs(slopes)) + 1e-300
        assert np.allclose(scalar[:, 1], slopes, rtol=1e-12, atol=1e-12 * dscale)


def test_a_monotone_sample_stays_monotone_and_outside_is_refused():
    x = np.array([0.0, 1.0, 1.5, 4.0, 4.2])
    y = np.array([0.0, 0.1, 3.0, 3.1, 9.0])
    fast = ScalarPchip(x, y)
    values, slopes = fast.values_and_slopes(np.linspace(0.0, 4.2, 500))
    assert np.all(np.diff(values) >= 0) and np.all(slopes >= 0)
    with pytest.raises(CurveRangeError, match="outside the curve's sampled range"):
        fast.value(4.3)


@pytest.mark.parametrize("x, y, field", [([0.0, 1.0], [1.0], "x, y"), ([1.0, 0.0], [0.0, 1.0], "x"),
                                         ([0.0, 1.0], [0.0, np.nan], "x, y")])
def test_bad_knots_are_refused_naming_the_field(x, y, field):
    with pytest.raises(ValueError, match=f"^{field}:"):
        pchip_coefficients(x, y)


def test_the_uc_tables_array_path_is_scipys_pchip_in_log_log_bit_for_bit():
    """`UcTable.values` runs on the same coefficients: inside the table scipy's PchipInterpolator of
    ln u_c over ln p/E, beyond it the power laws with scipy's end slopes, to the last bit."""
    from reduced.critical_gap import UcTable

    p = np.geomspace(1e-5, 0.2, 30)
    u = 1e-6 * (p / 0.025) ** -0.8 * (1.0 + 0.3 * np.sin(7.0 * np.log(p)))
    table = UcTable(p, u)
    lx, ly = np.log(p), np.log(u)
    cubic = PchipInterpolator(lx, ly, extrapolate=False)
    s0, s1 = cubic([lx[0], lx[-1]], 1)
    x = np.geomspace(1e-8, 2.0, 2001)
    t = np.log(x)
    expected = np.exp(np.where(t < lx[0], ly[0] + s0 * (t - lx[0]),
                               np.where(t > lx[-1], ly[-1] + s1 * (t - lx[-1]),
                                        cubic(np.clip(t, lx[0], lx[-1])))))
    assert np.array_equal(table.values(x), expected)


def _spline_cases(seed: int = 6, count: int = 200):
    """Knots from even to wildly uneven (neighbouring spacings up to ~1e4 apart: there the
    elimination interchanges rows), values smooth or random, 4 to 400 points."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        n = int(rng.integers(4, 400)) if k % 4 else int(rng.integers(4, 7))
        x = np.cumsum(rng.lognormal(sigma=3.0 * (k % 3) / 2, size=n)) * 10.0 ** rng.uniform(-6, 3)
        y = np.sin(x / x[-1] * 7.0) if k % 2 else rng.normal(size=n) * 10.0 ** rng.uniform(-5, 5)
        yield x, y


def test_the_spline_is_scipys_cubic_spline_bit_for_bit():
    for x, y in [*_spline_cases(), (PbTable.TAU, np.log1p(np.exp(PbTable.TAU)) - 0.3 * PbTable.TAU ** 2)]:
        knots, c = spline_coefficients(x, y)
        spline = CubicSpline(x, y)
        assert np.array_equal(knots, spline.x) and np.array_equal(c, spline.c), (x, y)


def test_the_cases_include_row_interchanges():
    """The test above can fail on the pivoting branch: some of its systems take it (|d_i| < |dl_i|)."""
    pivoted = 0
    for x, _ in _spline_cases():
        h = np.diff(x)
        d = [float(h[1])] + list(2 * (h[:-1] + h[1:])) + [float(h[-2])]
        dl = list(h[1:]) + [float(x[-1] - x[-3])]
        du = [float(x[2] - x[0])] + list(h[:-1])
        seen = []
        _tridiagonal_solve(_Watch(dl, seen, d), d, du, [1.0] * len(d))
        pivoted += any(seen)
    assert pivoted >= 10


class _Watch(list):
    """dl that records, at each elimination step i, whether |d_i| < |dl_i| (a row interchange)."""

    def __init__(self, dl, seen, d):
        super().__init__(dl)
        self.seen, self.d, self.at = seen, d, set()

    def __getitem__(self, i):
        if i not in self.at:
            self.at.add(i)
            self.seen.append(abs(self.d[i]) < abs(super().__getitem__(i)))
        return super().__getitem__(i)


def test_the_spline_reproduces_a_cubic():
    """Not-a-knot ends: a cubic polynomial is its own spline, on any knots (an exact property)."""
    rng = np.random.default_rng(8)
    x = np.cumsum(rng.uniform(0.01, 1.0, 30))
    poly = np.array([0.3, -1.2, 2.0, 0.7])
    knots, c = spline_coefficients(x, np.polyval(poly, x))
    at = rng.uniform(x[0], x[-1], 200)
    i = np.clip(np.searchsorted(knots, at, side="right") - 1, 0, knots.size - 2)
    d = at - knots[i]
    values = ((c[0, i] * d + c[1, i]) * d + c[2, i]) * d + c[3, i]
    assert np.allclose(values, np.polyval(poly, at), rtol=1e-12, atol=1e-12)
    assert np.allclose(c[0], poly[0], rtol=1e-9)         # one cubic throughout: the same leading coefficient


def test_a_spline_needs_four_knots():
    with pytest.raises(ValueError, match=">= 4"):
        spline_coefficients([0.0, 1.0, 2.0], [0.0, 1.0, 0.0])
