"""The paper and profile routes' integrator (private to them, `reduced.lifetime.routes`): the
leakage dynamics of Sec. 3 (eqs 3-10), flow of Sec. 4.

State and equations. The gas content N of the cavity and (with relaxation) the contact-time state
phi evolve in time; the cup height h is algebraic, fixed by the force balance

    G(h, N, phi) = kappa(phi) F0(h) + F1 - pi r(h)^2 (p_a - N kT / V(h)) = 0        (7), (8)

with kappa = E_eff(phi) / E_eff(phi0) (Sec. 3), kappa = 1 in reference mode. Then

    dN/dt   = (2 pi r / l) f(p, p_a, p_b),  p = kappa F0 / (2 pi r l) + beta (p_a - p_b)   (9), (23), (6)
    dphi/dt = 1 - rdot phi / l,   rdot = r'(h) hdot                                       (10)

and hdot follows from differentiating G = 0 (implicit function theorem); phi_dot contains rdot, so
(hdot, phi_dot) solve a 2x2 linear system, singular where D = G_h - (r' phi / l) G_phi = 0.

Equilibrium branch and start: `reduced.force_balance` (h is found from N on the stable branch
of eq (7) at every evaluation, so the force balance holds at every output to round-off; the
trapped gas N0 is fixed at r_start with F1 = 0; the largest holdable force is the first maximum
of the holding force).

End (reason): "reached_r1", "fold" (static fold, or with relaxation the dynamic singularity D -> 0
where rdot diverges), "over_force" (t = 0), "sealed" (u_c = 0 somewhere on the way: the leak rate
vanishes, the lifetime is infinite) or "horizon" (still holding at t_max).

With relaxation, phi(0) = 0 and E_eff is held at its first sample for shorter times, so the spring
starts at kappa0 = E_eff(phi=0)/E_eff(phi0) (1.25 for cup A with the default law); N0 is fixed with it.

Liquid (fluid='water'): the cavity is full of an incompressible liquid; its volume V(h) is the
content, p_b follows from eq (7), the inflow is eq (24). F1 leaves h at h_start (p_b drops by
F1 / (pi r^2), possibly below zero: tension, the paper's metastable liquid, Sec. 6) and the cup
detaches at r1. With a cavitation pressure p_cav (e.g. water's vapour pressure, 2.34 kPa at 20 C)
the liquid cannot go below it: if F1 would pull p_b below p_cav, a vapour bubble at p_cav opens at
t = 0 and the cup rises at once to h_c, the lowest height where the force balance holds with
p_b = p_cav, pi r^2 (p_a - p_cav) = F0 + F1; the liquid flows in at h_c (eq 24 with p_b = p_cav)
until the bubble has refilled, then the cup follows the liquid branch from h_c. The largest
holdable force is then the largest pi r^2 (p_a - p_cav) - F0 on the way to r1.

Reference mode (`reference_model`): Appendix A stiffness (x0 = r0, x1 = r1, d0 = 2 mm, d1 = 0,
E = 4 MPa), no relaxation (kappa = 1, E = 4 MPa for p/E), air at 293.15 K (eta = 1.81e-5 Pa s,
m = 28.97 u), p_a = 1e5 Pa, lambda_a from eq (12) at p_a, u_c from the given table, rigid-cone
geometry eqs (3)-(5), start and detachment as above. There the state is one-dimensional and
`reduced.lifetime.quadrature` gives the lifetime independently as t = int dN_eq/dh / Ndot dh.
"""

from __future__ import annotations

import math
from collections.abc import Callable
import numpy as np

from reduced.fast_curve import CurveRangeError
from reduced.force_balance import ForceBalance
from reduced.lifetime.result import _PaperRecord
from reduced.ode import dopri5
from reduced.roots import brentq

__all__ = ["integrate", "start_height", "sealed_on_branch", "check_run"]
_DYNAMIC_FOLD = 1e-4  # |D| / |D(0)| at which the relaxed dynamics is declared singular


