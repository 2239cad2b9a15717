"""The cup material: a compressible neo-Hookean solid, written for the axisymmetric deformation gradient.

Strain energy per unit reference volume (the documented default law)::

    W(F) = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,     I1 = tr(F^T F),  J = det F,

with the Lame constants from Young's modulus and Poisson's ratio,
mu = E / (2 (1 + nu)), lambda = E nu / ((1 + nu)(1 - 2 nu)). It reduces to Hooke's law for small strain.

In an axisymmetric, torsion-free deformation F = [[F_rR, F_rZ, 0], [F_zR, F_zZ, 0], [0, 0, F_tt]], so
F is stored as the 5-vector ``f = (F_rR, F_rZ, F_zR, F_zZ, F_tt)`` (leading axis), and every function
here works on arrays ``f[5, ...]`` over elements and quadrature points. Splitting

    W = W_iso + U(J),   W_iso = mu/2 (I1 - 3) - mu ln J,   U = lambda/2 (ln J)^2

the first Piola-Kirchhoff stress and its derivative (the material tangent) are

    P = mu f + (dW/dJ) g,                 g = dJ/df = J F^-T in 5-vector form,
    A = mu 1 + (d2W/dJ2) g (x) g + (dW/dJ) H,    H = d2J/df2 (constant pattern, linear in f).

``formulation="mixed"`` keeps W_iso at the quadrature points but evaluates U on the dilatation J
projected onto discontinuous linear polynomials per element (Q2-P1disc, a three-field Hu-Washizu
form condensed per element; see `fem.forms`). It is the same law for every state whose J is linear
over each element, and it does not lock as nu -> 1/2.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from .kinematics import IDENTITY

__all__ = ["NeoHookean", "jacobian", "jacobian_minus_one", "jacobian_gradient", "jacobian_hessian",
           "jacobian_hessian_entries", "tangent_points_first", "cauchy_stress"]

Formulation = Literal["displacement", "mixed"]


@dataclass(frozen=True)
class NeoHookean:
    """Compressible neo-Hookean material (module docstring), from E [Pa] and nu [-]."""

    E_Pa: float = 4.0e6
    nu: float = 0.49
    formulation: Formulation = "displacement"

    def __post_init__(self) -> None:
        if not (np.isfinite(self.E_Pa) and self.E_Pa > 0):
            raise ValueError(f"E_Pa: Young's modulus must be > 0 Pa, got {self.E_Pa}")
        if not (-1.0 < self.nu < 0.5):
            raise ValueError(f"nu: Poisson's ratio must be in (-1, 0.5), got {self.nu}")
        if self.formulation not in ("displacement", "mixed"):
            raise ValueError(
                f"formulation: must be 'displacement' or 'mixed', got {self.formulation!r}")

    @property
    def mu(self) -> float:
        """Shear modulus mu = E / (2 (1 + nu)) [Pa]."""
        return self.E_Pa / (2.0 * (1.0 + self.nu))

    @property
    def lam(self) -> float:
        """First Lame constant lambda = E nu / ((1 + nu)(1 - 2 nu)) [Pa]."""
        return self.E_Pa * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    # --- the split W = W_iso(f) + U(J) -------------------------------------------------------
    def volumetric(self, J: np.ndarray, lnJ: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """U(J) = lambda/2 (ln J)^2 and its first two derivatives (lnJ may be passed if known
        more accurately than log(J), e.g. as log1p(J - 1))."""
        lnJ = np.log(J) if lnJ is None else lnJ
        return (0.5 * self.lam * lnJ**2, self.lam * lnJ / J, self.lam * (1.0 - lnJ) / J**2)

    def isochoric(self, f: np.ndarray, h: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """W_iso = mu/2 (I1 - 3) - mu ln J: energy, stress P_iso[5, ...], tangent A_iso[5, 5, ...].

        The energy is evaluated from the displacement gradient h = f - 1 (pass it if known more
        accurately than f - 1) without cancellation: with j = J - 1,
        W_iso = mu (tr h - j) + mu (j - ln(1 + j)) + mu/2 |h|^2, every term O(h^2)."""
        J = jacobian(f)
        g = jacobian_gradient(f)
        mu = self.mu
        h = _displacement_gradient(f) if h is None else h
        W = self.isochoric_energy(h)
        dW, d2W = -mu / J, mu / J**2
        P = self.stress_with(f, g, dW)
        A = np.moveaxis(tangent_points_first(f, g, mu, d2W, dW), (-2, -1), (0, 1))
        return W, P, A

    def isochoric_energy(self, h: np.ndarray) -> np.ndarray:
        """W_iso from the displacement gradient h = f - 1, without cancellation (`isochoric`)."""
        mu = self.mu
        # tr h - j = -(h0 h3 - h1 h2) - a h4 with a = J_2D - 1 (exact algebra, no cancellation)
        a = _planar_jacobian_minus_one(h)
        return mu * (-(h[0] * h[3] - h[1] * h[2]) - a * h[4] + _x_minus_log1p(jacobian_minus_one(h))) \
            + 0.5 * mu * np.sum(h**2, axis=0)

    def tangent_coefficients(self, J: np.ndarray, lnJ: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The whole law (displacement formulation) as P = mu f + b g and
        A = mu 1 + a g (x) g + b H (module docstring): a = d2W/dJ2 = (mu + lambda (1 - ln J)) / J^2
        and b = dW/dJ = (lambda ln J - mu) / J."""
        _, dU, d2U = self.volumetric(J, lnJ)
        return self.mu / J**2 + d2U, -self.mu / J + dU

    def stress_with(self, f: np.ndarray, g: np.ndarray, dW_dJ: np.ndarray) -> np.ndarray:
        """P = mu f + (dW/dJ) g with g = dJ/df: the stress of the whole law or of a part of it."""
        return self.mu * f + dW_dJ * g

    def energy(self, f: np.ndarray, h: np.ndarray | None = None) -> np.ndarray:
        """W(F) per unit reference volume [J/m^3] (pointwise, all terms; h = f - 1 if known)."""
        h = _displacement_gradient(f) if h is None else h
        return self.isochoric_energy(h) + self.volumetric(jacobian(f), np.log1p(jacobian_minus_one(h)))[0]

    def stress(self, f: np.ndarray) -> np.ndarray:
        """First Piola-Kirchhoff stress P = dW/dF as a 5-vector [Pa] (pointwise, all terms)."""
        J = jacobian(f)
        return self.stress_with(f, jacobian_gradient(f), self.tangent_coefficients(J, np.log(J))[1])

    def tangent(self, f: np.ndarray) -> np.ndarray:
        """Material tangent A = d2W/dF2 as a 5x5 matrix [Pa] (pointwise, all terms)."""
        J = jacobian(f)
        a, b = self.tangent_coefficients(J, np.log(J))
        return np.moveaxis(tangent_points_first(f, jacobian_gradient(f), self.mu, a, b), (-2, -1), (0, 1))


