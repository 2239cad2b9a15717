"""`reduced.roots.brentq` (Brent's method, so the force balance needs no scipy.optimize) against
known roots and against scipy.optimize.brentq, whose contract it keeps: the root within
xtol + rtol |x|, a bracket without a sign change refused, a root at an end returned as it is."""

from __future__ import annotations

import math

import pytest
from scipy.optimize import brentq as scipy_brentq

from reduced.roots import brentq

#: (f, a, b, the exact root)
CASES = [
    (lambda x: x * x - 2.0, 0.0, 2.0, math.sqrt(2.0)),
    (lambda x: math.cos(x) - x, 0.0, 1.0, 0.7390851332151607),
    (lambda x: math.exp(x) - 1e-8, -30.0, 5.0, math.log(1e-8)),
    (lambda x: math.atan(x - 0.3), -10.0, 100.0, 0.3),
    (lambda x: (x - 1.0) ** 3, 0.0, 3.0, 1.0),                     # a triple root: slow convergence
    (lambda x: math.tanh(50.0 * (x - 0.7)), 0.0, 1.0, 0.7),
    (lambda x: 1.0 if x > 0.123 else -1.0, 0.0, 1.0, 0.123),         # a jump: bisection only
    (lambda x: 1e-30 * (x - 0.5), 0.0, 1.0, 0.5),                   # tiny values
]


@pytest.mark.parametrize("xtol, rtol", [(2e-12, 8.881784197001252e-16), (1e-15, 1e-15), (1e-6, 1e-10)])
@pytest.mark.parametrize("case", range(len(CASES)))
def test_the_root_is_within_the_tolerance_as_scipys(case, xtol, rtol):
    f, a, b, root = CASES[case]
    x = brentq(f, a, b, xtol=xtol, rtol=rtol, maxiter=200)
    # the bracket's half-width at exit, plus the last float step of an exact root
    assert abs(x - root) <= xtol + rtol * abs(root) + 4 * math.ulp(root)
    y = scipy_brentq(f, a, b, xtol=xtol, rtol=rtol, maxiter=200)
    assert abs(x - y) <= 2 * (xtol + rtol * abs(root)) + 4 * math.ulp(root)


def test_the_ends_and_the_bad_brackets():
    assert brentq(lambda x: x - 1.0, 1.0, 2.0) == 1.0
    assert brentq(lambda x: x - 2.0, 1.0, 2.0) == 2.0
    with pytest.raises(ValueError, match="different signs"):
        brentq(lambda x: x * x + 1.0, -1.0, 1.0)
    with pytest.raises(RuntimeError, match="no convergence"):
        brentq(lambda x: (x - 1.0) ** 3, 0.0, 3.0, xtol=1e-15, rtol=1e-15, maxiter=5)


def test_the_force_balances_start_height_is_scipys():
    """On the model's own function (the holding force at the start content), the start height of
    cup A at 10 N agrees with scipy's to the requested tolerance."""
    from reduced.cup import CUP_A
    from reduced.critical_gap import illustrative_uc_table
    from reduced.force_balance import force_balance
    from reduced.model import reference_model

    core = force_balance(reference_model(CUP_A, illustrative_uc_table()), "cone", "strip")
    hs, N0, kappa0, Fmax, hm = core.initial
    f = lambda x: core.holding_force(x, N0, kappa0)[0] - 10.0       # noqa: E731
    xtol = 1e-15 * core.h1
    ours, theirs = brentq(f, hs, hm, xtol=xtol, rtol=1e-15), scipy_brentq(f, hs, hm, xtol=xtol, rtol=1e-15)
    assert abs(ours - theirs) <= 2 * (xtol + 1e-15 * abs(theirs))