def check_run(force_N: float, t_max_s: float, rtol: float, refine: int) -> float:
    """F1 [N] after checking the run's inputs (ValueError naming the field)."""
    F1 = float(force_N)
    if not (math.isfinite(F1) and F1 > 0):
        # F1 = 0 ends only asymptotically at r1, where the contact pressure p -> 0
        raise ValueError(f"force_N: pull force must be > 0 N, got {force_N}")
    if not (t_max_s > 0 and 0 < rtol < 1e-2):
        raise ValueError(f"t_max_s, rtol: need t_max_s > 0 and 0 < rtol < 0.01, got {t_max_s}, {rtol}")
    if not (isinstance(refine, int) and 1 <= refine <= 1000):
        raise ValueError(f"refine: output points per step must be an integer in [1, 1000], got {refine}")
    return F1


def start_height(core: ForceBalance, F1: float) -> float:
    """h at t = 0 under F1 < the largest holdable force: F1 applied at the start content N0."""
    hs, N0, kappa0, Fmax, hm = core.initial
    return core.liquid_start(F1) if core.liquid else brentq(
        lambda x: core.holding_force(x, N0, kappa0)[0] - F1, hs, hm, xtol=1e-15 * core.h1, rtol=1e-15)


def integrate(core: ForceBalance, force_N: float, *, t_max_s: float = 1e12, rtol: float = 1e-6,
              refine: int = 1, progress: Callable[[float, str], None] | None = None) -> _PaperRecord:
    """Lifetime [s] of the cup of `core` under the pull force F1 = force_N, with trajectories.

    Integrates N (and phi with relaxation) by an adaptive Dormand-Prince pair with terminal events;
    h is solved from the force balance at every evaluation. The trajectories hold the accepted
    steps, or `refine` points per step from the solver's 4th-order dense output (each projected
    onto the force balance). Raises ValueError for bad input and `CurveRangeError` (a ValueError)
    if the state leaves the stiffness curve.
    """
    F1 = check_run(force_N, t_max_s, rtol, refine)
    hs, N0, kappa0, Fmax, hm = core.initial
    if F1 >= Fmax:
        msg = (f"F1 = {F1:g} N is at or above the largest force the cup can hold at t = 0, "
               f"{Fmax:.4g} N: it detaches at once")
        return _result(core, F1, 0.0, "over_force", msg, Fmax, N0, [0.0], [[N0, 0.0]], [hs], 0)
    h0 = start_height(core, F1)
    run = _run_reference if core.relax is None else _run_relaxed
    result = run(core, F1, N0, h0, Fmax, t_max_s, rtol, refine)
    if progress:
        progress(1.0, f"F1 = {F1:g} N: {result.reason}")
    return result


def _outputs(sol, refine: int) -> tuple[list, list]:
    """Output times and states: the accepted steps, refined by the dense output if asked."""
    if refine == 1 or not sol.dense:
        return list(sol.t), [list(y) for y in sol.y]
    ts, ys = [sol.t[0]], [list(sol.y[0])]
    for i, dense in enumerate(sol.dense):
        t0, t1 = sol.t[i], sol.t[i + 1]
        for j in range(1, refine):
            tj = t0 + (t1 - t0) * j / refine
            ts.append(tj)
            ys.append(dense(tj))
        ts.append(t1)
        ys.append(list(sol.y[i + 1]))
    return ts, ys


