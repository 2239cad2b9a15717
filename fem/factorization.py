"""The shifted factorization of the tangent: K_ff, or K_ff + s diag(K_ff) where it is not definite.

Where the tangent is not positive definite (buckling, a wall lifting off the plane) the Newton
direction would not descend in the energy. The diagonal is then shifted (Levenberg-Marquardt) by
a shift within a factor of ten of the smallest that makes it definite: near a bifurcation the
unstable eigenvalue is tiny, and a much larger shift damps that mode so much that the descent
creeps. The search remembers the last working shift across iterations (`ShiftPolicy`).
"""

from __future__ import annotations

import numpy as np

from .failure import StepFailure
from .linsolve import NotPositiveDefinite

__all__ = ["ShiftPolicy", "factor_shifted", "SHIFT_MIN"]

SHIFT_MIN = 1e-10       # smallest diagonal shift (relative); cond(K_ff + s D) stays < ~1e12


class ShiftPolicy:
    """The memory of the diagonal shift across the iterations of a path (`factor_shifted`): the
    shift that worked first in the last unstable episode, where the search of the next one
    starts; the count of factorizations (attempted, failed); and the last factor, reused when
    the same tangent is factored again with the same free set and shift (a step's convergence
    test factors the converged state's tangent, and the next step's first iteration starts there)."""

    def __init__(self) -> None:
        self.onset = 0.0
        self.factorizations = self.failed = 0
        self._last: tuple | None = None

    def factor(self, solver, K, free, shift):
        """solver.factor(K, free, shift), counted; the last factor if it is of the same (read-only)
        K, free set and shift."""
        last = self._last
        if last is not None and last[0] is solver and last[1] is K and last[3] == shift \
                and np.array_equal(last[2], free):
            return last[4]
        self.factorizations += 1
        try:
            fac = solver.factor(K, free, shift)
        except NotPositiveDefinite:
            self.failed += 1
            raise
        self._last = (solver, K, free.copy(), shift, fac) if _read_only(K) else None
        return fac


def _read_only(K) -> bool:
    """Whether K's entries cannot change in place (the tangents of `fem.forms.Mechanics.evaluate`)."""
    data = getattr(K, "data", None)
    return isinstance(data, np.ndarray) and not data.flags.writeable


def factor_shifted(solver, K, free, shift, history, policy=None, lower=True):
    """Factor K_ff, shifted if it is not positive definite (module docstring).

    The shift s that worked at the last iteration is tried tenfold smaller first (`lower`; below
    SHIFT_MIN: 0). If that fails, the search brackets the critical shift between the failed
    value and one that works (s itself, else the shift that opened the last unstable episode,
    else thousandfold steps up from SHIFT_MIN) and bisects the bracket in log-space down to a
    factor of ten: fewer factorizations than a tenfold ladder from SHIFT_MIN. Returns
    (factor, shift); raises `StepFailure` if even a shift of 1e3 leaves it indefinite."""
    policy = policy or ShiftPolicy()
    trial = shift
    if lower:
        trial = shift / 10.0 if shift >= 10.0 * SHIFT_MIN else 0.0
    try:
        return policy.factor(solver, K, free, trial), trial
    except NotPositiveDefinite:
        pass
    lo = max(trial, 0.1 * SHIFT_MIN)
    hi = next((c for c in (shift, policy.onset) if c > lo), max(1e3 * lo, SHIFT_MIN))
    while True:                              # bracket: lo fails, hi works
        try:
            fac = policy.factor(solver, K, free, hi)
            break
        except NotPositiveDefinite:
            lo, hi = hi, 1e3 * hi
            if hi > 1e3 * (1 + 1e-9):
                raise StepFailure("the tangent is not positive definite even with a diagonal shift "
                                  "of 1e3; likely cause: an unconstrained rigid-body mode", history) from None
    while hi > 10.0 * lo * (1 + 1e-9):       # bisect in log-space
        mid = float(np.sqrt(lo * hi))
        try:
            fac, hi = policy.factor(solver, K, free, mid), mid
        except NotPositiveDefinite:
            lo = mid
    if trial == 0.0:
        policy.onset = hi
    return fac, hi
