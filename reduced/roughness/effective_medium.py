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
  (``n_zeta`` cells of equal area), the Gaussian average is Gauss-Hermite (``n_herm`` nodes).
* Bruggeman's rule in the form with a threshold: ``int P(u) (sigma(u) - sigma_eff)/(sigma(u) +
  kappa sigma_eff) du = 0`` with ``kappa = a_c/(1 - a_c)``. For ``kappa = 1`` (a_c = 1/2) this is the
  classic 2D Bruggeman equation of Lorenz & Persson; choosing kappa from the same threshold a_c
  (0.42, Dapp et al. 2012) as the critical-junction route makes both routes seal at exactly the same
  pressure (the 2D Bruggeman threshold 1/2 would seal later). sigma_eff -> 0 continuously at the
  threshold, whereas the critical-junction u_c jumps to 0 there.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial.hermite_e import hermegauss
from scipy.special import erfinv

from .persson import Moments, contact_area_ratio, noncontact_separation


def gap_distribution(mom: Moments, pstar: float, gamma: float = 0.45, n_zeta: int = 24,
                     n_herm: int = 16) -> tuple[np.ndarray, np.ndarray, float]:
    """Discrete P(u) of the open area: (u nodes [m], weights, contact fraction A1/A0).

    The weights sum to ``1 - A1/A0``; nodes/weights have shape (n_zeta * n_herm,).
    """
    u, w, A1 = _gap_nodes(mom, np.atleast_1d(float(pstar)), gamma, n_zeta, n_herm)
    return u[0].ravel(), w[0].ravel(), float(A1[0])


def _gap_nodes(mom: Moments, pstar: np.ndarray, gamma: float, n_zeta: int, n_herm: int):
    A1 = contact_area_ratio(mom.m[-1], pstar)                          # (Np,)
    frac = (np.arange(n_zeta) + 0.5) / n_zeta
    A_mid = 1.0 - frac[None, :] * (1.0 - A1[:, None])                  # (Np, Nz) cell centres
    m = (pstar[:, None] / erfinv(A_mid)) ** 2 / np.pi                  # A(zeta) = A_mid
    lnq = mom.lnq_at_m(np.minimum(m, mom.m[-1]))
    u1 = noncontact_separation(mom, pstar[:, None], lnq, gamma)
    h = np.sqrt(np.interp(lnq, np.log(mom.q), mom.tail_ms))
    xi, om = hermegauss(n_herm)
    om = om / om.sum()
    u = np.abs(u1[..., None] + h[..., None] * xi)                      # (Np, Nz, Nh)
    w = ((1.0 - A1) / n_zeta)[:, None, None] * om[None, None, :] * np.ones_like(u)
    return u, w, A1


def bruggeman_conductance(u3: np.ndarray, w: np.ndarray, A1: np.ndarray, a_c: float,
                          iterations: int = 100) -> np.ndarray:
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
                         n_zeta: int = 24, n_herm: int = 16, chunk: int = 50,
                         progress=None) -> tuple[np.ndarray, np.ndarray]:
    """(u_c [m], sealed): the EMT leak rate expressed as the equivalent critical-junction gap."""
    pstar = np.atleast_1d(np.asarray(pstar, float))
    A1 = contact_area_ratio(mom.m[-1], pstar)
    sealed = A1 >= a_c
    u_c = np.zeros(pstar.size)
    idx = np.flatnonzero(~sealed)
    for k in range(0, idx.size, chunk):
        sel = idx[k:k + chunk]
        u, w, a1 = _gap_nodes(mom, pstar[sel], gamma, n_zeta, n_herm)
        n = u.shape[0]
        u_c[sel] = np.cbrt(bruggeman_conductance(u.reshape(n, -1) ** 3, w.reshape(n, -1), a1, a_c))
        if progress is not None:
            progress(min(1.0, (k + sel.size) / max(idx.size, 1)), "effective-medium u_c")
    return u_c, sealed