def _run_reference(core: ForceBalance, F1, N0, h0, Fmax, t_max, rtol, refine) -> _PaperRecord:
    h_end, reason = core.branch_end(h0, 1.0, F1)
    N_end = core.n_eq(h_end, 1.0, F1)[0]
    E = core.m.E_Pa
    # sealed anywhere on the branch? (u_c = 0 makes Ndot vanish; it is never crossed in finite time)
    sealed_at = sealed_on_branch(core, h0, h_end, F1)
    if sealed_at is not None:
        line = " (l = 0 there: a line contact, no strip resolved)" if core.geo.at(sealed_at)[4] <= 0 else ""
        return _result(core, F1, math.inf, "sealed",
                       f"u_c = 0 at h = {1e3 * sealed_at:.4g} mm on the way{line}: the interface "
                       f"seals, no further leak", Fmax, N0, [0.0], [[N0, 0.0]], [h0], 0)
    N_h0, slope0 = core.n_eq(h0, 1.0, F1)
    last = [h0, N_h0, slope0]     # last root, its N and dN_eq/dh: a predictor

    def h_of(N: float) -> float:
        if N >= N_end:
            return h_end
        if N <= N_h0:             # water with a vapour bubble (N0 < V(h_c)): the cup waits at h_c
            return h0
        guess = last[0] + (N - last[1]) / last[2] if last[2] > 0 else last[0]
        h, slope = core.branch_root(N, 1.0, F1, guess, h0, h_end)
        last[:] = h, N, slope
        return h

    Ndot_end = core.leak_rate(h_end, N_end, 1.0, E, F1)

    # The integrated variable is the leaked content Q = N - N0, so that the error control is
    # relative to what leaks (N itself hardly changes at large F1).
    def rhs(t, y):     # beyond the end of the branch: continued with the end value (event there)
        N = N0 + y[0]
        return [core.leak_rate(h_of(N), N, 1.0, E, F1) if N < N_end else Ndot_end]

    Ndot0 = rhs(0.0, [0.0])[0]
    Q_end = N_end - N0
    # At a fold h(N) ~ h_f - sqrt(N_f - N), so Ndot(N) has a square-root singularity at the end,
    # where the embedded error estimate is optimistic (measured: lifetime errors up to ~100 rtol
    # there, ~1 rtol otherwise). Fold endings are therefore integrated at rtol / 10.
    if reason == "fold":
        rtol = 0.1 * rtol
    # As F1 -> 0 the rate vanishes at r1 (the strip pressure and p_a - p_b both -> 0 there), so
    # Ndot(N) collapses in the last fraction of a per cent of Q, where the error estimate is as
    # optimistic as at a fold (F1 = 1 mN: Ndot_end / Ndot0 = 0.23, lifetime error 290 rtol):
    # such endings are integrated at rtol (Ndot_end / Ndot0)^2 (F1 = 1 mN: 0.05 rtol)
    elif 0.0 < Ndot_end < Ndot0:
        rtol = max(rtol * (Ndot_end / Ndot0) ** 2, 1e-3 * rtol)
    # water with a vapour bubble: the cup waits at h_c while the bubble refills at the constant
    # rate Ndot(h_c); that phase is exact, and integrating across its end (a kink of Ndot(N))
    # would cost the error control ~100 rtol
    Q_bubble = max(N_h0 - N0, 0.0) if core.liquid else 0.0
    t_bubble = Q_bubble / Ndot0 if Q_bubble > 0 else 0.0
    if t_bubble >= t_max:
        return _result(core, F1, math.inf, "horizon", f"still attached at t_max = {t_max:g} s (the "
                       f"vapour bubble refills at {t_bubble:.4g} s)", Fmax, N0, [0.0, t_max],
                       [[N0, 0.0], [N0 + Ndot0 * t_max, 0.0]], [h0, h0], 0)
    sol = dopri5(rhs, t_bubble, [Q_bubble], t_max, rtol, [rtol * Q_end],
                 events=[lambda t, y: y[0] - Q_end],
                 h0=1e-2 * Q_end / Ndot0 if Ndot0 > 0 else None, dense_output=refine > 1)
    ts, ys = _outputs(sol, refine)
    if Q_bubble > 0:
        ts, ys = [0.0] + ts, [[0.0]] + ys
    ys = [[N0 + y[0], 0.0] for y in ys]
    if sol.event is not None:
        ys[-1][0] = N_end      # the event is N = N_end; only its time is interpolated
    last[:] = h0, N_h0, slope0
    hs = [h_of(y[0]) for y in ys]
    bubble = _cavitation_note(core, F1, N0, h0, N_h0)
    if sol.event is None:
        return _result(core, F1, math.inf, "horizon", f"still attached at t_max = {t_max:g} s" + bubble,
                       Fmax, N0, ts, ys, hs, sol.steps)
    return _result(core, F1, ts[-1], reason, _end_message(reason, ts[-1]) + bubble, Fmax, N0, ts, ys,
                   hs, sol.steps)


