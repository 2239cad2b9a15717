"""Solves with the free block of a tangent, (R K)_ff x_f = b_f, for a few right-hand sides at once.

The branch sensitivities of the held plate (`fem.gas_branch`) solve the tangent's free block with
the plate and the held contact dofs fixed; under Coulomb's law the sliding nodes' rows are
combined with their normal rows (R = I + W: r + mu s lambda = 0), which makes the block
unsymmetric. Where K_ff is positive definite, the mesh's own banded Cholesky factors it
(`fem.condensation.make_solver`, kept per mesh: its ordering and condensation maps are built
once), ~4x cheaper than a sparse LU with its fill-reducing ordering at every state, and the k
combined rows S are added by the Woodbury identity,

    (K_ff + E_S V)^-1 b = y - Z (I + V Z)^-1 V y,   y = K_ff^-1 b,  Z = K_ff^-1 E_S,  V = (W K)_Sf,

Z read only at V's columns (`solve_at`: the sliding rows sit at the band's end), and x as one
more solve, K_ff x = b - E_S (I + V Z)^-1 V y, instead of k whole columns. Its result is accepted
where its componentwise backward error is at round-off (|R K x - b| <= 1e-9 (|R| |K| |x| + |b|));
otherwise, and where K_ff is not definite (the gas alone holding the wall), SuperLU factors
(R K)_ff itself.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .condensation import make_solver
from .kinematics import Kinematics
from .linsolve import NotPositiveDefinite, solve_at

__all__ = ["solve_free_block"]

BACKWARD_ERROR = 1e-9      # the componentwise backward error a Woodbury solve must meet


def solve_free_block(K: sp.csr_matrix, rows: sp.csr_matrix, free: np.ndarray, rhs: np.ndarray,
                     kin: Kinematics) -> np.ndarray:
    """x_f [n_free, m] with (rows @ K)_ff x_f = rhs [n_free, m]; K symmetric in the pattern of
    `kin`'s tangent, rows a row operator (the identity where no row is combined)."""
    n = K.shape[0]
    W = (sp.csr_matrix(rows) - sp.identity(n, format="csr")).tocsr()
    W.eliminate_zeros()
    S = np.flatnonzero(np.diff(W.indptr) > 0)
    S = S[free[S]]                                  # combined rows outside the block do not count
    try:
        factor = make_solver(K, kin.node_coordinates(), kin.mesh).factor(K, free)
    except NotPositiveDefinite:
        return _lu(K, rows, free, rhs)
    full = np.zeros((n,) + rhs.shape[1:])
    full[free] = rhs
    if S.size == 0:
        return factor.solve(full)[free]
    full2 = full.reshape(n, -1)
    Y = factor.solve(full2)                         # y, zero off f
    WK = (W[S] @ K).toarray()
    WK[:, ~free] = 0.0                               # V = (W K)_Sf
    reach = np.flatnonzero(WK.any(axis=0))          # V's columns: Z is read there only
    Z = solve_at(factor, S, np.eye(S.size), reach, n)
    try:
        C = np.linalg.solve(np.eye(S.size) + WK[:, reach] @ Z, WK @ Y)
    except np.linalg.LinAlgError:                   # a singular capacitance matrix
        return _lu(K, rows, free, rhs)
    b = full2.copy()
    b[S] -= C
    X = factor.solve(b)                             # y - Z C, one more solve of m columns
    R = sp.csr_matrix(rows)
    residual = R @ (K @ X) - full.reshape(n, -1)
    bound = abs(R) @ (abs(K) @ np.abs(X)) + np.abs(full.reshape(n, -1))
    if np.all(np.abs(residual[free]) <= BACKWARD_ERROR * bound[free]):
        return X[free].reshape(rhs.shape)
    return _lu(K, rows, free, rhs)


def _lu(K: sp.csr_matrix, rows: sp.csr_matrix, free: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    return spla.splu((rows @ K)[free][:, free].tocsc()).solve(rhs)
