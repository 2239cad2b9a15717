"""What the leak crosses: the paper's uniform strip (eq 6), or the contact-pressure profile p(r).

Both answer `flow(u, r, l, p_b, kappa, E) -> (Ndot, p, u_c, ballistic share)` at one state of the
cup (plate displacement u = h1 - h, inner contact radius r, strip width l, cavity pressure p_b,
stiffness factor kappa, modulus E for p/E); Ndot is molecules/s for air and m^3/s for a liquid.

- `StripSeal` (the paper's route): one strip of width l at p = kappa F0 / (2 pi r l) + beta (p_a - p_b)
  (eq 6), u_c(p/E), the flow of eqs (9), (19), (23) or (24) with L_y / L_x = 2 pi r / l. A strip
  width of 0 is a line contact: the pressure is unbounded and the interface sealed there.
- `ProfileSeal` (the profile route): the curve's profile at the samples u_k around u, each scaled
  by kappa and raised by beta (p_a - p_b), crossed ring by ring (`reduced.profile_leak`); between
  samples the flow is interpolated linearly in ln Ndot (leak rates vary exponentially with the
  pressure), linearly where one side is sealed. `p` reports the peak contact pressure and `u_c`
  the narrowest ring's gap, the critical constriction.

  When the u_c table carries a patch length L (`UcTable.patch_length_m`: for a table made from a
  spectrum the smallest patch on which u_c is the whole spectrum's) the pressure that enters u_c is the nominal one of
  rough-contact theory, the profile averaged over patches of width L (`profile_leak.patch_average`,
  the module docstring there says why), and the averaged profile carries the curve's force: at
  sample k it is kappa F0_k A[p_k] / F(A[p_k]) (A: the patch average, F: its force 2 pi int p r dr),
  raised by beta (p_a - p_b) on the nominal contact, the points within L/2 of a loaded sample
  (`profile_leak.patch_contact`: the patches that hold contact; a lone loaded node's is L wide).
  The suction's share is a pressure on the contact, as in eq 6, not a load to spread: averaged, a
  lone node's share would be its tributary length over L and vanish under refinement, and added on
  the average's support it would act on L plus the node's two element lengths. The FEM's lumped
  nodal pressures do not integrate to the contact force where the load is concentrated (the vertex
  and midpoint nodes of a quadratic facet and the off-plane neighbours' radii weigh a lone loaded
  corner node wrongly), while F0 is that force by equilibrium; so the
  profile supplies the shape and F0 the load, as eq (6) takes F0 and the width l. Without a patch
  length (a table from a CSV without the line, a callable) the raw profile is used as before;
  `patch_length_m` overrides the table's (0: off).

  Flow tables (`tabulate_at=(kappa, E)`, set by the force balance without relaxation): at one
  (kappa, E) a sample's flow depends on p_b alone, so it is tabulated once per sample (`PbTable`)
  and the ODE's right-hand side (`rate`) reads it; states off the table's grid, another (kappa, E)
  or a u_c without a vectorised form are solved directly, as every state is without the tables.
  `sealed` answers whether `flow` would report u_c <= 0 without solving the flow.
"""

from __future__ import annotations

import math
from bisect import bisect_right

import numpy as np

from reduced.fast_curve import spline_coefficients
from reduced.gas import Gas, ballistic_share, interpolated_leak_rate, liquid_volume_rate
from reduced.profile_leak import (ContactProfile, patch_average, patch_contact, profile_leak_rate,
                                  profile_leak_rates, profile_liquid_rate, ring_gaps)
from reduced.stiffness_curve import StiffnessCurve

__all__ = ["StripSeal", "ProfileSeal", "PbTable", "SEALS"]

SEALS = ("strip", "profile")


