"""Leakage through a contact-pressure profile p(r): the annulus as strips in series (Sec. 4, local).

The paper lets the gas cross one strip of width l at the uniform pressure of eq (6). Here the
contact zone r_0 < r < r_n is cut into rings [r_i, r_i+1], each with its own gap u_i = u_c(p_i / E)
(p_i: the contact pressure at the ring's middle), and the gas pressure P(r) rises from p_b at the
inner edge to p_a at the outer one. The molecule flow Q = 2 pi r j(r) is the same through every
ring (steady state). Locally the flux per unit circumference is eq (13) with eq (19)'s ballistic
correction, written with the local pressure:

    j = -(u^3 / (12 eta kT)) (P + a / u) dP/dr,      a = xi (n lambda) kT / 2,   xi = 32 / pi

(n lambda = 3 eta / (m v) does not depend on the density, eq 12). Integrated over a ring of
constant gap u,

    Phi_u(P_out) - Phi_u(P_in) = c Q,   Phi_u(P) = u^3 P^2 / 2 + a u^2 P,   c = 12 eta kT g / (2 pi)

with the ring's geometric factor g = ln(r_out / r_in) (the exact annulus; ``radial="annulus"``) or
g = (r_out - r_in) / r_0 (the paper's flat strip, L_y = 2 pi r_0; ``radial="strip"``). For one ring
this is exactly eqs (19), (20), (23) with L_y / L_x = 2 pi / g: for a strip of width l at r,
2 pi r / l, and for the annulus 2 pi / ln(1 + l / r) = (2 pi r / l)(1 + l / 2r + O(l^2/r^2)).
Rings in series: P is marched from p_a at r_n inwards, P_i = -a/u + ((P_i+1 + a/u)^2 - 2 c_i Q / u^3)^(1/2),
and Q is the root of P_0(Q) = p_b (monotone; Newton with bracketing). A ring with u = 0 (the
contact area percolates: sealed) stops the flow; a ring with no contact (p = 0) costs nothing.

`profile_leak_rates` solves many states of the same rings at once (the march vectorised over the
states), for tabulating a profile's flow against p_b (`reduced.seal.PbTable`).

Water (eq 24 locally): j_V = -(u^3 / (12 eta)) dP/dr, so p_a - p_b = Q_V sum_i 12 eta g_i / (2 pi u_i^3).

Patch-averaged pressure (`patch_average`, `patch_contact`; the profile route uses it when the u_c
table carries a length, `reduced.seal`, e.g. `reduced.roughness.uc_table(..., with_patch_length=True)`). u_c(p) of rough-contact theory (Persson's theory, the
critical-junction and effective-medium pictures of Sec. 4, 5.1) is a function of the *nominal*
pressure, uniform on a patch that holds every roughness wavelength u_c depends on: the theory's
contact, separation and percolation at the critical magnification are built up from the longest
wavelengths down. Wavelengths longer than the patch only tilt and lift it and do not change u_c,
so the smallest such patch L can be measured from the theory itself
(`reduced.roughness.persson.patch_length`: cut the spectrum's long wavelengths until u_c at 1 atm on
4 MPa changes by 2 %; the lengths of the presets are in docs/lifetime.md). On
shorter scales a pressure is not a nominal one, and u_c of it is outside the theory. The FEM's
pointwise profile has exactly such a feature: at small plate displacement only the sharp rim corner
touches, one loaded node whose lumped pressure (its force over its tributary length) doubles with
each mesh refinement (a corner singularity), so u_c(p_max) falls and the leak seals as the mesh is
refined. Averaged over patches of width L, the pressure entering u_c is
the force on the annulus [r - L/2, r + L/2] over its area: exact for a uniform pressure, force
conserving, and a lone loaded node becomes a strip L wide at F / (2 pi r L), independent of the
element size once the elements are shorter than L. The length is `UcTable.patch_length_m`, set by
`reduced.roughness.uc_table` with `with_patch_length=True` (the convergence it buys is measured by
`benchmarks/bench_profile_convergence.py`, docs/lifetime.md).
A contact far narrower than L that is known by its force alone (a finite-element node touching
the plane alone, its neighbours lifted) enters as a ring load: `patch_average` spreads its force
F over the patch around it, the box F / (2 pi r L), whatever the (unresolved) width it acts on.
Eq (6)'s suction share beta (p_a - p_b) is a pressure on the contact, not a load to spread: it is
added on the nominal contact, the FEM's contact intervals (edges half-way between the last loaded
node and the first free one) widened by L/2 each side (the patches that hold contact).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from reduced.gas import XI, Gas

__all__ = ["ContactProfile", "contact_segments", "patch_average", "patch_contact", "ring_gaps", "profile_leak_rate",
           "profile_leak_rates", "profile_liquid_rate"]


@dataclass(frozen=True)
class ContactProfile:
    """Contact pressure p(r) [Pa] at radii r [m] (strictly increasing) across the contact zone(s);
    p = 0 marks no contact. Plain data: from the FEM (the lumped nodal pressures), a measurement
    or a formula."""

    r_m: np.ndarray
    p_Pa: np.ndarray

    def __post_init__(self) -> None:
        r = np.array(self.r_m, dtype=float).reshape(-1)
        p = np.array(self.p_Pa, dtype=float).reshape(-1)
        if r.size != p.size or r.size < 2:
            raise ValueError(f"p_Pa: a contact profile needs >= 2 matching (r, p) samples, got {r.size}, {p.size}")
        if not (np.all(np.isfinite(r)) and np.all(np.isfinite(p))):
            raise ValueError("r_m, p_Pa: a contact profile must be finite")
        if np.any(r <= 0) or np.any(np.diff(r) <= 0):
            raise ValueError("r_m: profile radii must be > 0 and strictly increasing")
        if np.any(p < 0):
            raise ValueError(f"p_Pa: contact pressure must be >= 0, got {p.min():.4g} Pa")
        r.flags.writeable = p.flags.writeable = False
        object.__setattr__(self, "r_m", r)
        object.__setattr__(self, "p_Pa", p)

    @property
    def force_N(self) -> float:
        """The contact force 2 pi int p r dr [N] (trapezoid over the samples)."""
        f = self.p_Pa * self.r_m
        return float(np.pi * np.sum((f[1:] + f[:-1]) * np.diff(self.r_m)))


def patch_average(profile: ContactProfile, length_m: float, rings_r_m: np.ndarray | None = None,
                  rings_F_N: np.ndarray | None = None) -> ContactProfile:
    """The nominal pressure of `profile` on patches of radial width `length_m` (module docstring,
    "Patch-averaged pressure"): at radius x, the force on the annulus [x - L/2, x + L/2] over its area,

        pbar(x) = (G(x + L/2) - G(x - L/2)) / ((x + L/2)^2 / 2 - (x - L/2)^2 / 2),   G(r) = int_0^r p s ds

    with p r linear between the samples (the trapezoid rule of `ContactProfile.force_N`; G is then
    piecewise quadratic and exact). A uniform pressure is returned unchanged wherever the window lies
    inside it, and int pbar r dr = int p r dr. The result is sampled at its kinks r_i +- L/2 (pbar is
    a rational quadratic between them) and at the ends of the nominal contact (`patch_contact`),
    intervals longer than L/2 split evenly; its
    support is the input's widened by L/2 on each side (a window starting below r = 0 is cut there).

    `rings_F_N` [N] at `rings_r_m`: line loads on circles (a contact far narrower than L, known by
    its force alone), added to G as steps: each is the box F / (2 pi x L) on [rho - L/2, rho + L/2],
    its force kept exactly. The box's jumps are sampled on both sides, 1e-6 L apart (a ring that
    thin carries a negligible share of any flow).
    """
    L = float(length_m)
    if not (math.isfinite(L) and L > 0.0):
        raise ValueError(f"length_m: the patch length must be finite and > 0, got {length_m}")
    rho, F = _rings(rings_r_m, rings_F_N)
    r, p = profile.r_m, profile.p_Pa
    f = p * r
    G = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(r))])
    a, b = contact_segments(profile)
    kinks = np.unique(np.concatenate([r - 0.5 * L, r + 0.5 * L, a - 0.5 * L, b + 0.5 * L]))
    if rho.size:
        jumps = np.concatenate([rho - 0.5 * L, rho + 0.5 * L])
        kinks = np.unique(np.concatenate([kinks, jumps - 1e-6 * L, jumps + 1e-6 * L]))
    kinks = kinks[kinks > 0.0]
    n = np.maximum(1, np.ceil(np.diff(kinks) / (0.5 * L) - 1e-9).astype(int))
    start = np.repeat(kinks[:-1], n)
    step = np.repeat(np.diff(kinks) / n, n)
    j = np.arange(start.size) - np.repeat(np.cumsum(n) - n, n)
    x = np.append(start + j * step, kinks[-1])
    a, b = np.maximum(x - 0.5 * L, 0.0), x + 0.5 * L
    pbar = (_cumulative(r, f, G, b) - _cumulative(r, f, G, a)) / (0.5 * (b * b - a * a))
    pbar[pbar <= 1e-12 * max(float(p.max()), 0.0)] = 0.0     # round-off off the support
    if rho.size:
        inside = (rho[None, :] >= a[:, None]) & (rho[None, :] <= b[:, None])
        pbar = pbar + (inside @ F) / (math.pi * (b * b - a * a))
    return ContactProfile(x, pbar)


def _rings(r_m: np.ndarray | None, F_N: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Checked ring loads: radii > 0 and forces >= 0, one force per radius."""
    rho = np.zeros(0) if r_m is None else np.asarray(r_m, dtype=float).reshape(-1)
    F = np.zeros(0) if F_N is None else np.asarray(F_N, dtype=float).reshape(-1)
    if rho.size != F.size:
        raise ValueError(f"rings_F_N: one force per ring radius, got {F.size} for {rho.size}")
    if not (np.all(np.isfinite(rho)) and np.all(rho > 0) and np.all(np.isfinite(F)) and np.all(F >= 0)):
        raise ValueError("rings_r_m, rings_F_N: ring loads need radii > 0 and finite forces >= 0")
    return rho, F


