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
"""

from __future__ import annotations

import math

import numpy as np

from reduced.gas import Gas, ballistic_share, interpolated_leak_rate, liquid_volume_rate
from reduced.profile_leak import ring_gaps, profile_leak_rate, profile_liquid_rate
from reduced.stiffness_curve import StiffnessCurve

__all__ = ["StripSeal", "ProfileSeal", "SEALS"]

SEALS = ("strip", "profile")


class StripSeal:
    """Eq (6)'s uniform strip (module docstring)."""

    def __init__(self, curve: StiffnessCurve, u_c, gas: Gas, p_a: float, beta: float,
                 liquid_viscosity: float | None):
        self.uc, self.gas, self.pa, self.beta = getattr(u_c, "scalar", u_c), gas, p_a, beta
        self.mu = liquid_viscosity

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
                 liquid_viscosity: float | None):
        if curve.profiles is None or all(p is None for p in curve.profiles):
            raise ValueError(f"seal: 'profile' needs the stiffness curve's contact-pressure profiles; "
                             f"'{curve.provenance.get('source', '?')}' has none (an FEM curve's sidecar "
                             f"carries them)")
        self.u, self.profiles = curve.u_m, curve.profiles
        self.uc, self.gas, self.pa, self.beta, self.mu = u_c, gas, p_a, beta, liquid_viscosity

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
        gaps = ring_gaps(prof, self.uc, E, scale=kappa, extra_Pa=extra)
        if self.mu is not None:
            q = profile_liquid_rate(self.mu, self.pa, pb, prof.r_m, gaps)
        else:      # p_b < 0 only at trial states off the branch (the fold search): no gas inside
            q = profile_leak_rate(self.gas, self.pa, min(max(pb, 0.0), self.pa), prof.r_m, gaps)
        return q, kappa * float(prof.p_Pa.max()) + extra, float(np.min(gaps))