class StripSeal:
    """Eq (6)'s uniform strip (module docstring)."""

    def __init__(self, curve: StiffnessCurve, u_c, gas: Gas, p_a: float, beta: float,
                 liquid_viscosity: float | None):
        self.uc, self.gas, self.pa, self.beta = getattr(u_c, "scalar", u_c), gas, p_a, beta
        self.mu = liquid_viscosity

    def width(self, l: float) -> float:
        """The width of the strip a point of the cup crosses (eq 10's l): the strip's own."""
        return l

    def flow(self, F: float, r: float, l: float, pb: float, kappa: float, E: float, u: float):
        """(Ndot, p, u_c, ballistic share) with the stiffness force F = F0(h) [N]."""
        if l <= 0.0:             # a line contact: eq (6)'s pressure is unbounded, u_c = 0 (sealed)
            return 0.0, math.inf, 0.0, 0.0
        p = kappa * F / (2.0 * math.pi * r * l) + self.beta * (self.pa - pb)
        uc = self.uc(p / E)
        if self.mu is not None:
            return liquid_volume_rate(self.mu, self.pa, pb, uc, 2.0 * math.pi * r / l), p, uc, 0.0
        return (interpolated_leak_rate(self.gas, self.pa, pb, uc, 2.0 * math.pi * r / l), p, uc,
                ballistic_share(self.gas, self.pa, pb, uc))

    def rate(self, F: float, r: float, l: float, pb: float, kappa: float, E: float, u: float) -> float:
        """Ndot alone (`flow`'s first entry)."""
        return self.flow(F, r, l, pb, kappa, E, u)[0]

    def sealed(self, F: float, r: float, l: float, pb: float, kappa: float, E: float, u: float) -> bool:
        """Whether `flow` reports u_c <= 0 (a line contact, or eq 6's pressure at or above sealing)."""
        return l <= 0.0 or self.uc((kappa * F / (2.0 * math.pi * r * l) + self.beta * (self.pa - pb)) / E) <= 0.0

    def cannot_seal(self, kappa: float, E: float) -> bool:
        """Never known in advance: eq (6)'s pressure is unbounded as l -> 0."""
        return False