def contact_segments(profile: ContactProfile) -> tuple[np.ndarray, np.ndarray]:
    """The contact intervals [a_j, b_j] of `profile` (sorted, disjoint): a ring between two loaded
    samples (p > 0) is in contact, one between a loaded and a free sample up to its middle (the
    edge lies somewhere between the last node on the plane and the first off it); a loaded end
    sample ends its interval there."""
    r, loaded = profile.r_m, profile.p_Pa > 0
    half = 0.5 * (r[1:] + r[:-1])
    lo = np.where(loaded[:-1], r[:-1], half)[loaded[:-1] | loaded[1:]]
    hi = np.where(loaded[1:], r[1:], half)[loaded[:-1] | loaded[1:]]
    if lo.size == 0:
        return lo, hi
    start = np.concatenate([[True], lo[1:] > hi[:-1]])       # a new interval where a ring is free
    end = np.concatenate([start[1:], [True]])
    return lo[start], hi[end]


def patch_contact(profile: ContactProfile, length_m: float, r_m: np.ndarray) -> np.ndarray:
    """Which rings [r_i, r_i+1] of the grid `r_m` lie in the nominal contact of `profile` on patches
    of width L = `length_m`: the contact intervals (`contact_segments`) widened by L/2 on each side,
    i.e. the patches that hold contact (a lone loaded node's is L wide). Tested at the rings'
    middles; `patch_average`'s grid has the widened intervals' ends among its radii."""
    a, b = contact_segments(profile)
    r = np.asarray(r_m, dtype=float)
    mid = 0.5 * (r[1:] + r[:-1])
    if a.size == 0:
        return np.zeros(mid.size, dtype=bool)
    a, b = a - 0.5 * float(length_m), b + 0.5 * float(length_m)
    j = np.searchsorted(a, mid, side="right") - 1          # the last interval starting at or below
    return (j >= 0) & (mid <= b[np.clip(j, 0, None)])


