"""Effective-medium (Bruggeman) leak rate and its equivalent critical-junction gap.

Lorenz & Persson, Eur. Phys. J. E 31, 159 (2010) ("Leak rate of seals: effective-medium theory"):
the interface is a random mixture of local Reynolds conductances ``sigma(u) = u^3/(12 eta)`` with the
distribution ``P(u)`` of interfacial separations; the effective conductance ``sigma_eff`` gives the leak
rate ``Q = (L_y/L_x) sigma_eff dp``. Identifying it with the critical-junction expression, the
paper's eq. (24) ``Q = (L_y/L_x) u_c^3 dp/(12 eta)``, defines the equivalent gap
``u_c = (12 eta sigma_eff)^(1/3)`` (eta drops out). This is the route the paper used (Sec. 5.1,
"expected to be more accurate"), hence the default of `critical_gap_table`.

Choices where the literature leaves room (stated here once):

* ``P(u)`` (Almqvist, Campana, Prodanov & Persson, J. Mech. Phys. Solids 59, 2355 (2011), our
  reading): contact at full magnification, weight ``A1/A0``, at u = 0; the non-contact area
  ``-dA`` that appears at magnification zeta has separation ``u1(zeta)`` (see `persson`) spread by
  the roughness not yet resolved, a Gaussian of variance ``h^2(zeta) = 2 pi int_{zeta q0}^{q1} q C dq``
  reflected at u = 0 (the mirror term keeps u >= 0). The zeta integral is a midpoint rule in A
  (``n_zeta`` cells, graded); the Gaussians are binned exactly on a log grid in u, on which
  the Bruggeman integrand, smooth in ln u, is summed (`gap_distribution`).
* Bruggeman's rule in the form with a threshold: ``int P(u) (sigma(u) - sigma_eff)/(sigma(u) +
  kappa sigma_eff) du = 0`` with ``kappa = a_c/(1 - a_c)``. For ``kappa = 1`` (a_c = 1/2) this is the
  classic 2D Bruggeman equation of Lorenz & Persson; choosing kappa from the same threshold a_c
  (0.42, Dapp et al. 2012) as the critical-junction route makes both routes seal at exactly the same
  pressure (the 2D Bruggeman threshold 1/2 would seal later). Near the threshold
  sigma_eff ~ (1 - A1/a_c), so u_c ~ (distance)^(1/3); the critical-junction u_c also goes to 0
  there, but much faster (u1(zeta_c) -> 0 as zeta_c -> zeta1).
"""

from __future__ import annotations

import numpy as np

from .separation import Moments, contact_area_ratio, mean_separation


