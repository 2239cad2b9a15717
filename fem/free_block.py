"""Solves with the free block of a tangent, (R K)_ff x_f = b_f, for a few right-hand sides at once.

The branch sensitivities of the held plate (`fem.gas_branch`) solve the tangent's free block with
the plate and the held contact dofs fixed; under Coulomb's law the sliding nodes' rows are
combined (R: r + mu s lambda = 0), which makes the block unsymmetric. Where R is the identity and
K_ff is positive definite, the mesh's own banded Cholesky factors it (`fem.condensation.make_solver`,
kept per mesh: its ordering and condensation maps are built once), ~4x cheaper than a sparse LU
with its fill-reducing ordering at every state; otherwise SuperLU factors it (K_ff need not be
definite where the gas alone holds the wall, nor symmetric with sliding rows).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .condensation import make_solver
from .kinematics import Kinematics
from .linsolve import NotPositiveDefinite

__all__ = ["solve_free_block"]


def solve_free_block(K: sp.csr_matrix, rows: sp.csr_matrix, free: np.ndarray, rhs: np.ndarray,
                     kin: Kinematics) -> np.ndarray:
    """x_f [n_free, m] with (rows @ K)_ff x_f = rhs [n_free, m]; K in the pattern of `kin`'s
    tangent, rows a row operator (the identity where no row is combined)."""
    if _is_identity(rows):
        try:
            factor = make_solver(K, kin.node_coordinates(), kin.mesh).factor(K, free)
        except NotPositiveDefinite:
            pass
        else:
            full = np.zeros((K.shape[0],) + rhs.shape[1:])
            full[free] = rhs
            return factor.solve(full)[free]
    return spla.splu((rows @ K)[free][:, free].tocsc()).solve(rhs)


def _is_identity(A: sp.csr_matrix) -> bool:
    A = sp.csr_matrix(A)
    n = A.shape[0]
    return A.shape == (n, n) and A.nnz == n and np.array_equal(A.indices, np.arange(n)) \
        and np.array_equal(A.indptr, np.arange(n + 1)) and bool(np.all(A.data == 1.0))
