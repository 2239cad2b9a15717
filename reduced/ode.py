"""A small adaptive Runge-Kutta integrator on Python floats, with terminal events.

The reduced model's state has one or two components (N, or N and phi). scipy's `solve_ivp` spends
~100 us of array overhead per step on such a state; this Dormand-Prince 5(4) pair (the scheme of
`solve_ivp(method="RK45")`) works on lists of floats and costs a few microseconds per step beyond
the right-hand side. Step size follows the usual error-per-step control, so lifetimes from
milliseconds to 1e9 s need no tuning. Events are located on the 4th-order continuous extension of
each step (Shampine's dense output for this pair) by the Illinois variant of regula falsi.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

__all__ = ["IntegrationError", "OdeSolution", "dopri5"]

# Dormand-Prince 5(4) tableau
_C = (0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0)
_A = ((),
      (1 / 5,),
      (3 / 40, 9 / 40),
      (44 / 45, -56 / 15, 32 / 9),
      (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
      (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656))
_B = (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84)
# error weights b - b* (the 7th stage is f(t+h, y_new), FSAL)
_E = (71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40)
# 4th-order continuous extension (Shampine 1986): y(t + s h) = y + h sum_j k_j sum_m P[j][m] s^(m+1)
_P = ((1.0, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432),
      (0.0, 0.0, 0.0, 0.0),
      (0.0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799),
      (0.0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072),
      (0.0, 127303824393 / 49829197408, -318862633887 / 49829197408, 701980252875 / 199316789632),
      (0.0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844),
      (0.0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423))


class IntegrationError(RuntimeError):
    """The integrator could not proceed (step size underflow or too many steps)."""


@dataclass(frozen=True)
class OdeSolution:
    t: list            # accepted step times, t[0] = t0
    y: list            # states at t
    f: list            # derivatives at t
    event: int | None  # index of the terminal event that fired, None if t_end was reached
    steps: int
    rejected: int
    dense: list | None = None   # per step, y(t) on [t[i], t[i+1]] (with dense_output=True)


def dopri5(fun: Callable[[float, list], list], t0: float, y0: Sequence[float], t_end: float,
           rtol: float, atol: Sequence[float], events: Sequence[Callable[[float, list], float]] = (),
           h0: float | None = None, max_steps: int = 100_000, dense_output: bool = False) -> OdeSolution:
    """Integrate y' = fun(t, y) from t0 until t_end or until an event g(t, y) changes sign.

    An event fires when g goes from negative to >= 0 (write events so they start negative).
    The returned solution ends at the event time, with the state interpolated there.
    With dense_output, `dense[i]` is the 4th-order interpolant of step i.
    """
    n = len(y0)
    y = [float(v) for v in y0]
    t = float(t0)
    f = list(fun(t, y))
    ts, ys, fs = [t], [list(y)], [list(f)]
    dense_steps = [] if dense_output else None
    g_old = [g(t, y) for g in events]
    if h0 is None:
        # Hairer's first guess: 1 % of the time the first component needs to change by itself
        h0 = 0.01 * (abs(y[0]) + atol[0]) / max(abs(f[0]), 1e-300)
    h = min(max(h0, 1e-300), t_end - t)
    steps = rejected = 0
    just_rejected = False        # no growth right after a rejection (Hairer's facmax = 1)
    h_prev = err_prev = None     # last accepted step, for the predictive controller
    while t < t_end:
        if steps + rejected >= max_steps:
            raise IntegrationError(f"integrator: {max_steps} steps reached at t = {t:.6g} s "
                                   f"(state {y}); the problem may be ill-posed or the horizon too long")
        if h < 1e-14 * max(abs(t), 1e-300):
            raise IntegrationError(f"integrator: step size underflow at t = {t:.6g} s (h = {h:.3g} s, "
                                   f"state {y}); the right-hand side is singular there")
        h = min(h, t_end - t)
        y_new, f_new, k = _step(fun, t, y, f, h)
        err = 0.0
        for i in range(n):
            e = h * sum(_E[j] * k[j][i] for j in range(7))
            sc = atol[i] + rtol * max(abs(y[i]), abs(y_new[i]))
            err += (e / sc) ** 2
        err = math.sqrt(err / n)
        if not math.isfinite(err):
            rejected += 1
            h *= 0.25
            just_rejected = True
            continue
        if err > 1.0:
            rejected += 1
            h *= max(0.2, 0.9 * err ** -0.2)
            just_rejected = True
            continue
        steps += 1
        t_new = t + h
        g_new = [g(t_new, y_new) for g in events]
        fired = [i for i in range(len(events)) if g_old[i] < 0.0 <= g_new[i]]
        if fired:
            best = None
            dense = _dense(t, y, h, k)
            for i in fired:
                te, _ = _locate(events[i], dense, t, t_new, g_old[i], g_new[i])
                if best is None or te < best[1]:
                    best = (i, te)
            i, te = best
            # The step that straddles the event may have sampled the right-hand side beyond it
            # (where the model is only continued); so end with real steps from t that stop at the
            # event, refining the event time by the Illinois method on those steps.
            te, ye = _locate(events[i], lambda tau: _step(fun, t, y, f, tau - t)[0] if tau > t else y,
                             t, t_new, g_old[i], g_new[i], guess=te, iters=8)
            if dense_output:
                ye, fe, ke = _step(fun, t, y, f, te - t)
                dense_steps.append(_dense(t, y, te - t, ke))
            ts.append(te)
            ys.append(ye)
            fs.append(list(fun(te, ye)))
            return OdeSolution(ts, ys, fs, i, steps, rejected, dense_steps)
        if dense_output:
            dense_steps.append(_dense(t, y, h, k))
        t, y, f, g_old = t_new, y_new, f_new, g_new
        ts.append(t)
        ys.append(list(y))
        fs.append(list(f))
        # step control: the classical factor, made cautious by Gustafsson's predictive factor when
        # the error grows from step to step (solutions that steepen towards detachment)
        err = max(err, 1e-10)
        fac = 0.9 * err ** -0.2
        if err_prev is not None:
            fac = min(fac, fac * (h / h_prev) * (err_prev / err) ** 0.2)
        h_prev, err_prev = h, err
        h *= min(1.0 if just_rejected else 5.0, max(0.2, fac))
        just_rejected = False
    return OdeSolution(ts, ys, fs, None, steps, rejected, dense_steps)


def _step(fun, t: float, y: list, f: list, h: float):
    """One Dormand-Prince step: (y(t + h), f(t + h, y(t + h)), the seven stage slopes)."""
    n = len(y)
    k = [f]
    for s in range(1, 6):
        a = _A[s]
        ys_ = [y[i] + h * sum(a[j] * k[j][i] for j in range(s)) for i in range(n)]
        k.append(fun(t + _C[s] * h, ys_))
    y_new = [y[i] + h * sum(_B[j] * k[j][i] for j in range(6)) for i in range(n)]
    f_new = list(fun(t + h, y_new))
    k.append(f_new)
    return y_new, f_new, k


def _dense(t0: float, y0: list, h: float, k: list) -> Callable[[float], list]:
    """The step's 4th-order interpolant y(t), t in [t0, t0 + h]."""
    n = len(y0)
    q = [[sum(k[j][i] * _P[j][m] for j in range(7)) for m in range(4)] for i in range(n)]

    def y_at(t: float) -> list:
        s = (t - t0) / h
        return [y0[i] + h * s * (q[i][0] + s * (q[i][1] + s * (q[i][2] + s * q[i][3]))) for i in range(n)]

    return y_at


def _locate(g, dense, t0, t1, g0, g1, iters: int = 60, guess: float | None = None):
    """Event time in [t0, t1] (g0 < 0 <= g1) by the Illinois method on y(t) = dense(t)."""
    a, b, ga, gb = t0, t1, g0, g1
    side = 0
    tol = 1e-15 * max(abs(t1), 1e-300) + 1e-15 * (t1 - t0)
    gtol = 1e-12 * (g1 - g0)           # |g| this small puts the event within 1e-12 of the step
    for it in range(iters):
        if gb == ga:
            break
        c = b - gb * (b - a) / (gb - ga)
        if it == 0 and guess is not None:
            c = guess
        if not (a < c < b):
            c = 0.5 * (a + b)
        gc = g(c, dense(c))
        if abs(gc) <= gtol:
            return c, dense(c)
        if gc >= 0.0:
            b, gb = c, gc
            if side == 1:
                ga *= 0.5
            side = 1
        else:
            a, ga = c, gc
            if side == -1:
                gb *= 0.5
            side = -1
        if b - a <= tol:
            break
    return b, dense(b)