def gap_distribution(mom: Moments, pstar: np.ndarray, gamma: float = 0.45, n_zeta: int = 16,
                     n_u: int = 120, u_span: float = 1e-6,
                     n_sub: int = 128) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Binned P(u) of the open area: (u [m] per bin, weight per bin, A1/A0), one row per pressure.

    The ``n_zeta`` cells split [A1, 1] (graded towards both ends, where u1 varies fastest: cell
    edges at ``A = 1 - (1 - A1)(1 - cos(pi theta))/2``, theta uniform); cell j contributes a reflected
    Gaussian (centre u1 at the cell's midpoint, variance h^2 there). Its mass is binned exactly
    (folded-normal CDF) into ``n_u`` log-spaced bins spanning ``u_span`` to 1 times the largest
    ``u1 + 8h``; the mass below goes into the first bin. Row weights sum to ``1 - A1/A0``.
    ``u1`` at a cell midpoint uses the cell's edges for ``du/dA`` (same formula as `persson`);
    the separations use `n_sub` nodes each (128: within 0.1 % of 512, tests/test_rough_emt.py).
    """
    from scipy.special import erf, erfinv     # here: scipy.special costs ~0.3 s to import
    pstar = np.atleast_1d(np.asarray(pstar, float))
    A1 = contact_area_ratio(mom.m[-1], pstar)                               # (Np,)
    theta = np.linspace(0.0, 1.0, 2 * n_zeta + 1)                           # edges and midpoints
    frac = 0.5 * (1.0 - np.cos(np.pi * theta))                              # graded at both ends
    A = 1.0 - frac[None, :] * (1.0 - A1[:, None])                           # (Np, 2Nz+1)
    with np.errstate(divide="ignore"):
        m = (pstar[:, None] / erfinv(A)) ** 2 / np.pi                       # A(zeta) = A
    lnq = mom.lnq_at_m(np.minimum(m, mom.m[-1]))
    u = mean_separation(mom, pstar[:, None] / A, lnq, gamma, n_sub=n_sub)
    Am, um, lnqm = A[:, 1::2], u[:, 1::2], lnq[:, 1::2]
    u1 = um + Am * (u[:, 2::2] - u[:, 0:-1:2]) / (A[:, 2::2] - A[:, 0:-1:2])
    h = np.sqrt(np.interp(lnqm, np.log(mom.q), mom.tail_ms))
    top = np.max(u1 + 8 * h, axis=1)                                       # (Np,)
    edges = top[:, None] * np.geomspace(u_span, 1.0, n_u + 1)[None, :]     # (Np, Nu+1)
    z = np.sqrt(2.0) * np.maximum(h, 1e-300)[:, :, None]
    cdf = 0.5 * (erf((edges[:, None, :] - u1[..., None]) / z)
                 + erf((edges[:, None, :] + u1[..., None]) / z))            # (Np, Nz, Nu+1)
    dA = (1.0 - A1)[:, None] * np.diff(frac[::2])[None, :]                 # (Np, Nz)
    mass = np.einsum("pz,pzu->pu", dA, np.diff(cdf, axis=2))                # (Np, Nu)
    mass[:, 0] += np.sum(dA * cdf[:, :, 0], axis=1)
    centres = np.sqrt(edges[:, 1:] * edges[:, :-1])
    return centres, mass, A1


def bruggeman_conductance(u3: np.ndarray, w: np.ndarray, A1: np.ndarray, a_c: float,
                          iterations: int = 64) -> np.ndarray:
    """S = 12 eta sigma_eff [m^3]: root of sum w (u^3 - S)/(u^3 + kappa S) = A1/kappa per row.

    Rows are pressures (u3, w have shape (Np, n)); bisection in ln S, vectorised; S = 0 where the
    open area does not percolate (A1 >= a_c). The left side decreases monotonically in S.
    """
    kappa = a_c / (1.0 - a_c)
    top = np.log(np.maximum(u3.max(axis=1), 1e-300))
    lo, hi = top - 80.0, top.copy()
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        S = np.exp(mid)[:, None]
        f = np.sum(w * (u3 - S) / (u3 + kappa * S), axis=1) - A1 / kappa
        lo, hi = np.where(f > 0, mid, lo), np.where(f > 0, hi, mid)
    S = np.exp(0.5 * (lo + hi))
    return np.where(A1 >= a_c, 0.0, S)


def effective_medium_gap(mom: Moments, pstar: np.ndarray, gamma: float = 0.45, a_c: float = 0.42,
                         n_zeta: int = 16, n_u: int = 120, chunk: int = 40,
                         progress=None) -> tuple[np.ndarray, np.ndarray]:
    """(u_c [m], sealed): the EMT leak rate expressed as the equivalent critical-junction gap."""
    pstar = np.atleast_1d(np.asarray(pstar, float))
    A1 = contact_area_ratio(mom.m[-1], pstar)
    sealed = A1 >= a_c
    u_c = np.zeros(pstar.size)
    idx = np.flatnonzero(~sealed)
    for k in range(0, idx.size, chunk):
        sel = idx[k:k + chunk]
        u, w, a1 = gap_distribution(mom, pstar[sel], gamma, n_zeta, n_u)
        u_c[sel] = np.cbrt(bruggeman_conductance(u ** 3, w, a1, a_c))
        if progress is not None:
            progress(min(1.0, (k + sel.size) / max(idx.size, 1)), "effective-medium u_c")
    return u_c, sealed