def _cavitation_note(core: ForceBalance, F1: float, N0: float, h0: float, N_h0: float) -> str:
    """Water with a cavitation pressure: what the bubble did (empty if none opened). On the liquid
    branch beyond h_c, p_b must stay >= p_cav: a second cavitation is not modelled, so it is an error."""
    p_cav = core.m.cavitation_pressure_Pa
    if not core.liquid or p_cav is None:
        return ""
    h, _ = core.grid
    beyond = np.concatenate(([h0], h[h > h0]))
    short = core.liquid_capacity(beyond) < F1 * (1 - 1e-9)
    if short.any():
        raise RuntimeError(f"cavitation: p_b falls below p_cav = {p_cav:g} Pa again at h = "
                           f"{1e3 * beyond[short][0]:.4g} mm, after the cup has passed h_c = "
                           f"{1e3 * h0:.4g} mm; a second cavitation is not modelled")
    if N_h0 <= N0:
        return ""
    return (f"; cavitation at t = 0: a vapour bubble of {1e9 * (N_h0 - N0):.4g} mm^3 at "
            f"{p_cav:g} Pa let the cup rise to h_c = {1e3 * h0:.4g} mm")


def _run_relaxed(core: ForceBalance, F1, N0, h0, Fmax, t_max, rtol, refine) -> _PaperRecord:
    last = {"h": h0}

    def solve(N: float, phi: float):
        kappa, dk, E = core.modulus(phi)
        lo = last["h"]
        step = 1e-4 * core.h1
        while core.n_eq(lo, kappa, F1)[0] > N:      # step down to bracket the root
            lo = max(lo - step, core.h_lo)
            step *= 2.0
            if lo <= core.h_lo:
                if core.n_eq(lo, kappa, F1)[0] > N:
                    raise CurveRangeError(f"state: the cup height fell below {1e3 * core.h_lo:.4g} mm, "
                                          f"the lower end of the stiffness curve / geometry")
                break
        top, why = core.branch_end(lo, kappa, F1)
        N_top = core.n_eq(top, kappa, F1)[0]
        h = top if N >= N_top else core.branch_root(N, kappa, F1, last["h"], lo, top)[0]
        last["h"] = h
        return h, kappa, dk, E, N_top, why

    def derivatives(h, N, phi, kappa, dk, E):
        Ndot, pb, p, uc, share, r, rp, l, V, Vp, F, Fh = core.state(h, N, kappa, E, F1)
        pa, kT = core.pa, core.kT
        A = math.pi * r * r
        G_h = kappa * Fh - 2 * math.pi * r * rp * (pa - pb) - A * pb * Vp / V
        G_N = A * kT / V
        G_phi = dk * F
        a = rp * phi / l if l > 0.0 else 0.0     # a line contact (l = 0) keeps its point: phi grows
        D = G_h - a * G_phi
        hdot = -(G_N * Ndot + G_phi) / D
        return Ndot, 1.0 - a * hdot, D

    def rhs(t, y):      # y = (N - N0, phi); beyond the branch's end continued with the end values
        N, phi = N0 + y[0], max(y[1], 0.0)
        h, kappa, dk, E, N_top, _ = solve(N, phi)
        Ndot, phidot, _ = derivatives(h, min(N, N_top), phi, kappa, dk, E)
        return [Ndot, phidot]

    D0 = abs(derivatives(h0, N0, 0.0, *core.modulus(0.0))[2])

    def end_event(t, y):          # N reaches the top of the branch (fold or r1)
        h, kappa, dk, E, N_top, _ = solve(N0 + y[0], max(y[1], 0.0))
        return N0 + y[0] - N_top

    def dynamic_fold(t, y):       # D -> 0: rdot diverges
        phi = max(y[1], 0.0)
        h, kappa, dk, E, N_top, _ = solve(N0 + y[0], phi)
        return _DYNAMIC_FOLD - abs(derivatives(h, min(N0 + y[0], N_top), phi, kappa, dk, E)[2]) / D0

    Ndot0 = rhs(0.0, [0.0, 0.0])[0]
    if Ndot0 <= 0.0:
        return _result(core, F1, math.inf, "sealed", "u_c = 0 at t = 0: the interface is sealed",
                       Fmax, N0, [0.0], [[N0, 0.0]], [h0], 0)
    h_top0, _ = core.branch_end(h0, core.modulus(0.0)[0], F1)
    Q_scale = core.n_eq(h_top0, core.modulus(0.0)[0], F1)[0] - N0   # leak to the static end at t = 0
    sol = dopri5(rhs, 0.0, [0.0, 0.0], t_max, rtol, [rtol * Q_scale, 1e-6],
                 events=[end_event, dynamic_fold], h0=1e-3 * Q_scale / Ndot0, dense_output=refine > 1)
    ts, sol_y = _outputs(sol, refine)
    sol_y = [[N0 + y[0], y[1]] for y in sol_y]
    if sol.event == 0:       # the event is N = N_top(phi); only its time is interpolated
        sol_y[-1][0] = solve(sol_y[-1][0], max(sol_y[-1][1], 0.0))[4]
    last["h"] = h0
    hs = []
    for y in sol_y:
        last["h"] = hs[-1] if hs else h0
        hs.append(solve(y[0], max(y[1], 0.0))[0])
    if sol.event is None:
        return _result(core, F1, math.inf, "horizon", f"still attached at t_max = {t_max:g} s",
                       Fmax, N0, ts, sol_y, hs, sol.steps)
    last["h"] = hs[-1]
    reason = solve(sol_y[-1][0], max(sol_y[-1][1], 0.0))[5] if sol.event == 0 else "fold"
    msg = _end_message(reason, ts[-1])
    if sol.event == 1:
        msg += " (dynamic: D = G_h - (r' phi / l) G_phi -> 0, rdot diverges in eq 10)"
    return _result(core, F1, ts[-1], reason, msg, Fmax, N0, ts, sol_y, hs, sol.steps)