def _cumulative(r: np.ndarray, f: np.ndarray, G: np.ndarray, x: np.ndarray) -> np.ndarray:
    """G(x) = int_{r_0}^x f ds with f linear between the samples, 0 below r_0, G[-1] above r_n."""
    i = np.clip(np.searchsorted(r, x, side="right") - 1, 0, r.size - 2)
    h = r[i + 1] - r[i]
    t = np.clip(x - r[i], 0.0, h)
    inside = G[i] + f[i] * t + (f[i + 1] - f[i]) * t * t / (2.0 * h)
    return np.where(x <= r[0], 0.0, np.where(x >= r[-1], G[-1], inside))


def ring_gaps(profile: ContactProfile, u_c: Callable[[float], float], E_Pa: float,
              scale: float = 1.0, extra_Pa: float | np.ndarray = 0.0) -> np.ndarray:
    """Gap u_i [m] of each ring: u_c of the contact pressure at its middle, scale p + extra_Pa
    (kappa F0's share and eq (6)'s beta (p_a - p_b)); inf where neither touches (no contact).
    `extra_Pa` may be one value per ring (then a ring with extra_Pa > 0 is in contact too)."""
    p = profile.p_Pa
    mid = 0.5 * (p[1:] + p[:-1])
    touching = (p[1:] > 0) | (p[:-1] > 0)
    if np.ndim(extra_Pa):
        extra = np.asarray(extra_Pa, dtype=float)
        if extra.shape != mid.shape:
            raise ValueError(f"extra_Pa: one value per ring ({mid.size}) or one for all, got {extra.shape}")
        touching = touching | (extra > 0)
    else:
        extra = np.full(mid.size, float(extra_Pa))
    values = getattr(u_c, "values", None)
    if values is not None:                  # a UcTable: vectorised
        gaps = np.full(mid.size, math.inf)
        gaps[touching] = values((scale * mid[touching] + extra[touching]) / E_Pa)
        return gaps
    uc = getattr(u_c, "scalar", u_c)
    return np.array([uc((scale * m + x) / E_Pa) if t else math.inf for m, x, t in zip(mid, extra, touching)])