class ProfileSeal:
    """The contact-pressure profile of the curve's samples (module docstring)."""

    def __init__(self, curve: StiffnessCurve, u_c, gas: Gas, p_a: float, beta: float,
                 liquid_viscosity: float | None, patch_length_m: float | None = None,
                 tabulate_at: tuple[float, float] | None = None):
        if curve.profiles is None or all(p is None for p in curve.profiles):
            raise ValueError(f"seal: 'profile' needs the stiffness curve's contact-pressure profiles; "
                             f"'{curve.provenance.get('source', '?')}' has none (an FEM curve's sidecar "
                             f"carries them)")
        self.u, self.profiles, self.F0 = curve.u_m, curve.profiles, curve.F0_N
        self._u_list = [float(x) for x in curve.u_m]
        self.uc, self.gas, self.pa, self.beta, self.mu = u_c, gas, p_a, beta, liquid_viscosity
        L = getattr(u_c, "patch_length_m", None) if patch_length_m is None else patch_length_m
        if L is not None and not (math.isfinite(L) and L >= 0.0):
            raise ValueError(f"patch_length_m: must be finite and >= 0 (0: no averaging), got {L}")
        self.patch_length_m = L if L else None
        self._averaged: dict[int, tuple[ContactProfile, np.ndarray]] = {}
        # the flow tables need a vectorised u_c (a UcTable) and one (kappa, E) for every evaluation
        self.tabulate_at = tabulate_at if hasattr(u_c, "values") else None
        self._tables: dict[int, PbTable | None] = {}
        self._peaks: dict[int, tuple[float, float, float, bool, float]] = {}
        if self.tabulate_at is not None:      # u_c falls with p everywhere (a PCHIP keeps the rows' order)
            rows = np.asarray(u_c.u_c_m)[np.argsort(u_c.p_over_E)]
            self._monotone = bool(np.all(np.diff(rows[rows > 0]) < 0)) and hasattr(u_c, "scalar")
        else:
            self._monotone = False

    def width(self, l: float) -> float:
        """The width of the strip a point of the cup crosses (eq 10's l): the FEM's strip, at least
        one patch (the nominal contact of a lone loaded node is L wide, `patch_contact`); without a
        patch length the FEM's, 0 where the rim corner alone touches."""
        return max(l, self.patch_length_m) if self.patch_length_m else l

    def _ends(self, u: float) -> tuple[list[int], list[float]]:
        """The samples around u that have a profile, and their weights (linear in u)."""
        us = self._u_list
        k = min(max(bisect_right(us, u) - 1, 0), len(us) - 2)
        w = min(max((u - us[k]) / (us[k + 1] - us[k]), 0.0), 1.0)
        ends = [j for j in (k, k + 1) if self.profiles[j] is not None]
        if not ends:
            raise ValueError(f"seal: no contact-pressure profile at u = {1e3 * u:.4g} mm (neither "
                             f"sample {k} nor {k + 1} touches the plane)")
        return ends, ([1.0 - w, w] if len(ends) == 2 else [1.0])

    @staticmethod
    def _combine(weights: list[float], q: list[float]) -> float:
        """Ndot between the samples: linear in ln Ndot, linear where one side is sealed."""
        if all(x > 0 for x in q):
            return math.exp(sum(a * math.log(x) for a, x in zip(weights, q)))
        return sum(a * x for a, x in zip(weights, q))

    def flow(self, F: float, r: float, l: float, pb: float, kappa: float, E: float, u: float):
        ends, weights = self._ends(u)
        q, peak, gap = [], [], []
        for j in ends:
            x = self._tabulated(j, pb, kappa, E)
            top = self._top_x(j, pb, kappa, E) if x is not None and self._monotone else None
            if top is None:
                prof, gaps, p = self._rings(j, pb, kappa, E)
                q.append(self._direct(prof, gaps, pb) if x is None else x)
                peak.append(p)
                gap.append(float(np.min(gaps)))
            else:        # u_c falls with p: the narrowest gap is at the highest ring pressure
                q.append(x)
                peak.append(kappa * self._peak(j)[4] + self.beta * (self.pa - pb))
                gap.append(self.uc.scalar(top))
        Ndot = self._combine(weights, q)
        p = sum(a * x for a, x in zip(weights, peak))
        uc = min(gap) if Ndot == 0 else sum(a * g for a, g in zip(weights, gap))
        share = 0.0 if self.mu is not None or uc <= 0 else ballistic_share(self.gas, self.pa, pb, uc)
        return Ndot, p, uc, share

    def rate(self, F: float, r: float, l: float, pb: float, kappa: float, E: float, u: float) -> float:
        """Ndot alone (`flow`'s first entry), from the flow tables where they hold."""
        ends, weights = self._ends(u)
        q = []
        for j in ends:
            x = self._tabulated(j, pb, kappa, E)
            q.append(self._direct(*self._rings(j, pb, kappa, E)[:2], pb) if x is None else x)
        return self._combine(weights, q)

    def sealed(self, F: float, r: float, l: float, pb: float, kappa: float, E: float, u: float) -> bool:
        """Whether `flow` reports u_c <= 0 (some ring sealed where Ndot vanishes), without the flow:
        a UcTable seals at and above its sealing p/E, so a sample's narrowest gap is 0 exactly when
        its highest ring pressure reaches it."""
        ends, weights = self._ends(u)
        closed = [self._closed(j, pb, kappa, E) for j in ends]
        no_drive = pb >= self.pa if self.mu is None else pb == self.pa
        stopped = all(a == 0.0 or c or no_drive for a, c in zip(weights, closed))
        return stopped and any(closed)

    def cannot_seal(self, kappa: float, E: float) -> bool:
        """True if no state with 0 <= p_b can seal any sample (a UcTable's sealing p/E above every
        ring's pressure under the full suction share beta p_a); rounding is monotone, so the bound
        holds exactly."""
        seal = getattr(self.uc, "sealing_p_over_E", None)
        if seal is None or not hasattr(self.uc, "values"):
            return False
        top = max(self._peak(k)[2] if self.patch_length_m is None else max(self._peak(k)[:2])
                  for k, p in enumerate(self.profiles) if p is not None)
        return (kappa * top + self.beta * self.pa) / E < seal

    def _closed(self, k: int, pb: float, kappa: float, E: float) -> bool:
        """min over sample k's rings of the gap <= 0."""
        seal = getattr(self.uc, "sealing_p_over_E", None)
        if seal is not None and hasattr(self.uc, "values"):
            x = self._top_x(k, pb, kappa, E)
            if x is not None:
                return x >= seal
        return float(np.min(self._rings(k, pb, kappa, E)[1])) <= 0.0

    def _top_x(self, k: int, pb: float, kappa: float, E: float) -> float | None:
        """The largest p/E of sample k's touching rings, as `ring_gaps` forms it (rounding is
        monotone: it is at the largest ring-middle pressure); None for p_b > p_a or no touching ring."""
        extra = self.beta * (self.pa - pb)
        if extra < 0.0:
            return None
        top_contact, top_free, top_touching, any_contact, _ = self._peak(k)
        if self.patch_length_m is None:
            x = (kappa * top_touching + extra) / E if top_touching > 0 else -math.inf
        elif extra > 0.0:
            x = max((kappa * top_contact + extra) / E if any_contact else -math.inf,
                    (kappa * top_free) / E if top_free > 0 else -math.inf)
        else:
            x = (kappa * top_touching) / E if top_touching > 0 else -math.inf
        return x if x > -math.inf else None

    def _peak(self, k: int) -> tuple[float, float, float, bool, float]:
        """Sample k's largest ring-middle pressure on the nominal contact, off it (touching) and on
        all touching rings, whether any ring is in the nominal contact, and the profile's peak."""
        if k not in self._peaks:
            prof, contact = self.averaged(k) if self.patch_length_m is not None else (self.profiles[k], None)
            p = prof.p_Pa
            mid = 0.5 * (p[1:] + p[:-1])
            touching = (p[1:] > 0) | (p[:-1] > 0)
            contact = np.zeros(mid.size, dtype=bool) if contact is None else contact
            top = lambda m: float(m.max()) if m.size else 0.0       # noqa: E731
            self._peaks[k] = (top(mid[contact]), top(mid[touching & ~contact]), top(mid[touching]),
                              bool(contact.any()), float(p.max()))
        return self._peaks[k]

    def _rings(self, k: int, pb: float, kappa: float, E: float) -> tuple[ContactProfile, np.ndarray, float]:
        """(profile, ring gaps, peak pressure) of sample k at this state."""
        prof = self.profiles[k]
        extra = self.beta * (self.pa - pb)
        if self.patch_length_m is None:
            gaps = ring_gaps(prof, self.uc, E, scale=kappa, extra_Pa=extra)
        else:
            prof, contact = self.averaged(k)
            gaps = ring_gaps(prof, self.uc, E, scale=kappa, extra_Pa=np.where(contact, extra, 0.0))
        return prof, gaps, kappa * float(prof.p_Pa.max()) + extra

    def _direct(self, prof: ContactProfile, gaps: np.ndarray, pb: float) -> float:
        """The flow through the rings, solved at this state."""
        if self.mu is not None:
            return profile_liquid_rate(self.mu, self.pa, pb, prof.r_m, gaps)
        # p_b < 0 only at trial states off the branch (the fold search): no gas inside
        return profile_leak_rate(self.gas, self.pa, min(max(pb, 0.0), self.pa), prof.r_m, gaps)

    def _at(self, k: int, pb: float, kappa: float, E: float) -> tuple[float, float, float]:
        """(flow, peak pressure, narrowest gap) through sample k's profile, solved directly."""
        prof, gaps, peak = self._rings(k, pb, kappa, E)
        return self._direct(prof, gaps, pb), peak, float(np.min(gaps))

    def _tabulated(self, k: int, pb: float, kappa: float, E: float) -> float | None:
        """Sample k's flow from its table, or None where there is none (`PbTable`)."""
        if self.tabulate_at is None or (kappa, E) != self.tabulate_at or not 0.0 <= pb < self.pa:
            return None
        if k not in self._tables:
            self._tables[k] = self._tabulate(k)
        table = self._tables[k]
        return None if table is None else table(self.pa - pb)

    def _tabulate(self, k: int) -> PbTable | None:
        """Sample k's flow on the p_b grid of `PbTable`, solved for all of its states at once."""
        kappa, E = self.tabulate_at
        delta = self.pa * np.exp(PbTable.TAU)
        pb = self.pa - delta
        extra = self.beta * (self.pa - pb)
        prof, on = self.averaged(k) if self.patch_length_m is not None else (self.profiles[k], None)
        p = prof.p_Pa
        mid = 0.5 * (p[1:] + p[:-1])
        touching = (p[1:] > 0) | (p[:-1] > 0)
        if on is None:           # the raw profile: the suction's share on every touching ring
            on = touching
        touching = touching | on     # every state here has extra > 0
        x = (kappa * mid[touching, None] + np.where(on[touching, None], extra[None, :], 0.0)) / E
        # where a ring reaches the table's last open row u_c turns into a straight fall to 0 (a kink):
        # the table stops below that, and states beyond are solved directly
        open_rows = np.asarray(self.uc.p_over_E)[np.asarray(self.uc.u_c_m) > 0]
        ok = np.max(x, axis=0) < (open_rows.max() if np.isfinite(self.uc.sealing_p_over_E) else math.inf)
        n = int(np.argmin(ok)) if not ok.all() else ok.size
        if n < 8 or not touching.any():
            return None
        gaps = np.full((mid.size, n), math.inf)
        gaps[touching] = self.uc.values(x[:, :n].reshape(-1)).reshape(-1, n)
        if self.mu is not None:
            g = np.log(prof.r_m[1:] / prof.r_m[:-1])[touching]
            q = delta[:n] / np.sum(12.0 * self.mu * g[:, None] / (2.0 * math.pi * gaps[touching] ** 3), axis=0)
        else:
            q = profile_leak_rates(self.gas, self.pa, pb[:n], prof.r_m, gaps)
        if not np.all(q > 0):
            return None
        return PbTable(PbTable.TAU[:n], np.log(q / delta[:n]), self.pa)

    def averaged(self, k: int) -> tuple[ContactProfile, np.ndarray]:
        """Sample k's profile averaged over the patches and carrying F0_k, and which of its rings are
        in the nominal contact (module docstring)."""
        if k not in self._averaged:
            prof, L = self.profiles[k], self.patch_length_m
            avg = patch_average(prof, L)
            F, F0 = avg.force_N, float(self.F0[k])
            scale = F0 / F if F > 0 and math.isfinite(F0) and F0 > 0 else 1.0
            self._averaged[k] = (ContactProfile(avg.r_m, scale * avg.p_Pa), patch_contact(prof, L, avg.r_m))
        return self._averaged[k]