def tangent_points_first(f: np.ndarray, g: np.ndarray, c0: float | np.ndarray, a: np.ndarray,
                         b: np.ndarray) -> np.ndarray:
    """c0 1 + a g (x) g + b d2J/df2 at every point, [..., 5, 5] (points first, the element kernels'
    layout): the form of every tangent of this law (module docstring), with c0 = mu for the whole
    law or its isochoric part (times dV if the kernels want it)."""
    gp = np.moveaxis(g, 0, -1)                                        # [..., 5]
    A = (np.asarray(a)[..., None] * gp)[..., :, None] * gp[..., None, :]
    diagonal = np.arange(5)
    A[..., diagonal, diagonal] += np.asarray(c0)[..., None]
    for (i, j), v in jacobian_hessian_entries(f).items():
        bv = b * v
        A[..., i, j] += bv
        A[..., j, i] += bv
    return A


def _displacement_gradient(f: np.ndarray) -> np.ndarray:
    """h = f - 1 (the 5-vector convention of `fem.kinematics`)."""
    return f - IDENTITY.reshape((5,) + (1,) * (f.ndim - 1))


def _planar_jacobian_minus_one(h: np.ndarray) -> np.ndarray:
    """det of the in-plane 2x2 block of F, minus one, from h (exact algebra, no cancellation)."""
    return h[0] + h[3] + h[0] * h[3] - h[1] * h[2]


def jacobian_minus_one(h: np.ndarray) -> np.ndarray:
    """J - 1 from the displacement gradient h = f - 1, without cancellation for small h."""
    a = _planar_jacobian_minus_one(h)
    return a + h[4] + a * h[4]


def _x_minus_log1p(x: np.ndarray) -> np.ndarray:
    """x - ln(1 + x), by its series for |x| < 0.1 (no cancellation; truncation < 1e-13 relative)."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 0.1
    xs = np.where(small, x, 0.0)
    series = np.zeros_like(xs)
    term = xs * xs
    for k in range(2, 16):
        series += term / k if k % 2 == 0 else -term / k
        term = term * xs
    return np.where(small, series, x - np.log1p(np.where(small, 0.0, x)))


def jacobian(f: np.ndarray) -> np.ndarray:
    """J = det F = (F_rR F_zZ - F_rZ F_zR) F_tt."""
    return (f[0] * f[3] - f[1] * f[2]) * f[4]


def jacobian_gradient(f: np.ndarray) -> np.ndarray:
    """dJ/df, i.e. the cofactor J F^-T in 5-vector form."""
    return np.stack([f[3] * f[4], -f[2] * f[4], -f[1] * f[4], f[0] * f[4],
                     f[0] * f[3] - f[1] * f[2]])


def jacobian_hessian(f: np.ndarray) -> np.ndarray:
    """d2J/df2 [5, 5, ...]: J is trilinear in f, so H is linear in f."""
    H = np.zeros((5, 5) + f.shape[1:])
    for (a, b), v in jacobian_hessian_entries(f).items():
        H[a, b] = v
        H[b, a] = v
    return H


def jacobian_hessian_entries(f: np.ndarray) -> dict[tuple[int, int], np.ndarray]:
    """The nonzero entries (a, b), a < b, of the symmetric d2J/df2 (its diagonal is zero)."""
    return {(0, 3): f[4], (1, 2): -f[4], (0, 4): f[3], (3, 4): f[0], (1, 4): -f[2], (2, 4): -f[1]}


def cauchy_stress(f: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Cauchy stress sigma = P F^T / J as (s_rr, s_zz, s_tt, s_rz) [Pa]."""
    J = jacobian(f)
    s_rr = (P[0] * f[0] + P[1] * f[1]) / J
    s_zz = (P[2] * f[2] + P[3] * f[3]) / J
    s_rz = (P[0] * f[2] + P[1] * f[3]) / J
    s_tt = P[4] * f[4] / J
    return np.stack([s_rr, s_zz, s_tt, s_rz])