def _geometry(r: np.ndarray, radial: str) -> np.ndarray:
    if radial == "annulus":
        return np.log(r[1:] / r[:-1])
    if radial == "strip":
        return np.diff(r) / r[0]
    raise ValueError(f"radial: expected 'annulus' or 'strip', got {radial!r}")


def profile_leak_rate(gas: Gas, p_a: float, p_b: float, r_m: np.ndarray, gaps_m: np.ndarray,
                      radial: str = "annulus") -> float:
    """Molecule flow [1/s] into the cavity through rings [r_i, r_i+1] of gaps u_i (module docstring)."""
    if not 0.0 <= p_b <= p_a:
        raise ValueError(f"p_b: cavity pressure must be in [0, p_a] = [0, {p_a:g}] Pa, got {p_b:g}")
    u = np.asarray(gaps_m, dtype=float)
    g = _geometry(np.asarray(r_m, dtype=float), radial)
    if np.any(u <= 0.0) or p_b == p_a:
        return 0.0
    resist = np.isfinite(u)
    if not resist.any():
        raise ValueError("gaps_m: no ring of the profile is in contact (the cavity is open)")
    u, c = u[resist], 12.0 * gas.viscosity_Pa_s * gas.kT_J * g[resist] / (2.0 * math.pi)
    b = XI * gas.n_lambda_per_m2 * gas.kT_J / 2.0 / u          # a / u for each ring
    return _series_flow(p_a, p_b, u ** 3, b, c)


