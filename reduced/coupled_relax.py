"""Viscoelastic relaxation in the coupled cavity (`reduced.coupled`): the state (N, phi), eq (10).

As in the paper route (`reduced.lifetime.paper`, Sec. 3) the cup's stiffness follows the contact-time
state phi, kappa(phi) = kappa E_eff(phi) / E_eff(phi0) (phi0: the contact time of the stiffness
measurement, the table's cup being the cup as measured), with

    dphi/dt = 1 - rdot phi / l,   phi(0) = 0                                            (10)

The FEM behind the table is elastic, so at every instant the exact E-scaling of the module
`reduced.coupled` holds with the current kappa: in table coordinates (u, s = dp / kappa) the cup
holds F1 = kappa F1_tab(u, s), its gas (p_a - kappa s) V_tab(u, s) = N kT, and its contact
pressures are kappa p_tab(u, s). As in the paper route the interface sees the relaxed modulus,
u_c(p / E_eff(phi)) (Sec. 3: "the relaxation modulus evaluated at the time given by phi"); since
kappa p / E_eff(phi) = kappa_in p_tab / E_eff(phi0) (kappa_in: the constant factor), the gaps
at a table node do not depend on phi, and the leak there changes with kappa only through
p_b = p_a - kappa s. So each node's conductance ln(Ndot / dp) is a smooth function of p_b alone,
interpolated per node by Chebyshev polynomials over the p_b the relaxation can reach, and the
surface at the current kappa is built from the node values as in `reduced.coupled`.

r and l in eq (10) are those of the strip that carries the load: the uniform strip with the
profile's force quartiles, l = 2 (r_75 - r_25) (the force-quartile width that the FEM hands to the
paper route as eq 5's l, `fem.postprocess.quartile_width`) and r = (3 r_25 - r_75) / 2 its inner
edge. For the paper's uniform strip [r, r + l] these are exactly its r and l; on an FEM table they
move continuously, whereas the seal radius r_k is a mesh node's and jumps by a node spacing when
the contact front passes a node (the zone r_k ... r_cut is the whole flattened contact, not the
strip). Both are taken at the nodes (scale-free, so kappa-independent) and interpolated.

The state (N, phi) is integrated by Dormand-Prince (`reduced.ode.dopri5`); u and s are algebraic:
at each evaluation the branch at the current kappa is solved for the state holding N (Newton with
bisection, warm-started). Differentiating the two equations and eq (10) in time gives a 3 x 3
linear system for (udot, sdot, phidot); it is singular where its determinant D = 0: with
phi = 0 or a flat E_eff the static fold (no state holds more gas), otherwise the dynamic
singularity where rdot diverges (as in the paper route, `reduced.lifetime.paper`). End (reason): "fold"
(|D| / |D(0)| < 1e-4), "table_edge" (u reaches the table's smallest u), "over_force" (t = 0),
"sealed" (no leak at t = 0) or "horizon" (still holding at t_max).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, Protocol

import numpy as np
from numpy.polynomial import chebyshev

from reduced.coupled_branch import Branch, BranchPoint
from reduced.coupled_result import _CoupledRecord
from reduced.gas import Gas
from reduced.ode import dopri5
from reduced.profile_leak import ContactProfile, profile_leak_rate, ring_gaps
from reduced.suction_table import SuctionTable
from reduced.table_surface import TableSurface, cell, solid_profile
from reduced.viscoelastic import RelaxationModulus

__all__ = ["load_strip", "relaxed_lifetime", "relaxed_parts", "RelaxedParts"]


class CoupledCavity(Protocol):
    """What the relaxed dynamics reads of the cavity (`reduced.coupled.CoupledCavity`)."""

    table: SuctionTable
    u_c: Any
    gas: Gas
    p_a_Pa: float
    kappa: float
    interface: str
    radial: str
    along_u: str
    relaxation: RelaxationModulus | None
    phi0_s: float | None
    patch_length_m: float | None

    @property
    def _relaxed(self) -> RelaxedParts: ...

    def loaded(self, F1: float, u_start_m: float) -> tuple[float, float | None, float]: ...

_DYNAMIC_FOLD = 1e-4    # |D| / |D(0)| at which the branch is declared folded (static or dynamic)
_CHEBYSHEV = 7          # p_b points per node (cup A coarse, dp <= 60 kPa: 3e-7 in ln against direct)
_PHI_LONGEST = 1e15     # [s] the modulus is assumed not to exceed max(samples, E_eff(this)) before


def load_strip(profile: ContactProfile) -> tuple[float, float] | None:
    """(r, l) [m] of the uniform strip with the load quartiles of the innermost contact zone:
    l = 2 (r_75 - r_25), r = (3 r_25 - r_75) / 2, quartiles of int p dr (trapezoid, p linear
    between samples; the zone runs to the first zero after the first loaded sample). None if
    the profile carries no load."""
    r, p = profile.r_m, profile.p_Pa
    if not np.any(p > 0):
        return None
    k = int(np.argmax(p > 0))
    free = np.flatnonzero(p[k:] <= 0)
    end = r.size if free.size == 0 else k + int(free[0]) + 1
    r, p = r[:end], p[:end]
    load = np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(r))])
    q25, q75 = (_load_quantile(r, p, load, f) for f in (0.25, 0.75))
    return 0.5 * (3.0 * q25 - q75), 2.0 * (q75 - q25)


def _load_quantile(r: np.ndarray, p: np.ndarray, load: np.ndarray, fraction: float) -> float:
    target = fraction * load[-1]
    i = max(int(np.searchsorted(load, target)), 1)
    if load[i] == target:
        return float(r[i])
    h, rest = r[i] - r[i - 1], target - load[i - 1]
    a, b = 0.5 * (p[i] - p[i - 1]) / h, p[i - 1]          # int_0^x p = b x + a x^2
    if abs(a) * h < 1e-12 * max(abs(b), 1e-300):
        return float(r[i - 1] + rest / b)
    return float(r[i - 1] + (-b + math.sqrt(max(b * b + 4 * a * rest, 0.0))) / (2 * a))


class _NodeRates:
    """ln(Ndot / dp) at every table node as a function of kappa (module docstring): Chebyshev
    interpolation in p_b = p_a - kappa s_j over [max(0, p_a - kappa_hi s_j), p_a]."""

    def __init__(self, cc: CoupledCavity, E_ref: float, kappa_hi: float):
        t, pa = cc.table, cc.p_a_Pa
        self.u, self.s, self.pa, self.along_u = t.u_m, t.dp_Pa, pa, cc.along_u
        nu, ns = t.F1_N.shape
        self.lo = np.maximum(pa - kappa_hi * self.s, 0.0)
        x = np.cos((2 * np.arange(_CHEBYSHEV) + 1) * np.pi / (2 * _CHEBYSHEV))
        self.coef = np.zeros((nu, ns, _CHEBYSHEV))
        self.fixed = np.full((nu, ns), np.nan)      # +inf: no contact; -inf: sealed; dp = 0: its limit
        for i in range(nu):
            for j in range(ns):
                self.fixed[i, j], self.coef[i, j] = self._fit(cc, i, j, E_ref, x)
        at_ref = np.concatenate([self._raw(cc.kappa, j) for j in range(ns)])
        self.top = float(np.max(at_ref[np.isfinite(at_ref)]))   # ln of the conductances' scale
        self._last: tuple = (None, None, None)

    def _fit(self, cc: CoupledCavity, i: int, j: int, E_ref: float, x: np.ndarray) -> tuple[float, np.ndarray]:
        """(fixed value or nan, Chebyshev coefficients) of node (i, j): gaps from the solid profile
        at s_j (kappa-free), the leak at the p_b of the Chebyshev points x."""
        none = np.zeros(_CHEBYSHEV)
        pa, s = self.pa, self.s[j]
        prof = solid_profile(cc.table, i, j, 1.0, s, cc.interface, cc.patch_length_m)
        gaps = ring_gaps(prof, cc.u_c, E_ref, scale=cc.kappa)
        if np.all(np.isinf(gaps)):
            return math.inf, none                        # no contact: no resistance
        if np.any(gaps <= 0):
            return -math.inf, none                       # sealed

        def leak(pb: float) -> float:
            return profile_leak_rate(cc.gas, pa, pb, prof.r_m, gaps, cc.radial)
        if j == 0:
            return math.log(leak(pa - 1.0)), none        # the dp -> 0 limit, as unrelaxed
        pb = 0.5 * (self.lo[j] + pa) + 0.5 * (pa - self.lo[j]) * x
        return math.nan, chebyshev.chebfit(x, [math.log(leak(b) / (pa - b)) for b in pb], _CHEBYSHEV - 1)

    def _raw(self, kappa: float, j: int) -> np.ndarray:
        """ln(Ndot / dp) at the nodes (u_i, s_j) at kappa; nan beyond p_a, +-inf open / sealed."""
        pb = self.pa - kappa * self.s[j]
        if pb < 0.0:
            return np.full(self.u.size, np.nan)
        half = 0.5 * (self.pa - self.lo[j])
        x = min(max((pb - self.lo[j] - half) / half, -1.0), 1.0) if half > 0 else 0.0
        z = chebyshev.chebval(x, self.coef[:, j, :].T)
        return np.where(np.isnan(self.fixed[:, j]), z, self.fixed[:, j])

    def column(self, kappa: float, j: int) -> np.ndarray:
        """`_raw`, clipped to [1e-30, 1e3] x the scale (nan: the floor), as unrelaxed."""
        floor, top = self.top + math.log(1e-30), self.top + math.log(1e3)
        z = self._raw(kappa, j)
        return np.clip(np.where(np.isnan(z), floor, z), floor, top)

    def __call__(self, kappa: float, u: float, s: float) -> float:
        """ln(Ndot / dp) at (u, s) at kappa: the surface of `reduced.coupled` on that cell."""
        _, j, _, _ = cell(self.u, self.s, u, s)
        if self._last[:2] != (kappa, j):
            z = np.stack([self.column(kappa, j), self.column(kappa, j + 1)], axis=1)
            self._last = (kappa, j, TableSurface(self.u, self.s[j:j + 2], z, self.along_u))
        return self._last[2](u, s)


@dataclass(frozen=True, eq=False)
class RelaxedParts:
    """What the relaxed lifetimes of one `CoupledCavity` share: kappa(phi) -> (kappa, dkappa/dphi),
    the table's surfaces in (u, s) (F1, V and the strip's r, l) and the node conductances."""

    kappa: Callable[[float], tuple[float, float]]
    surfaces: dict[str, TableSurface]
    rates: _NodeRates


def relaxed_parts(cc: CoupledCavity) -> RelaxedParts:
    """Build `RelaxedParts` (the conductances: _CHEBYSHEV leak evaluations per node)."""
    law, t = cc.relaxation, cc.table
    E_ref = law.modulus_and_log_slope(cc.phi0_s)[0]

    def kappa(phi: float) -> tuple[float, float]:
        E, slope = law.modulus_and_log_slope(phi)
        k = cc.kappa * E / E_ref
        return k, (k * slope / phi if slope != 0.0 else 0.0)

    kappa_hi = cc.kappa * max(float(np.max(law.E_Pa)), law.modulus_and_log_slope(_PHI_LONGEST)[0]) / E_ref
    strips = np.array([[_strip(t, i, j) for j in range(t.dp_Pa.size)] for i in range(t.u_m.size)])
    surfaces = {name: TableSurface(t.u_m, t.dp_Pa, z, cc.along_u)
                for name, z in (("F1", t.F1_N), ("V", t.V_m3), ("r", strips[..., 0]), ("l", strips[..., 1]))}
    return RelaxedParts(kappa, surfaces, _NodeRates(cc, E_ref, kappa_hi))


def _strip(table: SuctionTable, i: int, j: int) -> tuple[float, float]:
    """(r, l) of eq (10) at node (i, j): `load_strip`, or where nothing presses the zone [r_k, r_cut]."""
    strip = load_strip(table.profiles[i][j])
    return strip if strip is not None else (table.seal_r_m[i, j], table.cut_r_m[i, j] - table.seal_r_m[i, j])


def _det3(m: list[list[float]]) -> float:
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


@dataclass(frozen=True)
class _Rates:
    """Ndot, phidot and D at a state."""

    point: BranchPoint
    kappa: float
    N_dot: float
    phi_dot: float
    D: float


class _Dynamics:
    """dN/dt (the leak) and dphi/dt (eq 10 with rdot from the 3 x 3 system) at (N, phi)."""

    def __init__(self, cc: CoupledCavity, parts: RelaxedParts, branch: Branch):
        self.cc, self.parts, self.br = cc, parts, branch
        self.sealed_below = parts.rates.top + math.log(1e-20)        # as unrelaxed
        self._last: tuple = (None, None)

    def __call__(self, N: float, phi: float) -> _Rates:
        if self._last[0] != (N, phi):
            k, dk = self.parts.kappa(phi)
            P, _ = self.br.solve(N, k)
            self._last = ((N, phi), self.rates(P, k, dk, phi))
        return self._last[1]

    def rates(self, P: BranchPoint, k: float, dk: float, phi: float) -> _Rates:
        S, kT = self.parts.surfaces, self.cc.gas.kT_J
        z = self.parts.rates(k, P.u, P.s)
        N_dot = k * P.s * math.exp(z) if z > self.sealed_below else 0.0
        r, r_u, r_s = S["r"].value_and_slopes(P.u, P.s)
        l = S["l"](P.u, P.s)
        a = phi / l if l > 0.0 else 0.0                # a line contact keeps its point: phi grows
        g = self.cc.p_a_Pa - k * P.s
        (F, F_u, F_s), (V, V_u, V_s) = P.F, P.V
        m = [[k * F_u, k * F_s, F * dk], [g * V_u, g * V_s - k * V, -P.s * V * dk], [a * r_u, a * r_s, 1.0]]
        D = _det3(m)
        b = [0.0, kT * N_dot, 1.0]
        phi_dot = _det3([[row[0], row[1], b[n]] for n, row in enumerate(m)]) / D if D != 0.0 else math.inf
        return _Rates(P, k, N_dot, phi_dot, D)


def relaxed_lifetime(cc: CoupledCavity, F1: float, u_start: float, t_max: float,
                     rtol: float) -> _CoupledRecord:
    """Lifetime of the relaxing cup released at u_start and pulled by F1 (module docstring)."""
    run = _Run(cc, F1)
    k0, dk0 = run.parts.kappa(0.0)
    P0 = run.start(u_start, k0)
    if P0 is None:
        return run.result(0.0, "over_force", f"F1 = {F1:g} N exceeds what the cup holds with its "
                          f"start content: it detaches at once", [])
    first = run.dyn.rates(P0, k0, dk0, 0.0)
    if first.N_dot <= 0.0:
        return run.result(math.inf, "sealed", f"the interface is sealed at t = 0 (u = {1e3 * P0.u:.4g} "
                          f"mm, dp = {k0 * P0.s / 1e3:.4g} kPa)", [run.row(0.0, run.N0, 0.0, first)])
    sol = run.integrate(first, k0, t_max, rtol)
    rows = run.trajectory(sol, P0)
    t_end = float(sol.t[-1])
    if sol.event is None:
        return run.result(math.inf, "horizon", f"still attached at t_max = {t_max:g} s", rows, sol.steps)
    where = (f"u reached the table's smallest u = {1e3 * cc.table.u_m[0]:.4g} mm" if sol.event == 0 else
             "the branch folds (D = 0: no state holds more gas, or rdot diverges in eq 10)")
    return run.result(t_end, ("table_edge", "fold")[sol.event], f"detached at t = {t_end:.4g} s: {where}",
                      rows, sol.steps)


class _Run:
    """One relaxed lifetime: the start, the integration of (N - N0, phi) and the trajectory."""

    def __init__(self, cc: CoupledCavity, F1: float):
        self.cc, self.F1, self.parts = cc, F1, cc._relaxed
        self.branch = Branch(cc.table, cc.gas.kT_J, cc.p_a_Pa, F1, self.parts.surfaces)
        self.dyn = _Dynamics(cc, self.parts, self.branch)
        self.N0 = math.nan

    def start(self, u_start: float, k0: float) -> BranchPoint | None:
        """The state at t = 0 (N0 fixed at F1 = 0 and kappa(0), Sec. 3), None for an over-force."""
        frozen = replace(self.cc, kappa=k0, relaxation=None, phi0_s=None)      # the cup at t = 0
        self.N0, dp0, _ = frozen.loaded(self.F1, u_start)
        if dp0 is None:
            return None
        self.branch.last_s = dp0 / k0
        P0, end = self.branch.solve(self.N0, k0)
        return P0 if end is None else None

    def integrate(self, first: _Rates, k0: float, t_max: float, rtol: float):
        """dopri5 on y = (N - N0, phi) (beyond the branch's end: its end values) with the edge and
        fold events."""
        N0, kappa, dyn, D0 = self.N0, self.parts.kappa, self.dyn, abs(first.D)
        Q_scale = self.branch.edge(k0).N - N0             # the leak to the table's edge at t = 0

        def rhs(t: float, y: list) -> list:
            R = dyn(N0 + y[0], max(y[1], 0.0))
            return [R.N_dot, R.phi_dot]

        def edge_event(t: float, y: list) -> float:
            return N0 + y[0] - self.branch.edge(kappa(max(y[1], 0.0))[0]).N

        def fold_event(t: float, y: list) -> float:
            return _DYNAMIC_FOLD - abs(dyn(N0 + y[0], max(y[1], 0.0)).D) / D0

        return dopri5(rhs, 0.0, [0.0, 0.0], t_max, rtol, [rtol * Q_scale, 1e-6],
                      events=[edge_event, fold_event], h0=1e-3 * Q_scale / first.N_dot)

    def trajectory(self, sol, P0: BranchPoint) -> list[tuple]:
        """The rows at the accepted steps, each solved on the branch from the start on."""
        self.branch.last_u, self.branch.last_s = P0.u, P0.s
        rows = []
        for t, (q, phi) in zip(sol.t, sol.y):
            phi, N = max(phi, 0.0), self.N0 + q
            if t == sol.t[-1] and sol.event == 0:      # the event is N = N_edge(kappa): its time interpolated
                N = self.branch.edge(self.parts.kappa(phi)[0]).N
            rows.append(self.row(t, N, phi, self.dyn(N, phi)))
        return rows

    @staticmethod
    def row(t: float, N: float, phi: float, R: _Rates) -> tuple:
        P = R.point
        return (t, P.u, R.kappa * P.s, N, R.N_dot, P.V[0], phi, R.kappa)

    def result(self, life: float, reason: str, msg: str, rows: list, steps: int = 0) -> _CoupledRecord:
        a = np.array(rows, dtype=float).reshape(-1, 8).T
        return _CoupledRecord(self.F1, life, reason, msg, self.N0, *a[:6], p_a_Pa=self.cc.p_a_Pa,
                               phi_s=a[6], kappa=a[7], steps=steps)
