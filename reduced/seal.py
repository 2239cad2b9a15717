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
"""

from __future__ import annotations

import math

import numpy as np

from reduced.gas import Gas, ballistic_share, interpolated_leak_rate, liquid_volume_rate
from reduced.profile_leak import (ContactProfile, patch_average, patch_contact, profile_leak_rate,
                                  profile_liquid_rate, ring_gaps)
from reduced.stiffness_curve import StiffnessCurve

__all__ = ["StripSeal", "ProfileSeal", "SEALS"]

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


class ProfileSeal:
    """The contact-pressure profile of the curve's samples (module docstring)."""

    def __init__(self, curve: StiffnessCurve, u_c, gas: Gas, p_a: float, beta: float,
                 liquid_viscosity: float | None, patch_length_m: float | None = None):
        if curve.profiles is None or all(p is None for p in curve.profiles):
            raise ValueError(f"seal: 'profile' needs the stiffness curve's contact-pressure profiles; "
                             f"'{curve.provenance.get('source', '?')}' has none (an FEM curve's sidecar "
                             f"carries them)")
        self.u, self.profiles, self.F0 = curve.u_m, curve.profiles, curve.F0_N
        self.uc, self.gas, self.pa, self.beta, self.mu = u_c, gas, p_a, beta, liquid_viscosity
        L = getattr(u_c, "patch_length_m", None) if patch_length_m is None else patch_length_m
        if L is not None and not (math.isfinite(L) and L >= 0.0):
            raise ValueError(f"patch_length_m: must be finite and >= 0 (0: no averaging), got {L}")
        self.patch_length_m = L if L else None
        self._averaged: dict[int, tuple[ContactProfile, np.ndarray]] = {}

    def width(self, l: float) -> float:
        """The width of the strip a point of the cup crosses (eq 10's l): the FEM's strip, at least
        one patch (the nominal contact of a lone loaded node is L wide, `patch_contact`); without a
        patch length the FEM's, 0 where the rim corner alone touches."""
        return max(l, self.patch_length_m) if self.patch_length_m else l

    def flow(self, F: float, r: float, l: float, pb: float, kappa: float, E: float, u: float):
        k = int(np.clip(np.searchsorted(self.u, u, side="right") - 1, 0, self.u.size - 2))
        w = min(max((u - self.u[k]) / (self.u[k + 1] - self.u[k]), 0.0), 1.0)
        ends = [self._at(j, pb, kappa, E) for j in (k, k + 1) if self.profiles[j] is not None]
        weights = [1.0 - w, w] if len(ends) == 2 else [1.0]
        if not ends:
            raise ValueError(f"seal: no contact-pressure profile at u = {1e3 * u:.4g} mm (neither "
                             f"sample {k} nor {k + 1} touches the plane)")
        q = [e[0] for e in ends]
        if all(x > 0 for x in q):
            Ndot = math.exp(sum(a * math.log(x) for a, x in zip(weights, q)))
        else:
            Ndot = sum(a * x for a, x in zip(weights, q))
        p = sum(a * e[1] for a, e in zip(weights, ends))
        uc = min(e[2] for e in ends) if Ndot == 0 else sum(a * e[2] for a, e in zip(weights, ends))
        share = 0.0 if self.mu is not None or uc <= 0 else ballistic_share(self.gas, self.pa, pb, uc)
        return Ndot, p, uc, share

    def _at(self, k: int, pb: float, kappa: float, E: float) -> tuple[float, float, float]:
        """(flow, peak pressure, narrowest gap) through sample k's profile."""
        prof = self.profiles[k]
        extra = self.beta * (self.pa - pb)
        if self.patch_length_m is None:
            gaps = ring_gaps(prof, self.uc, E, scale=kappa, extra_Pa=extra)
            peak = kappa * float(prof.p_Pa.max()) + extra
        else:
            prof, contact = self.averaged(k)
            gaps = ring_gaps(prof, self.uc, E, scale=kappa, extra_Pa=np.where(contact, extra, 0.0))
            peak = kappa * float(prof.p_Pa.max()) + extra
        if self.mu is not None:
            q = profile_liquid_rate(self.mu, self.pa, pb, prof.r_m, gaps)
        else:      # p_b < 0 only at trial states off the branch (the fold search): no gas inside
            q = profile_leak_rate(self.gas, self.pa, min(max(pb, 0.0), self.pa), prof.r_m, gaps)
        return q, peak, float(np.min(gaps))

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
