"""The coupled cavity ("fluid cavity"): the cup's state from its (u, dp) table instead of eqs (3)-(7).

The state is the gas content N of the cavity. Pulled by F1, the cup sits where the table says the
pull balances and the gas fills the cavity:

    F1(u, dp) = F1,        (p_a - dp) V(u, dp) = N k_B T,

two equations for the plate displacement u and dp = p_a - p_b (`SuctionTable`: F1 and V as the
FEM computes them with the suction acting on the deformed cup, so the rigid cone of eqs 3-4, the
force balance of eq 5 and eq 6's beta are all replaced). At fixed F1 the states form a branch
parametrised by u, as the fem route walks it: dp(u) from the first equation (F1 rises with dp),
N(u) from the second; gas leaks in, N rises, the plate rises (u falls). The cup starts like the
paper's (Sec. 3): released at u_start with F1 = 0, which fixes N0; it is then raised at fixed N0
until the handle pulls F1 (the largest pull along that raise is the largest holdable force). It
lets go where the branch ends: at a fold of N(u) (no state holds more gas), where the seal opens
(the branch would read a state whose rim has left the plane, `SuctionTable.sealed`: "reached_r1",
as the fem route's seal opening; the end is the last sample of the branch that reads only sealed
states, so it lies within the interpolation's reach of the table's last sealed row), or where it
leaves the table (its smallest u, or more suction than its largest dp: "table_edge").

The leak rate at a state is the series flow through its own contact-pressure profile
(`reduced.profile_leak`), computed at the table's nodes (p_b = p_a - dp_j exactly there) as the
conductance Ndot / dp and interpolated in its logarithm; F1, V and ln(Ndot / dp) are monotone
cubic (PCHIP) along u and linear along dp (monotone data stay monotone, so the branch is unique).
The interpolation error is measured by grid refinement (benchmarks/bench_coupled.py). The solid
pressure each node's leak reads (the interface gas, patches, a seal's last ring) is
`reduced.coupled_leak`'s.

A table with holes (`SuctionTable.built`: states only where the paths go) is read only where
every state the interpolation reads is built (`reduced.coupled_holes`); the root finders bracket
inside built cells, and a value that would read a hole raises `MissingStates` naming the states
to add. Where they are built the values are the full table's; without relaxation only.

The lifetime is t = int dN / Ndot from N0 to the end of the branch, by the trapezoid on a u
grid of `samples` points from the start to the branch's end (found by a first walk of samples/8,
which stops at its first sample past the fold: N has fallen). A stiffness factor kappa makes the cup kappa times stiffer, as the
paper's kappa multiplies F0 (Fig. 1stiffnessFactor): a neo-Hookean body in frictionless contact
with modulus kappa E answers dp exactly as the table's body answers dp / kappa, so F1(u, dp) =
kappa F1_tab(u, dp / kappa), V(u, dp) = V_tab(u, dp / kappa) and the contact pressures scale
likewise, while u_c(p/E) keeps the table's E (the same rubber at the interface, as in the paper
route). With a relaxation modulus (`relaxation`, `phi0_s`) kappa follows the contact time,
kappa(phi) = kappa E_eff(phi) / E_eff(phi0) with eq (10), the interface sees E_eff(phi) as on the
paper route, and (N, phi) is integrated in time: `reduced.coupled_relax`, on the table's rows
above its last row with an unsealed state only (the pressed rows; that integration does not
follow the seal's opening, so its branch ends at that edge, as before the raised rows).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from reduced import coupled_holes as holes
from reduced.coupled_holes import Holes
from reduced.coupled_leak import NodeLeak
from reduced.coupled_relax import RelaxedParts, relaxed_lifetime, relaxed_parts
from reduced.coupled_result import _CoupledRecord
from reduced.gas import AIR, Gas
from reduced.suction_table import SealOpen, SuctionTable
from reduced.table_surface import INTERFACES, TableSurface
from reduced.viscoelastic import RelaxationModulus

__all__ = ["CoupledCavity", "INTERFACES"]


@dataclass(frozen=True, eq=False)
class CoupledCavity:
    """The coupled reduced model (module docstring). u_c: critical gap [m] as a function of p/E,
    with E the table's modulus (with relaxation E_eff(phi), `reduced.coupled_relax`).
    relaxation: E_eff(t), or None (kappa fixed); phi0_s: with relaxation, the contact time [s] of
    the stiffness measurement the table stands for (`reduced.viscoelastic.measurement_contact_time`,
    13 s for cup A). conductances: None, or a dict of node conductances by the node's (u, dp) in
    table units, read and filled here, that cavities of the same model on tables of the same
    states share (a builder's rounds on a growing table with holes)."""

    table: SuctionTable
    u_c: Callable[[float], float]
    gas: Gas = AIR
    p_a_Pa: float = 1e5
    kappa: float = 1.0
    interface: str = "linear"
    radial: str = "annulus"
    samples: int = 801
    along_u: str = "pchip"
    relaxation: RelaxationModulus | None = None
    phi0_s: float | None = None
    conductances: dict | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.kappa) and self.kappa > 0):
            raise ValueError(f"kappa: stiffness factor must be > 0, got {self.kappa}")
        if self.interface not in INTERFACES:
            raise ValueError(f"interface: expected one of {', '.join(INTERFACES)}, got {self.interface!r}")
        if not (math.isfinite(self.p_a_Pa) and self.p_a_Pa > 0):
            raise ValueError(f"p_a_Pa: ambient pressure must be > 0 Pa, got {self.p_a_Pa}")
        if self.along_u not in ("pchip", "linear"):
            raise ValueError(f"along_u: expected 'pchip' or 'linear', got {self.along_u!r}")
        if not (isinstance(self.samples, int) and self.samples >= 11):
            raise ValueError(f"samples: need an integer >= 11, got {self.samples}")
        if self.phi0_s is not None and not (math.isfinite(self.phi0_s) and self.phi0_s > 0):
            raise ValueError(f"phi0_s: measurement contact time must be finite and > 0 s, got {self.phi0_s}")
        if self.relaxation is None and self.phi0_s is not None:
            raise ValueError("phi0_s: the measurement contact time is used only with relaxation; "
                             "give relaxation or drop phi0_s")
        if self.relaxation is not None and not self.table.all_sealed:
            # the time integration does not follow the seal's opening: the rows above the last one
            # with a state without a seal (the pressed rows), so the relaxed branch ends there
            last_open = int(np.flatnonzero(~self.table.sealed.all(axis=1))[-1])
            object.__setattr__(self, "table", self.table.rows(np.arange(self.table.u_m.size) > last_open))
        if self.relaxation is not None and not self.table.complete:
            raise ValueError("suction table: relaxation needs a table without holes (its paths "
                             "follow the contact time, not the built states)")
        if self.relaxation is not None and self.phi0_s is None:
            raise ValueError("phi0_s: with relaxation give the contact time of the stiffness "
                             "measurement in s (> 0), e.g. reduced.viscoelastic.measurement_contact_time(cup)")

    @cached_property
    def _relaxed(self) -> RelaxedParts:
        return relaxed_parts(self)

    # -------------------------------------------------------------- the table, interpolated
    @property
    def _u(self) -> np.ndarray:
        return self.table.u_m

    @cached_property
    def _dp(self) -> np.ndarray:
        """The table's dp axis for the kappa-times-stiffer cup (kappa dp_tab)."""
        return self.kappa * self.table.dp_Pa

    @cached_property
    def _dp_top(self) -> float:
        """The largest dp a state can have: the table's, at most p_a (p_b >= 0)."""
        return float(min(self._dp[-1], self.p_a_Pa))

    def F1(self, u: float, dp: float) -> float:
        """Pull on the handle [N] at (u, dp)."""
        if self._holes is not None:
            self._holes.need(u, dp)
        return self.kappa * self._mechanics["F1"](u, dp)

    def V(self, u: float, dp: float) -> float:
        """Cavity volume [m^3] at (u, dp)."""
        if self._holes is not None:
            self._holes.need(u, dp)
        return self._mechanics["V"](u, dp)

    @cached_property
    def _holes(self) -> Holes | None:
        """The table's built states (None: a complete table)."""
        if self.table.complete and self.table.all_sealed:
            return None
        return Holes(self.table.built, self._u, self._dp, self.along_u, self.table.sealed)

    def _filled(self, z: np.ndarray) -> np.ndarray:
        """z with 0 at the holes and the states without a seal: the surfaces need numbers there;
        `Holes.need` keeps them unread."""
        return z if self._holes is None else np.where(self._holes.built, z, 0.0)

    def Ndot(self, u: float, dp: float) -> float:
        """Molecules per second leaking in at (u, dp): dp times the conductance Ndot / dp,
        interpolated in ln (it varies exponentially with the contact pressure; dividing by dp
        removes the zero of the driving force at dp = 0). A sealed node enters as 1e-30 of the
        largest conductance, and a conductance below 1e-20 of it is a seal (0)."""
        if self._holes is not None:
            self._holes.need(u, dp)
        g = float(np.exp(self._rate_surface(u, dp)))
        return dp * g if g > 1e-20 * self._largest_conductance else 0.0

    @cached_property
    def _largest_conductance(self) -> float:
        g = self._node_conductance
        return float(np.max(g[np.isfinite(g)]))

    @cached_property
    def _mechanics(self) -> dict[str, TableSurface]:
        return {"F1": TableSurface(self._u, self._dp, self._filled(self.table.F1_N), self.along_u),
                "V": TableSurface(self._u, self._dp, self._filled(self.table.V_m3), self.along_u)}

    @cached_property
    def _rate_surface(self) -> TableSurface:
        g = self._node_conductance          # inf: no contact (1e3 x the largest); nan: p_b < 0
        top, floor = 1e3 * self._largest_conductance, 1e-30 * self._largest_conductance
        rates = np.log(np.clip(np.where(np.isnan(g), floor, g), floor, top))
        return TableSurface(self._u, self._dp, self._filled(rates), self.along_u)

    @cached_property
    def _node_conductance(self) -> np.ndarray:
        """Ndot / dp [1/(s Pa)] at every node (u_i, dp_j) through its profile with p_b = p_a - dp_j
        (`reduced.coupled_leak`; nan beyond p_a and at a hole)."""
        leak = NodeLeak(self.table, self.u_c, self.gas, self.p_a_Pa, self.kappa, self.interface, self.radial,
                        self.patch_length_m)
        return leak.conductances(self._dp, self.conductances)

    @property
    def patch_length_m(self) -> float | None:
        """The u_c table's patch length [m]: the profiles' pressures are averaged over it (None: raw)."""
        return getattr(self.u_c, "patch_length_m", None) or None

    # -------------------------------------------------------------- the branch at fixed F1
    def u_at(self, F1: float, dp: float) -> float:
        """u with F1(u, dp) = F1 (F1 falls with u); ValueError where the table ends."""
        if self._holes is not None:
            return holes.u_at(self, F1, dp)
        lo, hi = self.F1(self._u[-1], dp), self.F1(self._u[0], dp)
        slack = 1e-9 * max(abs(lo), abs(hi), 1.0)       # the bracket ends, found by brentq on dp
        if lo - slack <= F1 < lo:
            return float(self._u[-1])
        if hi < F1 <= hi + slack:
            return float(self._u[0])
        if not lo <= F1 <= hi:
            raise ValueError(f"F1 = {F1:.4g} N at dp = {dp / 1e3:.4g} kPa lies outside the table's "
                             f"[{lo:.4g}, {hi:.4g}] N over u = {1e3 * self._u[0]:.4g} ... "
                             f"{1e3 * self._u[-1]:.4g} mm")
        return brentq(lambda u: self.F1(u, dp) - F1, self._u[0], self._u[-1], xtol=1e-15, rtol=1e-13)

    def content(self, F1: float, dp: float) -> tuple[float, float]:
        """(u, N) of the state on the F1 branch at dp."""
        u, V = self._on_branch(F1, dp)
        return u, (self.p_a_Pa - dp) * V / self.gas.kT_J

    def _on_branch(self, F1: float, dp: float) -> tuple[float, float]:
        """(u, V) of the state on the F1 branch at dp."""
        u = self.u_at(F1, dp)
        return u, self.V(u, dp)

    def _dp_range(self, F1: float) -> tuple[float, float]:
        """The dp interval of the branch inside the table: u from u_min (low dp) to u_max (on a
        table with holes: (the low end, nan))."""
        top = self._dp_top
        if self._holes is not None:
            return holes.dp_low(self, F1), math.nan
        if F1 > self.F1(self._u[0], top):
            return math.nan, math.nan
        lo = 0.0 if F1 <= self.F1(self._u[0], 0.0) else brentq(
            lambda d: self.F1(self._u[0], d) - F1, 0.0, top, xtol=1e-9)
        hi = top if F1 >= self.F1(self._u[-1], top) else brentq(
            lambda d: self.F1(self._u[-1], d) - F1, lo, top, xtol=1e-9)
        return lo, hi

    def start(self, u_start_m: float) -> tuple[float, float]:
        """(dp, N0) of the cup released at u_start with F1 = 0 (Sec. 3's start)."""
        if not self._u[0] <= u_start_m <= self._u[-1]:
            raise ValueError(f"u_start: must lie in the table's u range [{1e3 * self._u[0]:.4g}, "
                             f"{1e3 * self._u[-1]:.4g}] mm, got {1e3 * u_start_m:.4g} mm")
        top = self._dp_top
        if self._holes is not None:
            dp = holes.start_dp(self, u_start_m)
            return dp, (self.p_a_Pa - dp) * self.V(u_start_m, dp) / self.gas.kT_J
        if self.F1(u_start_m, top) < 0:
            raise ValueError(f"u_start: the table's dp <= {top / 1e3:.4g} kPa cannot hold the cup "
                             f"released at u = {1e3 * u_start_m:.4g} mm")
        dp = brentq(lambda d: self.F1(u_start_m, d), 0.0, top, xtol=1e-9)
        return dp, (self.p_a_Pa - dp) * self.V(u_start_m, dp) / self.gas.kT_J

    def dp_holding(self, u: float, value: Callable[[float], float], target: float, rising: bool,
                   near: float | None = None) -> float | None:
        """dp in [0, top] with value(dp) = target at the plate displacement u (value monotone in
        dp, rising or falling); None if the target lies beyond the table's dp range. SealOpen
        (`reduced.suction_table`) where the crossing lies among states without a seal. On a table
        with holes `near` (a path's previous dp) says which missing states to name first
        (`Holes.root_cell`)."""
        top = self._dp_top
        if self._holes is not None:
            found = self._holes.root_cell("dp", u, value, target, rising=rising, top=top, near=near)
            if not isinstance(found, tuple):
                return None
            a, b = found
        else:
            a, b = 0.0, top
        sign = 1.0 if rising else -1.0
        ga, gb = sign * (value(a) - target), sign * (value(b) - target)
        if ga > 0 or gb < 0:
            return None
        if ga == 0 or a == b:
            return a
        return brentq(lambda d: value(d) - target, a, b, xtol=1e-9 * max(top, 1.0))

    def _gas(self, u: float, dp: float) -> float:
        """N [molecules] of the state (u, dp): the gas law (p_a - dp) V = N k_B T."""
        return (self.p_a_Pa - dp) * self.V(u, dp) / self.gas.kT_J

    def _walk(self, u_from: float, u_to: float, dp_of: Callable[[float, float | None], float | None],
              samples: int, stop: Callable[[float, float], bool] | None = None
              ) -> tuple[np.ndarray, np.ndarray, str]:
        """The states (u, dp(u, dp of the previous state or None)) from u_from down to u_to on
        `samples` points, as far as they exist: (u, dp, end) with end "table_edge" (u_to reached,
        or dp(u) beyond the table's dp), "reached_r1" (the next state reads one without a seal:
        the seal has opened), or "stop" (stop(u, dp) true at the last state)."""
        us, dps = [], []
        end = "table_edge"
        for u in np.linspace(u_from, u_to, samples):
            try:
                dp = dp_of(float(u), dps[-1] if dps else None)
            except SealOpen:
                end = "reached_r1"
                break
            if dp is None:
                break
            us.append(float(u))
            dps.append(dp)
            if stop is not None and stop(float(u), dp):
                end = "stop"
                break
        return np.array(us), np.array(dps), end

    def _raised_at(self, N0: float, u_start_m: float, F1: float | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
        """The cup sealed with N0 at u_start and raised at fixed N0 (the plate from u_start to
        the table's smallest u, or until it pulls F1): (u, dp, F1 along it, how it ends, as `_walk`)."""
        def dp_of(u: float, near: float | None) -> float | None:
            return self.dp_holding(u, lambda d: self._gas(u, d), N0, rising=False, near=near)
        stop = None if F1 is None else (lambda u, d: self.F1(u, d) >= F1)
        us, dps, end = self._walk(u_start_m, float(self._u[0]), dp_of, self.samples, stop)
        return us, dps, np.array([self.F1(u, d) for u, d in zip(us, dps)]), end

    def loaded(self, F1: float, u_start_m: float) -> tuple[float, float | None, float]:
        """(N0, dp0, u0): the start content of the cup released at u_start (`start`), and the state
        that holds F1 with it: the cup raised at fixed N0 until the handle pulls F1 (dp0 None if
        no state on that path pulls F1: more than the cup holds, the over-force)."""
        _, N0 = self.start(u_start_m)
        us, dps, pull, _ = self._raised_at(N0, u_start_m, F1)
        above = np.flatnonzero(pull >= F1)
        if above.size == 0:
            return N0, None, math.nan
        k = int(above[0])
        if k == 0:
            return N0, float(dps[0]), float(us[0])
        def excess(u: float) -> float:
            return self.F1(u, self.dp_holding(u, lambda d: self._gas(u, d), N0, rising=False)) - F1
        u0 = brentq(excess, us[k], us[k - 1], xtol=1e-13, rtol=1e-12)
        return N0, self.dp_holding(u0, lambda d: self._gas(u0, d), N0, rising=False), u0

    def largest_force(self, u_start_m: float) -> float:
        """The largest F1 [N] the cup released at u_start holds at t = 0: the largest pull of the
        cup raised at fixed N0 (`loaded`), refined between the samples around it. With
        relaxation: the cup at t = 0, kappa(phi = 0)."""
        if self.relaxation is not None:
            k0 = self._relaxed.kappa(0.0)[0]
            return replace(self, kappa=k0, relaxation=None, phi0_s=None).largest_force(u_start_m)
        _, N0 = self.start(u_start_m)
        us, _, pull, _ = self._raised_at(N0, u_start_m)
        if pull.size == 0:
            return 0.0
        k = int(np.argmax(pull))
        if k == 0 or k == pull.size - 1:
            return max(float(pull[k]), 0.0)

        def minus_pull(u: float) -> float:
            return -self.F1(u, self.dp_holding(u, lambda d: self._gas(u, d), N0, rising=False))
        best = minimize_scalar(minus_pull, bounds=(us[k + 1], us[k - 1]), method="bounded",
                               options={"xatol": 1e-12})
        return max(float(-best.fun), float(pull[k]))

    def lifetime(self, force_N: float, u_start_m: float, *, t_max_s: float = 1e12,
                  rtol: float = 1e-6) -> _CoupledRecord:
        """Lifetime of the cup released at u_start and pulled by F1 = force_N (module docstring).
        With relaxation it is integrated in time (`reduced.coupled_relax`) up to t_max_s with the
        relative tolerance rtol; without, t_max_s and rtol are not used (a quadrature)."""
        F1 = float(force_N)
        if not (math.isfinite(F1) and F1 > 0):
            raise ValueError(f"force_N: pull force must be > 0 N, got {force_N}")
        if self.relaxation is not None:
            if not (t_max_s > 0 and 0 < rtol < 1e-2):
                raise ValueError(f"t_max_s, rtol: need t_max_s > 0 and 0 < rtol < 0.01, got {t_max_s}, {rtol}")
            return relaxed_lifetime(self, F1, u_start_m, t_max_s, rtol)
        N0, dp0, u0 = self.loaded(F1, u_start_m)
        if dp0 is None:
            return _CoupledRecord(F1, 0.0, "over_force", f"F1 = {F1:g} N exceeds what the cup holds "
                                   f"with its start content: it detaches at once", N0,
                                   *(np.zeros(0),) * 6, p_a_Pa=self.p_a_Pa)

        def dp_of(u: float, near: float | None) -> float | None:
            return dp0 if u == u0 else self.dp_holding(u, lambda d: self.F1(u, d), F1, rising=True, near=near)
        # a first walk finds where the branch ends (or has passed its fold: N fell), the second
        # samples it up to there
        u_end, coarse, contents = float(self._u[0]), max(self.samples // 8, 11), []

        def past_fold(u: float, dp: float) -> bool:
            contents.append(self._gas(u, dp))
            return len(contents) > 1 and contents[-1] <= contents[-2]
        u, _, end = self._walk(u0, u_end, dp_of, coarse, stop=past_fold)
        if end == "stop":
            u_end = float(u[-1])
        elif u.size < coarse:
            u_end = float(np.linspace(u0, u_end, coarse)[u.size])
        u, dps, reason = self._walk(u0, u_end, dp_of, self.samples)
        V = np.array([self.V(a, b) for a, b in zip(u, dps)])
        N = (self.p_a_Pa - dps) * V / self.gas.kT_J
        rising = np.diff(N) > 0
        if not np.all(rising):
            end = int(np.argmin(rising)) + 1
            reason = "fold"
            dps, u, N, V = dps[:end], u[:end], N[:end], V[:end]
        q = np.array([self.Ndot(a, b) for a, b in zip(u, dps)])
        if np.any(q <= 0):
            k = int(np.argmax(q <= 0))
            return _CoupledRecord(F1, math.inf, "sealed", f"the interface seals at u = "
                                   f"{1e3 * u[k]:.4g} mm, dp = {dps[k] / 1e3:.4g} kPa", N0,
                                   np.zeros(1), u[:1], dps[:1], N[:1], q[:1], V[:1], p_a_Pa=self.p_a_Pa)
        t = np.concatenate([[0.0], np.cumsum(0.5 * (1 / q[1:] + 1 / q[:-1]) * np.diff(N))])
        where = {"table_edge": "the branch leaves the table (its smallest u = "
                               f"{1e3 * self._u[0]:.4g} mm or its largest dp)",
                 "fold": "the branch folds: no state holds more gas",
                 "reached_r1": f"the seal opens: past u = {1e3 * u[-1]:.4g} mm the rim leaves the plane"}[reason]
        return _CoupledRecord(F1, float(t[-1]), reason, f"detached at t = {t[-1]:.4g} s: {where}", N0,
                               t, u, dps, N, q, V, p_a_Pa=self.p_a_Pa)