def profile_leak_rates(gas: Gas, p_a: float, p_b: np.ndarray, r_m: np.ndarray, gaps_m: np.ndarray,
                       radial: str = "annulus") -> np.ndarray:
    """`profile_leak_rate` for many states of the same rings at once: p_b [Pa] of shape (M,), gaps
    u_i [m] of shape (rings, M), one column per state; the flows [1/s] of shape (M,). The same
    march and root search, vectorised over the states (for tabulating a profile's flow)."""
    pb = np.asarray(p_b, dtype=float).reshape(-1)
    u = np.asarray(gaps_m, dtype=float).reshape(-1, pb.size)
    g = _geometry(np.asarray(r_m, dtype=float), radial)
    if not np.all((pb >= 0.0) & (pb <= p_a)):
        raise ValueError(f"p_b: cavity pressures must be in [0, p_a] = [0, {p_a:g}] Pa")
    if u.shape[0] != g.size:
        raise ValueError(f"gaps_m: one row per ring ({g.size}), got {u.shape[0]}")
    resist = np.isfinite(u).any(axis=1)
    if not resist.any():
        raise ValueError("gaps_m: no ring of the profile is in contact (the cavity is open)")
    u, g = u[resist], g[resist]
    q = np.zeros(pb.size)
    live = ~np.any(u <= 0.0, axis=0) & (pb < p_a)
    if live.any():
        u = u[:, live]
        c = 12.0 * gas.viscosity_Pa_s * gas.kT_J * g / (2.0 * math.pi)
        b = XI * gas.n_lambda_per_m2 * gas.kT_J / 2.0 / u      # 0 where a ring is open (u = inf)
        q[live] = _series_flows(p_a, pb[live], u ** 3, b, c)
    return q


