"""A compact periodic boundary-element contact solver: the second method behind Persson's u(p).

An elastic half-space (plane-strain modulus E*) is pressed on a rigid, periodic rough surface h(x, y)
at nominal pressure p. On a periodic N x N grid the surface displacement is
``w~(q) = 2 p~(q) / (E* |q|)`` (q != 0; the mean displacement is not defined for a periodic
half-space and is set to 0), the gap is ``g = d + w - h`` and the contact conditions are
``g >= 0, p >= 0, g p = 0`` with ``mean(p) = p_nominal``. They are solved by the constrained
conjugate-gradient method of Polonsky & Keer (Wear 231, 206 (1999)). The mean separation is
``mean(g) = d`` (mean h = mean w = 0), which is Persson's u.

Only numpy; used by the slow test `tests/test_rough_bem.py`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .spectrum import PowerSpectrum, _loglog_interp


class ContactSolverError(RuntimeError):
    """The Polonsky-Keer iteration did not converge."""


def random_surface(spectrum: PowerSpectrum, n: int, length_m: float, seed: int = 0,
                   exact_rms: bool = True) -> np.ndarray:
    """Periodic Gaussian surface [m] on an n x n grid of side `length_m` with isotropic C(q).

    Fourier amplitudes ``|h_q|^2 = C(q) (2 pi/L)^2`` (so that <h^2> = sum_q C (2pi/L)^2 = int d^2q C)
    with random phases; C is zero outside the spectrum's band. Mean removed; with `exact_rms` the
    realisation is rescaled to the spectrum's rms (removes most of the realisation scatter, which
    sits in the few longest-wavelength modes).
    """
    k = 2 * np.pi * np.fft.fftfreq(n, d=length_m / n)
    q = np.hypot(k[:, None], k[None, :])
    C = _loglog_interp(np.maximum(q, 1e-300).ravel(), spectrum.q_per_m, spectrum.C_m4).reshape(q.shape)
    amp = np.sqrt(C) * (2 * np.pi / length_m) * n * n
    phase = np.exp(2j * np.pi * np.random.default_rng(seed).random((n, n)))
    h = np.sqrt(2.0) * np.real(np.fft.ifft2(amp * phase))
    h -= h.mean()
    return h * (spectrum.h_rms_m() / h.std()) if exact_rms else h


@dataclass(frozen=True)
class ContactState:
    pressure_Pa: np.ndarray
    gap_m: np.ndarray
    iterations: int

    @property
    def contact_area_ratio(self) -> float:
        return float(np.mean(self.pressure_Pa > 0))

    @property
    def mean_separation_m(self) -> float:
        return float(np.mean(self.gap_m))


def solve_contact(h_m: np.ndarray, length_m: float, p_Pa: float, Estar_Pa: float,
                  tol: float = 1e-8, max_iter: int = 5000) -> ContactState:
    """Polonsky-Keer constrained CG for rigid rough `h_m` vs elastic half-space at mean pressure p.

    `h_m` is (nx, ny) on square cells; `length_m` is the period along the first axis.
    """
    nx, ny = h_m.shape
    dx = length_m / nx
    q = np.hypot(2 * np.pi * np.fft.fftfreq(nx, d=dx)[:, None],
                 2 * np.pi * np.fft.fftfreq(ny, d=dx)[None, :])
    with np.errstate(divide="ignore"):
        green = np.where(q > 0, 2.0 / (Estar_Pa * q), 0.0)

    def displacement(p):
        return np.real(np.fft.ifft2(green * np.fft.fft2(p)))

    p = np.full_like(h_m, p_Pa)
    t = np.zeros_like(h_m)
    G_old, delta = 1.0, 0.0
    for it in range(1, max_iter + 1):
        g = displacement(p) - h_m
        I = p > 0
        g -= g[I].mean()
        G = float(np.sum(g[I] ** 2))
        t = np.where(I, g + delta * (G / G_old) * t, 0.0)
        G_old = G
        r = displacement(t)
        r -= r[I].mean()
        denom = float(np.sum(r[I] * t[I]))
        tau = float(np.sum(g[I] * t[I])) / denom if denom != 0 else 0.0
        p_prev = p.copy()
        p = np.where(I, p - tau * t, 0.0)
        p[p < 0] = 0.0
        overlap = (p == 0) & (g < 0)
        if np.any(overlap):
            delta = 0.0
            p[overlap] -= tau * g[overlap]
        else:
            delta = 1.0
        p *= p_Pa / p.mean()
        err = float(np.sum(np.abs(p - p_prev))) / (p_Pa * p.size)
        if err < tol:
            g = displacement(p) - h_m
            g -= g[p > 0].mean()
            return ContactState(p, np.maximum(g, 0.0), it)
    raise ContactSolverError(f"Polonsky-Keer: no convergence in {max_iter} iterations at "
                             f"p = {p_Pa:g} Pa (last relative pressure change {err:.2e}); "
                             f"refine the grid or loosen tol")
