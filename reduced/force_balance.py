"""The force balance of the cup, eqs (3)-(8), and its stable equilibrium branch (Sec. 3).

Equilibrium branch. At fixed kappa and F1 the gas content in equilibrium is explicit in h,

    N_eq(h) = V(h) [p_a - (kappa F0(h) + F1) / (pi r(h)^2)] / kT,

and stable equilibria are where N_eq increases with h (G_h < 0). h is found from N by a safeguarded
Newton iteration on that branch, to 1e-13 relative, at every evaluation ("projection"): the force
balance then holds at every output to round-off. The branch ends where N_eq has its first local
maximum (the fold: no equilibrium holds more gas) or where r = r1.

Start. At r_start with F1 = 0 the force balance fixes the trapped gas N0. F1 is then applied at
t = 0 with N0 fixed; h follows the equilibrium continuously from r_start (continuation in F1). The
holding force at fixed N0, F_hold(h) = pi r^2 (p_a - N0 kT/V) - kappa F0, must rise to F1 before its
first local maximum: that maximum (or its value at r1) is the largest force the cup can hold;
at or above it the cup detaches at t = 0.

`ForceBalance` evaluates everything a lifetime needs at one state (h, N, phi) as floats, for the
ODE right-hand sides of `reduced.lifetime.paper`: N_eq(h), the holding force, the leak state (through
the model's seal, `reduced.seal`: eq 6's strip or the contact-pressure profile), the fold, the
start and, for a liquid, cavitation.
"""

from __future__ import annotations

import math
import weakref
from functools import cached_property

import numpy as np

from reduced.fast_curve import CurveRangeError, ScalarPchip
from reduced.geometry import geometry_source
from reduced.model import LeakageModel
from reduced.roots import brentq
from reduced.seal import SEALS, ProfileSeal, StripSeal
from reduced.viscoelastic import measurement_contact_time

__all__ = ["ForceBalance", "force_balance"]

_GRID = 1200          # h samples for locating folds (refined by brentq)