class PbTable:
    """One sample's flow against the cavity pressure at a fixed (kappa, E): the flow over the
    pressure drop, Q / (p_a - p_b), as a cubic spline of its logarithm in tau = ln((p_a - p_b) / p_a).

    The ring gaps follow p_b through eq (6)'s beta (p_a - p_b) and u_c's log-log table, so the flow
    is smooth in tau (the rings loaded by the suction alone have power-law gaps as p_b -> p_a),
    C1 at u_c's rows. The grid is fine where the cup lives (p_b up to 99.3 % of p_a: tau >= -5) and
    coarser down to tau = -14 (p_a - p_b = 0.08 Pa, where the direct solution's round-off reaches
    1e-4 of the flow); it stops at p_b = 0.1 % of p_a (at p_b = 0 the flow chokes, P_in(Q) has an
    infinite slope and the root search bisects). Outside the grid the flow is solved directly.
    """

    TAU = np.unique(np.concatenate([np.arange(-14.0, -5.0, 0.1), np.linspace(-5.0, math.log(0.999), 251)]))

    def __init__(self, tau: np.ndarray, log_ratio: np.ndarray, p_a: float):
        x, c = spline_coefficients(tau, log_ratio)     # scipy's CubicSpline, without its import
        self.x = [float(v) for v in x]
        self.c3, self.c2, self.c1, self.c0 = ([float(v) for v in row] for row in c)
        self.lo, self.hi, self.pa = self.x[0], self.x[-1], p_a

    def __call__(self, drop: float) -> float | None:
        """Q [1/s or m^3/s] at p_a - p_b = drop [Pa] > 0, None outside the grid."""
        t = math.log(drop / self.pa)
        if not self.lo <= t <= self.hi:
            return None
        i = min(bisect_right(self.x, t) - 1, len(self.x) - 2)
        d = t - self.x[i]
        return drop * math.exp(self.c0[i] + d * (self.c1[i] + d * (self.c2[i] + d * self.c3[i])))