def _series_flow(p_a: float, p_b: float, u3: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    """Q with P marched from p_a through the rings (Phi differences c_i Q) ending at p_b."""
    # upper bound: no ring passes more than it would with the whole drop across it alone
    q_hi = float(np.min(u3 * ((p_a + b) ** 2 - (p_b + b) ** 2) / (2.0 * c)))
    # start: each ring's conductance frozen at the mean pressure (exact for one ring, or all b equal)
    q_lin = (p_a - p_b) / float(np.sum(c / (u3 * (0.5 * (p_a + p_b) + b))))
    lo, hi = 0.0, q_hi
    q = q_lin if 0.0 < q_lin < q_hi else 0.5 * q_hi
    # the march's round-off: each ring's P = sqrt((P + b)^2 - ...) - b cancels to ~eps (P + b); at
    # nanometre gaps b = a/u reaches 1e9 Pa and P_in is no better than that, so a residual at that
    # level is converged (Newton would wander in the noise)
    noise = 1e-13 * (p_a + float(np.max(b))) * math.sqrt(u3.size)
    # the march on Python floats: the same IEEE operations as on numpy scalars, at a third of the cost
    rings = (u3.tolist(), b.tolist(), c.tolist())
    for _ in range(100):
        p_in, dp_dq = _march(p_a, rings[0], rings[1], rings[2], q)
        f = p_in - p_b
        if abs(f) <= noise:
            return q
        if f > 0.0:
            lo = q
        else:
            hi = q
        step = q - f / dp_dq if math.isfinite(dp_dq) and dp_dq < 0 else math.nan
        q_new = step if lo < step < hi else 0.5 * (lo + hi)
        if abs(q_new - q) <= 1e-13 * q_hi or hi - lo <= 1e-14 * q_hi:
            return q_new
        q = q_new
    raise RuntimeError(f"profile leak: no convergence of the series flow (p_a {p_a:g}, p_b {p_b:g} Pa)")


def _march(p_a: float, u3: np.ndarray, b: np.ndarray, c: np.ndarray, q: float) -> tuple[float, float]:
    """(P at the inner edge, dP/dQ) for flow q; -inf if the pressure would fall below zero on the
    way (a gas has none: the flow is too large). Without that stop a ring with a small b after one
    that left P below -b would square its way back up, P_in(q) would not be monotone and the root
    search could settle on a flow no state has."""
    P, dP = p_a, 0.0
    sqrt = math.sqrt
    for bi, ci, ui in zip(reversed(b), reversed(c), reversed(u3)):
        w = (P + bi) ** 2 - 2.0 * ci * q / ui
        if w <= 0.0:
            return -math.inf, -math.inf
        root = sqrt(w)
        dP = ((P + bi) * dP - ci / ui) / root
        P = root - bi
        if P < 0.0:
            return -math.inf, -math.inf
    return P, dP


def _series_flows(p_a: float, p_b: np.ndarray, u3: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """`_series_flow` for the columns of u3, b (rings x states) with the rings' c, each column
    solved to the same tolerances by the same safeguarded Newton; a column's search stops when it
    has converged, and the last few (a march costs the same for one column as for hundreds) are
    finished one by one on Python floats."""
    k = c[:, None] / u3
    with np.errstate(over="ignore", invalid="ignore"):
        q_hi = np.min(u3 * ((p_a + b) ** 2 - (p_b + b) ** 2) / (2.0 * c[:, None]), axis=0)
    q_lin = (p_a - p_b) / np.sum(k / (0.5 * (p_a + p_b) + b), axis=0)
    q = np.where((0.0 < q_lin) & (q_lin < q_hi), q_lin, 0.5 * q_hi)
    lo, hi = np.zeros_like(q), q_hi.copy()
    noise = 1e-13 * (p_a + np.max(b, axis=0)) * math.sqrt(u3.shape[0])
    out = np.full(q.size, math.nan)
    todo = np.arange(q.size)
    for _ in range(100):
        if todo.size <= 8:
            for j in todo:
                out[j] = _series_flow(p_a, float(p_b[j]), u3[:, j], b[:, j], c)
            return out
        p_in, dp_dq = _march_columns(p_a, k[:, todo], b[:, todo], q)
        f = p_in - p_b[todo]
        done = np.abs(f) <= noise[todo]
        out[todo[done]] = q[done]
        lo, hi = np.where(f > 0.0, q, lo), np.where(f > 0.0, hi, q)
        with np.errstate(invalid="ignore", divide="ignore"):
            step = np.where(np.isfinite(dp_dq) & (dp_dq < 0), q - f / dp_dq, math.nan)
        q_new = np.where((lo < step) & (step < hi), step, 0.5 * (lo + hi))
        span = q_hi[todo]
        close = ~done & ((np.abs(q_new - q) <= 1e-13 * span) | (hi - lo <= 1e-14 * span))
        out[todo[close]] = q_new[close]
        keep = ~(done | close)
        if not keep.any():
            return out
        todo, q, lo, hi = todo[keep], q_new[keep], lo[keep], hi[keep]
    raise RuntimeError(f"profile leak: no convergence of the series flow (p_a {p_a:g} Pa, {todo.size} states)")


def _march_columns(p_a: float, k: np.ndarray, b: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`_march` for each column (k = c / u^3 and b per ring and state): (P_in, dP_in/dQ), -inf where
    the pressure would fall below zero on the way."""
    P, dP = np.full(q.size, p_a), np.zeros(q.size)
    dead = np.zeros(q.size, dtype=bool)
    two_q = 2.0 * q
    with np.errstate(invalid="ignore", divide="ignore"):
        for i in range(k.shape[0] - 1, -1, -1):
            Pb = P + b[i]
            w = Pb * Pb - two_q * k[i]
            dead |= w <= 0.0
            root = np.sqrt(w)
            dP = (Pb * dP - k[i]) / root
            P = root - b[i]
            dead |= P < 0.0
    P[dead] = -math.inf
    dP[dead] = -math.inf
    return P, dP


def profile_liquid_rate(viscosity_Pa_s: float, p_a: float, p_b: float, r_m: np.ndarray,
                        gaps_m: np.ndarray, radial: str = "annulus") -> float:
    """Volume flow [m^3/s] of an incompressible liquid through the rings (eq 24 in series)."""
    u = np.asarray(gaps_m, dtype=float)
    g = _geometry(np.asarray(r_m, dtype=float), radial)
    if np.any(u <= 0.0):
        return 0.0
    resist = np.isfinite(u)
    if not resist.any():
        raise ValueError("gaps_m: no ring of the profile is in contact (the cavity is open)")
    R = float(np.sum(12.0 * viscosity_Pa_s * g[resist] / (2.0 * math.pi * u[resist] ** 3)))
    return (p_a - p_b) / R
