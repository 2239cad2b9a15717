"""A scalar root in a bracket by Brent's method (R. P. Brent, Algorithms for Minimization without
Derivatives, 1973, ch. 4: inverse quadratic interpolation and secant steps, safeguarded by
bisection), on Python floats.

The reduced model's force balance needs a handful of bracketed roots per lifetime; this keeps it
from importing scipy.optimize, whose import alone costs ~0.5 s of CPU, several times the paper
route's whole lifetime command. The contract is scipy.optimize.brentq's: f(a) and f(b) of opposite
signs (or one of them 0), the root returned within xtol + rtol |x| (tests/test_roots.py checks it
against scipy's on the model's own functions and on hard cases).
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["brentq"]


def brentq(f: Callable[[float], float], a: float, b: float, *, xtol: float = 2e-12,
           rtol: float = 8.881784197001252e-16, maxiter: int = 100) -> float:
    """A root of f in [a, b] to within xtol + rtol |x| (ValueError if f(a), f(b) have one sign;
    RuntimeError if `maxiter` steps do not converge)."""
    a, b = float(a), float(b)
    fa, fb = f(a), f(b)
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0.0) == (fb > 0.0):
        raise ValueError(f"f(a) and f(b) must have different signs, got f({a!r}) = {fa!r}, "
                         f"f({b!r}) = {fb!r}")
    c, fc = a, fa                       # the bracket's other end: f(b), f(c) of opposite signs
    d = e = b - a                       # the last step and the one before
    for _ in range(maxiter):
        if (fb > 0.0) == (fc > 0.0):
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):           # b: the best estimate so far
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        tol = 0.5 * (xtol + rtol * abs(b))
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) < tol or abs(fa) <= abs(fb):
            d = e = m                   # bisection
        else:
            s = fb / fa
            if a == c:                  # secant
                p, q = 2.0 * m * s, 1.0 - s
            else:                       # inverse quadratic interpolation
                q, r = fa / fc, fb / fc
                p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0))
                q = (q - 1.0) * (r - 1.0) * (s - 1.0)
            if p > 0.0:
                q = -q
            else:
                p = -p
            if 2.0 * p < min(3.0 * m * q - abs(tol * q), abs(e * q)):
                e, d = d, p / q         # the interpolation step is accepted
            else:
                d = e = m
        a, fa = b, fb
        b += d if abs(d) > tol else (tol if m > 0.0 else -tol)
        fb = f(b)
    raise RuntimeError(f"brentq: no convergence in {maxiter} steps (bracket [{b!r}, {c!r}])")
