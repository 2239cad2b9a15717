"""Persson contact mechanics without adhesion: the spectrum's moments, contact area and mean separation.

Notation (Persson convention, see `reduced.roughness.spectrum`): ``E* = E/(1 - nu^2)``,
``p* = p/E*``, ``m(q) = int_{q0}^{q} q'^3 C(q') dq'`` (so ``h'_rms^2 = 2 pi m(q1)``).

* Contact area at magnification zeta = q/q0 (Persson, J. Chem. Phys. 115, 3840 (2001)):
  ``A(zeta)/A0 = erf(1/(2 sqrt(G)))``, ``G = (pi/4)(E*/p)^2 m(zeta q0)``, i.e.
  ``A/A0 = erf(p*/sqrt(pi m))``; at full magnification ``erf(sqrt(2) p*/h'_rms)``.
* Mean separation with the gamma correction (Yang & Persson, J. Phys.: Condens. Matter 20, 215214
  (2008)): ``u = sqrt(pi) int dq q^2 C w int_p^inf dp'/p' [gamma + 3(1-gamma) P^2] exp(-(w p'/E*)^2)``
  with ``w = (pi m(q))^(-1/2)`` and ``P(q, p') = erf(w p'/E*)``. With ``x = w p'/E*`` the inner
  integral is a universal function ``F(x0) = int_{x0}^inf dx/x [gamma + 3(1-gamma) erf(x)^2] e^(-x^2)``
  (``gamma E1(x0^2)/2`` plus a tabulated erf^2 part). With ``s = sqrt(m)`` the outer integral
  becomes ``u = 2 int F(p*/(sqrt(pi) s)) / q ds``, which has no endpoint singularity (``w``
  diverges at q0 like ``(q - q0)^(-1/2)``). Product integration in s: F is integrated exactly over
  each cell through its antiderivative ``int_0^s F(c/t) dt = c Phi(c/s)`` (closed form by parts,
  tabulated once in ln-ln form), 1/q by the trapezoid rule.
* Small-pressure asymptote: ``-du/dln p -> sqrt(pi) gamma int q^2 C w dq = 2 gamma int ds/q``.
Numerics: the input spectrum is integrated on its own grid (cumulative trapezoid in ln q); the
cumulative moments are kept on a working grid uniform in ln q (``n_q``, default 4096), and each mean-separation
integral runs on its own ``n_sub`` log-spaced nodes from its lower limit to q1 (defaults converged
to ~0.1 %, see tests/test_rough_persson.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .spectrum import PowerSpectrum

__all__ = ["effective_modulus", "separation_kernel", "Moments", "contact_area_ratio", "mean_separation", "small_pressure_slope", "noncontact_separation"]


def effective_modulus(E_Pa: float, nu: float) -> float:
    """Plane-strain modulus E* = E/(1 - nu^2) [Pa]."""
    if not E_Pa > 0:
        raise ValueError(f"E_Pa: Young's modulus must be > 0, got {E_Pa}")
    if not -1.0 < nu <= 0.5:
        raise ValueError(f"nu: Poisson ratio must be in (-1, 0.5], got {nu}")
    return E_Pa / (1.0 - nu ** 2)


# --------------------------------------------------------------------------------------------
# the universal inner integral F(x0)
# --------------------------------------------------------------------------------------------

# Tables on one uniform grid in ln x (index arithmetic instead of a search). F(6.5) ~ e^-42.
_LNX0, _LNX1, _NX = np.log(1e-15), np.log(6.5), 65536
_LNX = np.linspace(_LNX0, _LNX1, _NX)
_DLNX = _LNX[1] - _LNX[0]


def _tail_integral(g: np.ndarray) -> np.ndarray:
    """int_{x_i}^{x_end} g d(ln x) on _LNX, summed from the top (keeps tiny tails accurate)."""
    seg = 0.5 * (g[1:] + g[:-1]) * _DLNX
    out = np.zeros_like(g)
    out[:-1] = np.cumsum(seg[::-1])[::-1]
    return out


@lru_cache(maxsize=1)
def _erf2_tails() -> tuple[np.ndarray, np.ndarray]:
    """J(x0) = int_{x0}^inf erf^2 e^(-x^2) dx/x and K(x0) = int_{x0}^inf erf^2 e^(-x^2) dx/x^2."""
    from scipy.special import erf     # here: scipy.special costs ~0.3 s to import
    x = np.exp(_LNX)
    g = erf(x) ** 2 * np.exp(-x ** 2)
    return _tail_integral(g), _tail_integral(g / x)


@lru_cache(maxsize=8)
def _tables(gamma: float) -> tuple[np.ndarray, np.ndarray]:
    """F(x) and ln Phi(x) on _LNX, with Phi(x) = (1/c) int_0^(c/x) F(c/t) dt (see below)."""
    from scipy.special import erfc, exp1     # here: scipy.special costs ~0.3 s to import
    x = np.exp(_LNX)
    J, K = _erf2_tails()
    F = gamma * 0.5 * exp1(x ** 2) + 3.0 * (1.0 - gamma) * J
    # integration by parts, F'(x) = -[gamma + 3(1-gamma) erf^2] e^(-x^2)/x:
    # Phi = F/x - Psi, Psi = int_x^inf [..] e^(-t^2) dt/t^2 = gamma (e^(-x^2)/x - sqrt(pi) erfc x) + 3(1-gamma) K
    Phi = F / x - gamma * (np.exp(-x ** 2) / x - np.sqrt(np.pi) * erfc(x)) - 3.0 * (1.0 - gamma) * K
    # Phi > 0; where round-off of the (tiny) large-x tail makes it <= 0 use 0 (ln -> -inf)
    with np.errstate(divide="ignore"):
        return F, np.log(np.where(Phi > 0, Phi, 0.0))


def _lerp_uniform(lnx: np.ndarray, table: np.ndarray) -> np.ndarray:
    """Linear interpolation of `table` on _LNX; clamped to its first/last value outside."""
    t = np.clip((lnx - _LNX0) / _DLNX, 0.0, _NX - 1.000001)
    i = t.astype(np.intp)
    f = t - i
    return table[i] * (1.0 - f) + table[i + 1] * f


def separation_kernel(x0: np.ndarray, gamma: float) -> np.ndarray:
    """F(x0) = int_{x0}^inf dx/x [gamma + 3(1-gamma) erf(x)^2] exp(-x^2); F(inf) = 0."""
    with np.errstate(divide="ignore"):
        lnx = np.log(x0)
    F = _lerp_uniform(np.nan_to_num(lnx, nan=_LNX1, posinf=_LNX1), _tables(float(gamma))[0])
    return np.where(lnx < _LNX1, F, 0.0)


def _kernel_antiderivative(s: np.ndarray, c: np.ndarray, gamma: float) -> np.ndarray:
    """I(s) = int_0^s F(c/t) dt = c Phi(c/s), Phi tabulated in ln-ln form; I(0) = 0.

    Used as a product-integration rule: F(c/s) switches on within s ~ c, far inside the first
    grid cell at small pressure, which a trapezoid rule in s would resolve badly.
    """
    with np.errstate(divide="ignore"):
        lnx = np.log(c) - np.log(s)                      # +inf where s = 0
    ln_phi = _lerp_uniform(np.minimum(lnx, _LNX1), _tables(float(gamma))[1])
    return np.where(lnx < _LNX1, c * np.exp(ln_phi), 0.0)


# --------------------------------------------------------------------------------------------
# working grid
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Moments:
    """Cumulative moments of C on a working grid uniform in ln q (all SI; default 4096 nodes or
    the input's size if larger; the input's own cumulative integrals are interpolated onto it).

    ``m[i] = int_{q0}^{q_i} q^3 C dq`` and ``tail_ms[i] = 2 pi int_{q_i}^{q1} q C dq`` (the
    mean-square height of the roughness not yet resolved at magnification q_i/q0).
    """

    q: np.ndarray
    m: np.ndarray
    tail_ms: np.ndarray

    @classmethod
    def of(cls, spectrum: PowerSpectrum, n_q: int | None = None) -> "Moments":
        qf = spectrum.q_per_m
        mf = spectrum.moment(2) / (2 * np.pi)
        msf = spectrum.moment(0)
        n = max(4096, qf.size) if n_q is None else n_q
        q = np.geomspace(qf[0], qf[-1], n)            # uniform in ln q: lookups by index
        m = np.interp(np.log(q), np.log(qf), mf)
        ms = np.interp(np.log(q), np.log(qf), msf)
        return cls(q, m, ms[-1] - ms)

    def m_at(self, lnq: np.ndarray) -> np.ndarray:
        """m at ln q (linear in ln q between the uniform working nodes; clamped to [q0, q1])."""
        lnq0 = np.log(self.q[0])
        step = (np.log(self.q[-1]) - lnq0) / (self.q.size - 1)
        t = np.clip((np.asarray(lnq) - lnq0) / step, 0.0, self.q.size - 1.000001)
        i = t.astype(np.intp)
        f = t - i
        return self.m[i] * (1.0 - f) + self.m[i + 1] * f

    def lnq_at_m(self, m: np.ndarray) -> np.ndarray:
        """Inverse of m(q) (m is non-decreasing; flat parts resolve to their lower end)."""
        keep = np.concatenate([[True], np.diff(self.m) > 0])
        return np.interp(m, self.m[keep], np.log(self.q[keep]))


def contact_area_ratio(m: np.ndarray, pstar: np.ndarray) -> np.ndarray:
    """A/A0 = erf(p*/sqrt(pi m)) (Persson 2001); 1 where m = 0."""
    from scipy.special import erf     # here: scipy.special costs ~0.3 s to import
    with np.errstate(divide="ignore"):
        return erf(pstar / np.sqrt(np.pi * np.maximum(m, 0.0)))


def mean_separation(mom: Moments, pstar: np.ndarray, lnq_lo: np.ndarray | float | None = None,
                    gamma: float = 0.45, n_sub: int = 192, chunk: int = 2048) -> np.ndarray:
    """Mean separation [m] of the roughness between exp(lnq_lo) and q1 under pressure p* (module doc).

    `pstar` and `lnq_lo` broadcast to one shape; ``lnq_lo = ln q0`` (default) is the full surface
    (Yang & Persson 2008). Each evaluation runs on its own `n_sub` log-spaced nodes from
    exp(lnq_lo) to q1 (m interpolated from the working grid), so u(zeta) is smooth in zeta.
    """
    lnq0, lnq1 = np.log(mom.q[0]), np.log(mom.q[-1])
    lnq_lo = lnq0 if lnq_lo is None else lnq_lo
    pstar, lnq_lo = np.broadcast_arrays(np.asarray(pstar, float), np.asarray(lnq_lo, float))
    shape = pstar.shape
    pstar, lnq_lo = pstar.ravel(), np.clip(lnq_lo.ravel(), lnq0, lnq1)
    t = np.linspace(0.0, 1.0, n_sub)
    out = np.empty(pstar.size)
    for a in range(0, pstar.size, chunk):
        b = min(a + chunk, pstar.size)
        lnq = lnq_lo[a:b, None] + (lnq1 - lnq_lo[a:b, None]) * t[None, :]
        s = np.sqrt(np.maximum(mom.m_at(lnq) - mom.m_at(lnq_lo[a:b, None]), 0.0))
        dI = np.diff(_kernel_antiderivative(s, pstar[a:b, None] / np.sqrt(np.pi), gamma), axis=1)
        inv_q = np.exp(-lnq)
        out[a:b] = 2.0 * np.sum(dI * 0.5 * (inv_q[:, 1:] + inv_q[:, :-1]), axis=1)
    return out.reshape(shape)


def small_pressure_slope(mom: Moments, gamma: float = 0.45) -> float:
    """Closed-form limit of -du/dln p as p -> 0: sqrt(pi) gamma int q^2 C w dq = 2 gamma int ds/q."""
    s = np.sqrt(mom.m)
    f = 1.0 / mom.q
    return float(gamma * np.sum((f[1:] + f[:-1]) * np.diff(s)))


def noncontact_separation(mom: Moments, pstar: np.ndarray, lnq: np.ndarray,
                          gamma: float = 0.45, delta: float | None = None) -> np.ndarray:
    """u1(zeta) [m] at magnification q = exp(lnq)/q0 and nominal pressure p* (arrays broadcast).

    ``u1 = u(zeta) + A(zeta) du/dA`` with central differences of width 2 delta in ln zeta (module doc).
    """
    lnq0, lnq1 = np.log(mom.q[0]), np.log(mom.q[-1])
    delta = min(0.01 if delta is None else delta, (lnq1 - lnq0) / 4)
    pstar, lnq = np.broadcast_arrays(np.asarray(pstar, float), np.asarray(lnq, float))
    lo = np.clip(lnq - delta, lnq0, lnq1 - 2 * delta)
    pts = np.stack([lo, lnq, lo + 2 * delta])                 # (3, ...)
    A = contact_area_ratio(mom.m_at(pts), pstar[None])
    u = mean_separation(mom, pstar[None] / np.maximum(A, 1e-300), pts, gamma)
    dA = A[2] - A[0]
    safe = dA < 0
    slope = np.where(safe, (u[2] - u[0]) / np.where(safe, dA, -1.0), 0.0)
    return u[1] + A[1] * slope