def sealed_on_branch(core: ForceBalance, h0: float, h_end: float, F1: float) -> float | None:
    """First h on [h0, h_end] (checked on the fold-search grid) where u_c = 0, or None."""
    line = core.geo.line_contact and core.seal_name == "strip"
    if getattr(core.m.u_c, "sealing_p_over_E", 0.0) == math.inf and not line:
        return None        # a table without sealed rows never seals, unless the strip is a line
    if not core.liquid and core.seal.cannot_seal(1.0, core.m.E_Pa):
        return None        # no ring's pressure reaches sealing even at p_b = 0
    h, _ = core.grid
    for x in [h0] + [float(x) for x in h[(h > h0) & (h < h_end)]] + [h_end]:
        if core.sealed(x, core.n_eq(x, 1.0, F1)[0], 1.0, core.m.E_Pa, F1):
            return x
    return None


def _end_message(reason: str, t: float) -> str:
    what = {"reached_r1": "the contact radius reached r1", "fold": "the force balance lost its "
            "equilibrium (fold)"}[reason]
    return f"detached at t = {t:.6g} s: {what}"


def _result(core: ForceBalance, F1, t_life, reason, msg, Fmax, N0, ts, ys, hs, steps) -> _PaperRecord:
    rows = []
    for t, y, h in zip(ts, ys, hs):
        N, phi = y[0], max(y[1], 0.0)
        kappa, _, E = core.modulus(phi)
        Ndot, pb, p, uc, share, r, rp, l, V, Vp, F, Fh = core.state(h, N, kappa, E, F1)
        G = kappa * F + F1 - math.pi * r * r * (core.pa - pb)
        scale = abs(kappa * F) + F1 + math.pi * r * r * core.pa
        rows.append((t, r, h, pb, p, uc, N, Ndot, phi, share, abs(G) / scale))
    a = np.array(rows, dtype=float).T
    for arr in a:
        arr.flags.writeable = False
    return _PaperRecord(force_N=F1, lifetime_s=float(t_life), reason=reason, message=msg,
                          fluid=core.m.fluid,
                          largest_force_N=float(Fmax), N0=float(N0), t_s=a[0], r_m=a[1], h_m=a[2],
                          p_b_Pa=a[3], p_Pa=a[4], u_c_m=a[5], N=a[6], N_dot_per_s=a[7], phi_s=a[8],
                          ballistic_share_t=a[9], force_residual=a[10], steps=steps)