class ForceBalance:
    """Scalar evaluation of eqs (3)-(10), (23) for one model, plus the h grid for folds."""

    def __init__(self, m: LeakageModel, geometry: str = "cone", seal: str = "strip", exact: bool = False):
        if m.stiffness is None:
            raise ValueError("stiffness: the force balance of eqs (3)-(8) needs a stiffness curve F0(u)")
        if m.u_c is None:
            raise ValueError("u_c: the leak needs a critical gap u_c(p/E)")
        self.m = m
        self.seal_name = seal
        curve = m.stiffness if m.kappa == 1.0 else m.stiffness.scaled(m.kappa)
        self.geo = geometry_source(geometry, m.cup, curve)
        self.h1 = self.geo.h_ref_m             # F0 is taken at u = h1 - h
        self.F0 = ScalarPchip(curve.u_m, curve.F0_N, "stiffness curve (u)")
        self.gas = m.gas
        self.liquid = m.fluid == "water"
        self.kT = m.gas.kT_J
        self.pa = m.p_a_Pa
        self.beta = m.cup.beta
        self.uc = getattr(m.u_c, "scalar", m.u_c)
        self.relax = m.relaxation
        mu = m.liquid_viscosity_Pa_s if self.liquid else None
        if seal == "profile":    # without relaxation every leak is at (kappa, E) = (1, E): tabulated
            fixed = None if exact or self.relax is not None else (1.0, m.E_Pa)
            self.seal = ProfileSeal(curve, m.u_c, m.gas, m.p_a_Pa, m.cup.beta, mu, tabulate_at=fixed)
        else:
            self.seal = StripSeal(curve, m.u_c, m.gas, m.p_a_Pa, m.cup.beta, mu)
        if self.relax is not None:
            self.phi0 = m.phi0_s if m.phi0_s is not None else measurement_contact_time(m.cup)
            self.E_ref = self.relax.modulus_and_log_slope(self.phi0)[0]
        u_lo, u_hi = self.F0.lo, self.F0.hi
        self.h_lo = max(self.h1 - u_hi, self.geo.h_min_m, 1e-3 * self.h1)
        self.h_hi = min(self.geo.h_detach_m, self.h1 - u_lo)

    # kappa(phi), dkappa/dphi and the modulus for p/E
    def modulus(self, phi: float) -> tuple[float, float, float]:
        if self.relax is None:
            return 1.0, 0.0, self.m.E_Pa
        E, slope = self.relax.modulus_and_log_slope(phi)
        dk = slope * E / (phi * self.E_ref) if slope != 0.0 else 0.0
        return E / self.E_ref, dk, E

    def spring(self, h: float) -> tuple[float, float]:
        """F0(h) and dF0/dh."""
        F, dF_du = self.F0.value_and_slope(self.h1 - h)
        return F, -dF_du

    def n_eq(self, h: float, kappa: float, F1: float) -> tuple[float, float]:
        """N_eq(h) and dN_eq/dh on the equilibrium branch (eqs 3, 4, 7, 8).

        For a liquid-filled cavity the content is the liquid volume: V(h) and dV/dh (eq 4).
        """
        r, rp, V, Vp, _ = self.geo.at(h)
        if self.liquid:
            return V, Vp
        F, Fh = self.spring(h)
        A = math.pi * r * r
        X = (kappa * F + F1) / A
        N = V * (self.pa - X) / self.kT
        dN = (Vp * (self.pa - X) - V * (kappa * Fh / A - 2.0 * X * rp / r)) / self.kT
        return N, dN

    def holding_force(self, h: float, N0: float, kappa: float) -> tuple[float, float]:
        """F_hold(h) = pi r^2 (p_a - N0 kT/V) - kappa F0 and its h-derivative."""
        r, rp, V, Vp, _ = self.geo.at(h)
        F, Fh = self.spring(h)
        pb = N0 * self.kT / V
        A = math.pi * r * r
        F_hold = A * (self.pa - pb) - kappa * F
        return F_hold, 2 * math.pi * r * rp * (self.pa - pb) + A * pb * Vp / V - kappa * Fh

    def state(self, h: float, N: float, kappa: float, E: float, F1: float):
        """(Ndot, p_b, p, u_c, ballistic share, r, rp, l, V, Vp, F, Fh) at a point, eqs (6), (9), (23)."""
        r, rp, V, Vp, l = self.geo.at(h)
        l = self.seal.width(l)
        F, Fh = self.spring(h)
        pa = self.pa
        if self.liquid:          # p_b from the force balance (7); volume flow eq (24)
            pb = pa - (kappa * F + F1) / (math.pi * r * r)
        else:                    # p_b from the ideal gas (8); molecule flow eqs (9), (19)
            pb = N * self.kT / V
        Ndot, p, uc, share = self.seal.flow(F, r, l, pb, kappa, E, self.h1 - h)
        return Ndot, pb, p, uc, share, r, rp, l, V, Vp, F, Fh

    def _seal_args(self, h: float, N: float, kappa: float, F1: float) -> tuple:
        r, _, V, _, l = self.geo.at(h)
        F = self.spring(h)[0]
        pb = self.pa - (kappa * F + F1) / (math.pi * r * r) if self.liquid else N * self.kT / V
        return F, r, self.seal.width(l), pb

    def leak_rate(self, h: float, N: float, kappa: float, E: float, F1: float) -> float:
        """`state`'s Ndot alone (the ODE's right-hand side): the seal's cheapest evaluation of it."""
        F, r, l, pb = self._seal_args(h, N, kappa, F1)
        return self.seal.rate(F, r, l, pb, kappa, E, self.h1 - h)

    def sealed(self, h: float, N: float, kappa: float, E: float, F1: float) -> bool:
        """Whether `state` reports u_c <= 0 here (the interface seals), without the flow."""
        F, r, l, pb = self._seal_args(h, N, kappa, F1)
        return self.seal.sealed(F, r, l, pb, kappa, E, self.h1 - h)

    # ------------------------------------------------------------------ the h grid
    def spring_array(self, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        F, dF_du = self.F0.values_and_slopes(self.h1 - h)
        return F, -dF_du

    @cached_property
    def grid(self):
        """h samples and the pieces of dN_eq/dh = (S0 - kappa S1 - F1 S2) / kT on them."""
        h = np.linspace(self.h_lo, self.h_hi, _GRID)
        r, rp, V, Vp, _ = self.geo.at_array(h)
        F, Fh = self.spring_array(h)
        A = math.pi * r * r
        S = np.array([Vp * self.pa,
                      Vp * F / A + V * Fh / A - 2.0 * V * F * rp / (r * A),
                      Vp / A - 2.0 * V * rp / (r * A)])
        return h, S

    def branch_end(self, h_from: float, kappa: float, F1: float) -> tuple[float, str]:
        """First local maximum of N_eq above h_from (the fold), else the detachment height (r = r1).

        The sign of dN_eq/dh is scanned on the grid and the fold refined by brentq. A liquid-filled
        cavity has no fold (V(h) increases). Raises `CurveRangeError` if the stiffness curve ends
        below the detachment height, since the cup would then leave the curve.
        """
        if not self.liquid:
            if self.n_eq(h_from, kappa, F1)[1] <= 0.0:
                return h_from, "fold"
            h, S = self.grid
            i0 = int(np.searchsorted(h, h_from, side="right"))
            bad = np.flatnonzero(S[0, i0:] - kappa * S[1, i0:] - F1 * S[2, i0:] <= 0.0)
            if bad.size:
                j = i0 + int(bad[0])
                a = h_from if j == i0 else float(h[j - 1])
                hf = brentq(lambda x: self.n_eq(x, kappa, F1)[1], a, float(h[j]),
                            xtol=1e-15 * self.h1, rtol=1e-14)
                return hf, "fold"
        if self.h_hi < self.geo.h_detach_m * (1 - 1e-12):
            raise CurveRangeError(
                f"stiffness curve: the cup moves towards r1 (u = 0) but the curve starts at "
                f"u = {1e3 * (self.h1 - self.h_hi):.4g} mm; extend it to u = 0")
        return self.h_hi, "reached_r1"

    def branch_root(self, N: float, kappa: float, F1: float, h_guess: float, lo: float,
                    hi: float) -> tuple[float, float]:
        """(h, dN_eq/dh) with N_eq(h) = N to 1e-13 relative, h in [lo, hi] where N_eq increases.

        Safeguarded Newton: a Newton step that leaves the bracket is replaced by bisection.
        """
        h = min(max(h_guess, lo), hi)
        tol_N = 1e-13 * abs(N)
        for _ in range(100):
            f, df = self.n_eq(h, kappa, F1)
            f -= N
            if abs(f) <= tol_N:
                return h, df
            if f > 0.0:
                hi = h
            else:
                lo = h
            h_new = h - f / df if df > 0.0 else lo - 1.0
            if lo < h_new < hi and abs(h_new - h) < 1e-7 * hi:
                return h_new, df       # converged quadratically: the next residual is ~1e-14
            if not (lo < h_new < hi):
                h_new = 0.5 * (lo + hi)
            if hi - lo <= 4e-16 * hi:
                return h_new, df
            h = h_new
        raise RuntimeError(f"force balance: no convergence for N = {N:.6g} in h = [{lo:.6g}, {hi:.6g}] m")

    # ------------------------------------------------------------------ the start
    def start(self):
        """(h_start, N0, kappa0, F_max, h_max): the trapped gas and the largest holdable force."""
        kappa0 = self.modulus(0.0)[0]
        hs = self.geo.h_start_m
        if not self.h_lo <= hs <= self.h_hi:
            raise CurveRangeError(f"stiffness curve: r_start needs h = {1e3 * hs:.6g} mm, outside the "
                                  f"curve's range [{1e3 * self.h_lo:.6g}, {1e3 * self.h_hi:.6g}] mm")
        N0 = self.n_eq(hs, kappa0, 0.0)[0]
        if self.liquid:   # incompressible: h stays at h_start when F1 is applied; p_b takes it all
            return hs, N0, kappa0, self.largest_liquid_force(hs), hs
        if N0 <= 0:
            raise ValueError("r_start_m: the stiffness force at r_start exceeds the full vacuum force "
                             "(no gas can be trapped); check the stiffness curve or r_start")
        h, _ = self.grid
        hh = np.concatenate(([hs], h[h > hs]))
        r, rp, V, Vp, _ = self.geo.at_array(hh)
        F, Fh = self.spring_array(hh)
        pb = N0 * self.kT / V           # d/dh of F_hold, as in holding_force, on the grid
        slope = 2 * math.pi * r * rp * (self.pa - pb) + math.pi * r * r * pb * Vp / V - kappa0 * Fh
        bad = np.flatnonzero(slope <= 0.0)
        if bad.size == 0:
            hm = self.h_hi
        elif bad[0] == 0:
            hm = hs
        else:
            j = int(bad[0])
            hm = brentq(lambda x: self.holding_force(x, N0, kappa0)[1], float(hh[j - 1]), float(hh[j]),
                        xtol=1e-15 * self.h1)
        return hs, N0, kappa0, self.holding_force(hm, N0, kappa0)[0], hm

    # ------------------------------------------------------------------ cavitation (water)
    def liquid_capacity(self, h: np.ndarray) -> np.ndarray:
        """pi r^2 (p_a - p_cav) - F0: the largest F1 the liquid holds at height h without cavitating."""
        r = self.geo.at_array(h)[0]
        return math.pi * r * r * (self.pa - self.m.cavitation_pressure_Pa) - self.spring_array(h)[0]

    def largest_liquid_force(self, hs: float) -> float:
        """The largest capacity on the way from h_start to r1 (inf without a cavitation pressure)."""
        if self.m.cavitation_pressure_Pa is None:
            return math.inf
        h, _ = self.grid
        hh = np.concatenate(([hs], h[h > hs]))
        cap = self.liquid_capacity(hh)
        j = int(np.argmax(cap))
        if 0 < j < len(hh) - 1:       # an interior maximum: refine it between its neighbours
            from scipy.optimize import minimize_scalar     # here: a cavitating liquid only
            res = minimize_scalar(lambda x: -float(self.liquid_capacity(np.array([x]))[0]),
                                  bounds=(float(hh[j - 1]), float(hh[j + 1])), method="bounded",
                                  options={"xatol": 1e-12 * self.h1})
            return max(float(cap[j]), -float(res.fun))
        return float(cap[j])

    def liquid_start(self, F1: float) -> float:
        """h_c: h_start if the liquid holds F1 there with p_b >= p_cav, else the lowest height above it
        where pi r^2 (p_a - p_cav) = F0 + F1 (a vapour bubble opens and the cup rises to it)."""
        hs = self.geo.h_start_m
        if self.m.cavitation_pressure_Pa is None:
            return hs
        cap = lambda x: float(self.liquid_capacity(np.array([x]))[0]) - F1     # noqa: E731
        if cap(hs) >= 0.0:
            return hs
        h, _ = self.grid
        hh = np.concatenate(([hs], h[h > hs]))
        j = int(np.argmax(self.liquid_capacity(hh) >= F1))     # F1 < F_max: a crossing exists
        return brentq(cap, float(hh[j - 1]), float(hh[j]), xtol=1e-15 * self.h1, rtol=1e-15)

    @cached_property
    def initial(self):
        return self.start()


_BALANCES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def force_balance(model: LeakageModel, geometry: str = "cone", seal: str = "strip",
                  exact: bool = False) -> ForceBalance:
    """The `ForceBalance` of `model` with the cup laws `geometry` ('cone' | 'curve') and the
    `seal` ('strip' | 'profile'), as the route chose them; built once per model and choice (its
    start state, fold grid and the profile seal's flow tables are what every lifetime of the model
    shares). exact: the profile seal solves every flow directly instead of from its tables."""
    if seal not in SEALS:
        raise ValueError(f"seal: unknown seal '{seal}', allowed: {', '.join(SEALS)}")
    key = (geometry, seal, bool(exact) and seal == "profile")
    if seal == "profile" and geometry != "curve":
        raise ValueError("seal: the profile's radii are the FEM's: 'profile' needs geometry 'curve' "
                         "(r and V from the same curve)")
    per_model = _BALANCES.setdefault(model, {})
    if key not in per_model:
        per_model[key] = ForceBalance(model, *key)
    return per_model[key]
