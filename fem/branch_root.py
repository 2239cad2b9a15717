"""The root of F1(u, N) = F1 along one unknown of the held branch (`fem.branch_walk`): N at a
given plate position, or the plate position at a given N, every trial a state reached from the
branch's last state (its history). Newton on the exact dF1/dx (`fem.branch_slopes`), the secant
where a step does not reduce the mismatch tenfold, Illinois regula falsi on the closest bracket
the trials found, and the jump of the pull across F1 where that bracket closes without a root.

Coulomb's corrections start their Newton iteration from the last trial (`Walk._corrects`). Where
the step from the branch state has two solutions (the seal's inner nodes held or let go at the
same N), a started trial can follow the other one: a started trial and another that contradict
an F1 monotone in the unknown send the root back to the branch state, every trial from there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .solver import StepResult

__all__ = ["Jump", "PullRoot", "Trial"]


@dataclass(frozen=True, eq=False)
class Trial:
    """A converged sealed state before its measurement: plate position, N, pull, solver state."""

    u_m: float
    N: float
    F1_N: float
    step: StepResult
    crossed: "Trial | None" = None   # the state after the first instability its path crossed
    predicted: bool = False          # started from another trial (`Walk._corrects`)


class _Contradiction(Exception):
    """Two trials of an F1 root, one started from another trial, contradict a monotone F1(x)."""


def _x(s: Trial, k: int) -> float:
    """The unknown of an F1 root (`Walk._root`): N (k = 0) or the plate position (k = 1)."""
    return s.N if k == 0 else s.u_m


class Jump(RuntimeError):
    """The pull jumps across F1 between two states close together in N or u (module docstring)."""

    def __init__(self, before: "Trial", after: "Trial", message: str, instability: bool = False):
        super().__init__(message)
        self.before, self.after, self.instability = before, after, instability


class PullRoot:
    """The F1 root of `fem.branch_walk.Walk` (a mixin: it uses the walk's `solve`,
    `derivatives`, `trial_options`, `F1`, `tolerance` and its switches `stop_at_crossing`,
    `predict_from`, `predicting`)."""

    def hold(self, prev: Trial, u_m: float, N_guess: float) -> Trial:
        """The state at plate position u_m whose pull is F1 (N by Newton on F1(N), module
        docstring), reached from prev. Raises `Jump` where F1(N) jumps across F1."""
        return self._root(prev, u_m, N_guess, 0)

    def hold_u(self, prev: Trial, u_guess: float, N: float) -> Trial:
        """The state at N whose pull is F1 (the plate position by Newton on F1(u)), reached
        from prev. Raises `Jump` where F1(u) jumps across F1."""
        return self._root(prev, u_guess, N, 1)

    def _root(self, prev: Trial, u_m: float, N: float, k: int) -> Trial:
        """F1(x) = F1 for x = N at the plate u_m (k = 0) or x = u at N (k = 1), every trial
        reached from prev: Newton with the exact dF1/dx, the secant where it does not halve the
        mismatch; where that fails, regula falsi on the bracket its trials found (`_bracket`).
        Coulomb's corrections start from the last trial (`Walk._corrects`); where a trial so started
        and another contradict an F1 monotone in x (the sign of dF1/dx at the first trial), or the root
        fails, the step from prev has more than one solution and the started trial may have found
        another than prev's: the root is found again with every trial started at prev."""
        trials: list[Trial] = []
        try:
            return self._root_from(prev, u_m, N, k, trials)
        except (RuntimeError, _Contradiction):
            if not any(t.predicted for t in trials):
                raise
        was, self.predicting = self.predicting, False
        try:
            return self._root_from(prev, u_m, N, k, [])
        finally:
            self.predicting = was

    def _root_from(self, prev: Trial, u_m: float, N: float, k: int, trials: list[Trial]) -> Trial:
        """`_root`'s search; every trial is appended to `trials`."""
        name = "N" if k == 0 else "the plate position"

        def at(x, base=prev):
            self.stop_at_crossing, self.predict_from = True, base
            try:
                s = self.solve(prev, u_m, x, self.trial_options) if k == 0 else \
                    self.solve(prev, x, N, self.trial_options)
            finally:
                self.stop_at_crossing, self.predict_from = False, None
            trials.append(s)
            if s.crossed is not None:       # the cup meets an instability on the way: it jumps
                raise Jump(prev, s.crossed, f"F1_N = {self.F1:g} N: an instability (a slip) "
                            f"crossed on the way to {name} {x:.6g}", instability=True)
            if s.predicted:     # dF1/dx of the first trial (from prev, known: it was corrected)
                sign = np.sign(self.derivatives(trials[0])[k])
                if any(sign * (_x(s, k) - _x(t, k)) * (s.F1_N - t.F1_N) < 0.0 for t in trials[:-1]):
                    raise _Contradiction()
            return s
        x0, x_prev = (N, prev.N) if k == 0 else (u_m, prev.u_m)
        s = at(x0)
        tried: list[tuple[float, float, Trial]] = [(x0, s.F1_N - self.F1, s)]
        for _ in range(12):
            miss = s.F1_N - self.F1
            if abs(miss) <= self.tolerance:
                return s
            x_new = tried[-1][0] - miss / self.derivatives(s)[k]
            if len(tried) >= 2 and abs(miss) > 0.1 * abs(tried[-2][1]):   # slow: secant
                (xa, fa, _), (xb, fb, _) = tried[-2:]
                if fb != fa:
                    x_new = xb - fb * (xb - xa) / (fb - fa)
            if k == 0 and not x_new > 0.0:
                break
            s = at(x_new, s)
            tried.append((x_new, s.F1_N - self.F1, s))
        return self._bracket(at, tried, x0 - x_prev, name)

    def _bracket(self, at, tried, travel: float, name: str) -> Trial:
        """The root of F1(x) = F1 on the closest bracket among the trials (Illinois regula
        falsi, every third trial a bisection). Where the bracket closes to 1e-3 of the trial's
        move from the previous state without a root, F1 jumps across F1 there (a slip of the
        sticking law, a snap): `Jump` with the states on both sides. RuntimeError where the
        trials found no bracket."""
        pos = [t for t in tried if t[1] > 0.0]
        neg = [t for t in tried if t[1] < 0.0]
        x, f, s = tried[-1]
        if not (pos and neg):
            raise RuntimeError(f"F1_N = {self.F1:g} N: {name} not found at {x:.6g} (pull off by "
                               f"{f:.3g} N after {len(tried) - 1} corrections)")
        a, b = min(((p, n) for p in pos for n in neg), key=lambda pn: abs(pn[0][0] - pn[1][0]))
        xtol = 1e-3 * abs(travel) + 1e-12 * abs(x)
        side = 0
        for i in range(60):
            (xa, fa, sa), (xb, fb, sb) = a, b
            if abs(xa - xb) <= xtol:
                before, after = (a, b) if (xb - xa) * travel > 0.0 else (b, a)
                raise Jump(before[2], after[2], f"F1_N = {self.F1:g} N: the pull jumps from "
                            f"{before[2].F1_N:.4g} to {after[2].F1_N:.4g} N at {name} {xa:.6g}")
            x = 0.5 * (xa + xb) if i % 3 == 2 else xb - fb * (xb - xa) / (fb - fa)
            s = at(x)
            f = s.F1_N - self.F1
            if abs(f) <= self.tolerance:
                return s
            if f > 0.0:
                a = (x, f, s)
                b = (xb, 0.5 * fb if side == 1 else fb, sb)
                side = 1
            else:
                b = (x, f, s)
                a = (xa, 0.5 * fa if side == -1 else fa, sa)
                side = -1
        raise RuntimeError(f"F1_N = {self.F1:g} N: {name} not found at {x:.6g} (bracket not closed)")
