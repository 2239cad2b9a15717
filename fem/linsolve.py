"""The linear solves of Newton's method: K du = b on the free dofs, by a banded Cholesky factorization.

The cross-sections are thin strips: ordered along the strip, the tangent's band is a few element
columns wide (half bandwidth kd ~ 3 x 2 x nodes through the thickness), and LAPACK's banded
Cholesky (``pbtrf``, cost n kd^2) beats a general sparse LU several times over (benchmarks/bench_fem.py).
The ordering is computed once per mesh: the nodes sorted along the principal axis of the node
cloud (the strip's length), or reverse Cuthill-McKee if that gives the narrower band (a user's
unstructured mesh of any shape).

Constrained dofs (prescribed displacements, contact) are eliminated in place: their rows and
columns are zeroed and the diagonal set to one, so the band keeps its size and the entries map
from the assembled CSR data to the band by a fixed index table; nothing is copied or converted
per iteration but the data itself.

Cholesky needs the free block K_ff positive definite, which is exactly the condition for the
Newton direction to descend in energy. When it is not (a structural instability: buckling,
snap-through), `NotPositiveDefinite` is raised and the caller may shift the diagonal.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.sparse.csgraph import reverse_cuthill_mckee

__all__ = ["BandedCholesky", "Factor", "NotPositiveDefinite", "strip_ordering"]


class NotPositiveDefinite(np.linalg.LinAlgError):
    """The free block of the tangent (plus the shift) is not positive definite."""


def strip_ordering(coordinates: np.ndarray, pattern: sp.csr_matrix) -> np.ndarray:
    """A dof permutation with a narrow band: nodes along the principal axis of `coordinates`
    [2, nnodes] (dofs 2n, 2n + 1 per node), or reverse Cuthill-McKee of `pattern`, whichever
    band is narrower."""
    X = coordinates - coordinates.mean(axis=1, keepdims=True)
    axis = np.linalg.eigh(X @ X.T)[1][:, -1]
    nodes = np.argsort(axis @ X, kind="stable")
    along = np.ravel(np.column_stack([2 * nodes, 2 * nodes + 1]))
    rcm = reverse_cuthill_mckee(sp.csr_matrix(pattern), symmetric_mode=True).astype(np.int64)
    return min((along, rcm), key=lambda p: _half_bandwidth(pattern, p))


def _half_bandwidth(pattern: sp.csr_matrix, perm: np.ndarray) -> int:
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    rows = np.repeat(np.arange(pattern.shape[0]), np.diff(pattern.indptr))
    return int(np.max(np.abs(inv[rows] - inv[pattern.indices])))


class BandedCholesky:
    """Solver for K du = b with du prescribed on some dofs, K symmetric with a fixed CSR pattern."""

    def __init__(self, pattern: sp.csr_matrix, coordinates: np.ndarray):
        n = pattern.shape[0]
        perm = strip_ordering(coordinates, pattern)
        inv = np.empty_like(perm)
        inv[perm] = np.arange(n)
        rows = np.repeat(np.arange(n), np.diff(pattern.indptr))
        pi, pj = inv[rows], inv[pattern.indices]
        upper = pi <= pj                                     # band storage of the upper triangle
        self.n, self.kd = n, int(np.max(pj - pi))
        self._indptr, self._indices = pattern.indptr, pattern.indices
        self._sel = np.flatnonzero(upper)
        self._rows, self._cols = rows[self._sel], pattern.indices[self._sel]
        self._band = (self.kd + pi[upper] - pj[upper]) * n + pj[upper]     # flat index into ab
        self._perm, self._inv = perm, inv

    def factor(self, K: sp.csr_matrix, free: np.ndarray, shift: float = 0.0) -> "Factor":
        """Factor K_ff (+ shift diag(K_ff), a Levenberg-Marquardt regularization) with the
        constrained dofs (~free) eliminated. Raises `NotPositiveDefinite` if it is not."""
        if K.nnz != len(self._indices) or K.shape[0] != self.n:
            raise ValueError("BandedCholesky: the matrix does not have the pattern it was built for")
        keep = free[self._rows] & free[self._cols]
        ab = np.zeros((self.kd + 1) * self.n)
        ab[self._band] = np.where(keep, K.data[self._sel], 0.0)
        ab = ab.reshape(self.kd + 1, self.n)
        diag = ab[self.kd]                                     # a view, in permuted order
        fixed_p = ~free[self._perm]
        if shift:
            diag += shift * np.where(fixed_p, 0.0, np.abs(diag))
        diag[fixed_p] = 1.0
        try:
            c = sla.cholesky_banded(ab, overwrite_ab=True, lower=False, check_finite=False)
        except np.linalg.LinAlgError as err:
            raise NotPositiveDefinite(str(err)) from None
        return Factor(self, K, free, c)

    def solve(self, K: sp.csr_matrix, rhs: np.ndarray, free: np.ndarray, du_fixed: np.ndarray,
              shift: float = 0.0) -> np.ndarray:
        """du with K_ff du_f = rhs_f - K_fc du_fixed_c and du_c = du_fixed_c on the constrained dofs
        (~free). Raises `NotPositiveDefinite` (see `factor`)."""
        return self.factor(K, free, shift).solve(rhs, du_fixed)


class Factor:
    """A factored free block K_ff; `solve` for one or several right-hand sides."""

    def __init__(self, owner: BandedCholesky, K: sp.csr_matrix, free: np.ndarray, c: np.ndarray):
        self._owner, self._K, self.free, self._c = owner, K, free, c

    def solve(self, rhs: np.ndarray, du_fixed: np.ndarray | None = None) -> np.ndarray:
        """x with K_ff x_f = rhs_f - K_fc du_fixed_c, x_c = du_fixed_c (0 if None); rhs [n] or [n, m]."""
        fixed = ~self.free
        mask = fixed if rhs.ndim == 1 else fixed[:, None]
        if du_fixed is None:
            b = np.where(mask, 0.0, rhs)
        else:
            b = rhs - self._K @ np.where(fixed, du_fixed, 0.0)
            b = np.where(fixed, du_fixed, b)
        x = sla.cho_solve_banded((self._c, False), b[self._owner._perm], overwrite_b=True,
                                 check_finite=False)
        return x[self._owner._inv]
