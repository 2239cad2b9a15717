"""The linear solves of Newton's method: K du = b on the free dofs, by a banded Cholesky factorization.

The cross-sections are thin strips: ordered along the strip, the tangent's band is a few element
columns wide (half bandwidth kd ~ 3 x 2 x nodes through the thickness), and LAPACK's banded
Cholesky (``pbtrf``, cost n kd^2) beats a general sparse LU several times over (benchmarks/bench_fem.py).
The ordering is computed once per mesh, the narrowest band of three candidates:

* the wall ordering (`wall_ordering`, for a mesh tagged ``top_plate`` and ``cavity``): the nodes
  sorted by their graph distance from the plate edge, then from the cavity face. On a mapped
  mesh this is exactly column by column through the thickness, so an element couples three
  adjacent columns and kd = 2 (2 n_c + 3) - 1 for n_c nodes per column: the smallest band a
  strip ordering can have, whatever the taper, grading or slant of the columns;
* the nodes sorted along the principal axis of the node cloud (the strip's length), which
  interleaves neighbouring columns where they are slanted against the axis (about 1.8 times the
  band of the wall ordering on the cups' graded meshes);
* reverse Cuthill-McKee (a user's unstructured mesh of any shape).

Constrained dofs (prescribed displacements, contact) are eliminated in place: their rows and
columns are zeroed and the diagonal set to one, so the band keeps its size and the entries map
from the assembled CSR data to the band by a fixed index table; nothing is copied or converted
per iteration but the data itself.

The LAPACK calls run on one BLAS thread (threadpoolctl): a band of kd ~ 40-140 is too narrow for
OpenBLAS's threads to pay, and when the other core is busy they spin: the medium cup A run took
7.1 s with the default two threads against 2.0 s with one on the 2-core machine under load.

Cholesky needs the free block K_ff positive definite, which is exactly the condition for the
Newton direction to descend in energy. When it is not (a structural instability: buckling,
snap-through), `NotPositiveDefinite` is raised and the caller may shift the diagonal.
"""

from __future__ import annotations

import contextlib
import functools

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra, reverse_cuthill_mckee
from skfem import Mesh
from threadpoolctl import ThreadpoolController

__all__ = ["BandedCholesky", "BorderedFactor", "Factor", "NotPositiveDefinite", "solve_at", "strip_ordering",
           "wall_ordering"]


class NotPositiveDefinite(np.linalg.LinAlgError):
    """The free block of the tangent (plus the shift) is not positive definite."""


@functools.cache
def _blas_libraries() -> tuple:
    """threadpoolctl's controllers of the loaded BLAS libraries (found once)."""
    return tuple(ThreadpoolController().select(user_api="blas").lib_controllers)


@contextlib.contextmanager
def _one_thread():
    """A context that limits BLAS/LAPACK to one thread (a few us: only the libraries that run
    more threads are set, through threadpoolctl's controllers, and restored afterwards)."""
    changed = [(lib, n) for lib in _blas_libraries() if (n := lib.get_num_threads()) != 1]
    for lib, _ in changed:
        lib.set_num_threads(1)
    try:
        yield
    finally:
        for lib, n in changed:
            lib.set_num_threads(n)


def strip_ordering(coordinates: np.ndarray, pattern: sp.csr_matrix,
                   mesh: Mesh | None = None) -> np.ndarray:
    """A dof permutation with a narrow band (dofs 2n, 2n + 1 per node): the narrowest of the wall
    ordering of `mesh` (if it has the tags), the nodes along the principal axis of `coordinates`
    [2, nnodes], and reverse Cuthill-McKee of `pattern` (module docstring)."""
    X = coordinates - coordinates.mean(axis=1, keepdims=True)
    axis = np.linalg.eigh(X @ X.T)[1][:, -1]
    candidates = [_node_dofs(np.argsort(axis @ X, kind="stable")),
                  reverse_cuthill_mckee(sp.csr_matrix(pattern), symmetric_mode=True).astype(np.int64)]
    wall = wall_ordering(mesh) if mesh is not None else None
    if wall is not None and len(wall) == coordinates.shape[1]:
        candidates.insert(0, _node_dofs(wall))
    return min(candidates, key=lambda p: _half_bandwidth(pattern, p))


def wall_ordering(mesh: Mesh, along_from: str = "top_plate", across_from: str = "cavity") -> np.ndarray | None:
    """The mesh nodes sorted by graph distance (over element edges) from the boundary
    `along_from`, then from `across_from`; None if the mesh lacks either tag.

    Distances are counted on the vertex graph; a mid-side node takes the mean of its edge's two
    vertices, an interior node that of its element's vertices (scikit-fem numbers the quadratic
    nodes vertices, then facets, then element interiors), so on a mapped quadrilateral mesh the
    keys are the lattice indices (i, j) of every node and the ordering runs column by column."""
    boundaries = getattr(mesh, "boundaries", None) or {}
    if along_from not in boundaries or across_from not in boundaries:
        return None
    nv = int(mesh.t.max()) + 1
    graph = sp.coo_matrix((np.ones(mesh.facets.shape[1]), (mesh.facets[0], mesh.facets[1])),
                          shape=(nv, nv)).tocsr()

    def distance(name: str) -> np.ndarray:
        sources = np.unique(mesh.facets[:, boundaries[name]])
        d = dijkstra(graph, directed=False, indices=sources, unweighted=True, min_only=True)
        return np.concatenate([d, d[mesh.facets].mean(axis=0), d[mesh.t].mean(axis=0)])

    along, across = distance(along_from), distance(across_from)
    nodes = mesh.doflocs.shape[1]
    if not np.all(np.isfinite(along)) or len(along) < nodes:
        return None                  # a disconnected mesh, or a node layout not understood
    return np.lexsort((across[:nodes], along[:nodes]))


def _node_dofs(nodes: np.ndarray) -> np.ndarray:
    return np.ravel(np.column_stack([2 * nodes, 2 * nodes + 1])).astype(np.int64)


def _half_bandwidth(pattern: sp.csr_matrix, perm: np.ndarray) -> int:
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    rows = np.repeat(np.arange(pattern.shape[0]), np.diff(pattern.indptr))
    return int(np.max(np.abs(inv[rows] - inv[pattern.indices])))


def solve_at(factor, rows: np.ndarray, values: np.ndarray, dofs: np.ndarray, n: int) -> np.ndarray:
    """x = K_ff^-1 b at `dofs`, [len(dofs), m], for b [n, m] with the rows `values` at `rows` and
    zero elsewhere: the factor's own `solve_at` (`Factor.solve_at`) where it has one, else its
    whole solve, read at `dofs`."""
    at = getattr(factor, "solve_at", None)
    if at is not None:
        return at(rows, values, dofs)
    b = np.zeros((n, values.shape[1]))
    b[rows] = values
    return factor.solve(b)[dofs]


class BandedCholesky:
    """Solver for K du = b with du prescribed on some dofs, K symmetric with a fixed CSR pattern."""

    def __init__(self, pattern: sp.csr_matrix, coordinates: np.ndarray | None, mesh: Mesh | None = None,
                 *, perm: np.ndarray | None = None):
        """`perm`: the dof ordering, if given; otherwise `strip_ordering` of the coordinates [2, nnodes]."""
        n = pattern.shape[0]
        perm = strip_ordering(coordinates, pattern, mesh) if perm is None else np.asarray(perm)
        inv = np.empty_like(perm)
        inv[perm] = np.arange(n)
        rows = np.repeat(np.arange(n), np.diff(pattern.indptr))
        pi, pj = inv[rows], inv[pattern.indices]
        upper = pi <= pj                                     # band storage of the upper triangle
        self.n, self.kd = n, int(np.max(pj - pi))
        self._indptr, self._indices = pattern.indptr, pattern.indices
        self._sel = np.flatnonzero(upper)
        # flat index into ab [kd + 1, n] in Fortran order, the layout LAPACK takes without a copy
        self._band = (self.kd + pi[upper] - pj[upper]) + (self.kd + 1) * pj[upper]
        self._perm, self._inv = perm, inv

    def factor(self, K: sp.csr_matrix, free: np.ndarray, shift: float = 0.0) -> "Factor":
        """Factor K_ff (+ shift diag(K_ff), a Levenberg-Marquardt regularization) with the
        constrained dofs (~free) eliminated. Raises `NotPositiveDefinite` if it is not."""
        if K.nnz != len(self._indices) or K.shape[0] != self.n:
            raise ValueError("BandedCholesky: the matrix does not have the pattern it was built for")
        return Factor(self, K, free, self.band_factor(K.data, free, shift), shift)

    @property
    def position(self) -> np.ndarray:
        """The band position of each dof."""
        return self._inv

    @property
    def upper_entries(self) -> np.ndarray:
        """The positions in the pattern's CSR data of the entries the band holds (the upper
        triangle in the band's ordering), in the order `upper_band_factor` takes them."""
        return self._sel

    def band_factor(self, data: np.ndarray, free: np.ndarray, shift: float = 0.0) -> np.ndarray:
        """The banded Cholesky factor of K_ff from the CSR `data` of K (the pattern's layout)."""
        return self.upper_band_factor(data[self._sel], free, shift)

    def upper_band_factor(self, upper: np.ndarray, free: np.ndarray, shift: float = 0.0) -> np.ndarray:
        """`band_factor` from K's entries at `upper_entries` only."""
        ab = np.zeros((self.kd + 1) * self.n)
        ab[self._band] = upper
        ab = ab.reshape((self.kd + 1, self.n), order="F")
        fixed_p = ~free[self._perm]
        at = np.flatnonzero(fixed_p)                           # the constrained rows and columns
        ab[:, at] = 0.0
        offset = np.arange(self.kd + 1)                        # row i is ab[kd - o, i + o]
        cols = at[:, None] + offset
        inside = cols < self.n
        ab[np.broadcast_to(self.kd - offset, cols.shape)[inside], cols[inside]] = 0.0
        diag = ab[self.kd]                                     # a view, in permuted order
        if shift:
            diag += shift * np.where(fixed_p, 0.0, np.abs(diag))
        diag[fixed_p] = 1.0
        try:
            with _one_thread():
                return sla.cholesky_banded(ab, overwrite_ab=True, lower=False, check_finite=False)
        except np.linalg.LinAlgError as err:
            raise NotPositiveDefinite(str(err)) from None

    def band_solve(self, c: np.ndarray, b: np.ndarray) -> np.ndarray:
        """x = K_ff^-1 b with a factor of `band_factor` (b zero on the constrained dofs)."""
        with _one_thread():
            x = sla.cho_solve_banded((c, False), b[self._perm], overwrite_b=True, check_finite=False)
        return x[self._inv]

    def tail_solve(self, c: np.ndarray, positions: np.ndarray, values: np.ndarray,
                   start: int) -> np.ndarray:
        """x = K_ff^-1 b at the band positions >= `start`, [n - start, m], for b with the rows
        `values` [len(positions), m] at `positions` (>= start; repeated ones summed) and zero
        elsewhere: both triangular sweeps run on the factor's trailing block alone (forward, x
        is zero before `start`; backward, x at a position needs x only after it)."""
        b = np.zeros((self.n - start, values.shape[1]))
        if len(positions):                       # the sums of repeated positions, in their order
            order = np.argsort(positions, kind="stable")
            at, first = np.unique(positions[order], return_index=True)
            b[at - start] = np.add.reduceat(values[order], first, axis=0)
        if start >= self.n:
            return b
        with _one_thread():
            return sla.cho_solve_banded((c[:, start:], False), b, overwrite_b=True, check_finite=False)

    def solve(self, K: sp.csr_matrix, rhs: np.ndarray, free: np.ndarray, du_fixed: np.ndarray,
              shift: float = 0.0) -> np.ndarray:
        """du with K_ff du_f = rhs_f - K_fc du_fixed_c and du_c = du_fixed_c on the constrained dofs
        (~free). Raises `NotPositiveDefinite` (see `factor`)."""
        return self.factor(K, free, shift).solve(rhs, du_fixed)


class Factor:
    """A factored free block K_ff; `solve` for one or several right-hand sides."""

    def __init__(self, owner: BandedCholesky, K: sp.csr_matrix, free: np.ndarray, c: np.ndarray,
                 shift: float = 0.0):
        self._owner, self._K, self.free, self._c, self.shift = owner, K, free, c, shift

    def solve(self, rhs: np.ndarray, du_fixed: np.ndarray | None = None) -> np.ndarray:
        """x with K_ff x_f = rhs_f - K_fc du_fixed_c, x_c = du_fixed_c (0 if None); rhs [n] or [n, m]."""
        return self._owner.band_solve(self._c, _constrained_rhs(self._K, self.free, rhs, du_fixed))

    def solve_at(self, rows: np.ndarray, values: np.ndarray, dofs: np.ndarray) -> np.ndarray:
        """x = K_ff^-1 b at `dofs` only, [len(dofs), m], for the right-hand side b with the rows
        `values` [len(rows), m] at the distinct dofs `rows` and zero elsewhere (constrained rows
        dropped; a constrained dof's x is 0): the sweeps run from the first band position that
        `rows` and `dofs` reach (`BandedCholesky.tail_solve`). A few contact rows at the band's
        end (the cup's rim) cost a fraction of a whole solve, and nothing of size n is formed."""
        o = self._owner
        values = np.where(self.free[rows][:, None], values, 0.0)
        pos, at = o.position[rows], o.position[dofs]
        start = int(min(pos.min(initial=o.n), at.min(initial=o.n)))
        return o.tail_solve(self._c, pos, values, start)[at - start]

    def freeing(self, dofs: np.ndarray) -> "BorderedFactor":
        """The factor of the free block with the constrained `dofs` freed as well (e.g. contact
        nodes let go), by the Schur complement on them: len(dofs) solves with this factor instead
        of a new factorization. Raises `NotPositiveDefinite` if the larger block is not."""
        return BorderedFactor(self, np.asarray(dofs))


class BorderedFactor:
    """The block [[K_ff, K_fT], [K_Tf, K_TT]] of a `Factor` bordered by the dofs T:
    with Y = K_ff^-1 K_fT and the Schur complement S = K_TT - K_Tf Y (Cholesky, m x m),
    x_T = S^-1 (b_T - K_Tf K_ff^-1 b_f) and x_f = K_ff^-1 b_f - Y x_T. The base factor's diagonal
    shift is applied to K_TT as well."""

    def __init__(self, base: Factor, dofs: np.ndarray):
        if np.any(base.free[dofs]):
            raise ValueError("BorderedFactor: the dofs to free must be constrained in the base factor")
        K = base._K
        self._base, self._dofs, self._K = base, dofs, K
        self.free = base.free.copy()
        self.free[dofs] = True
        self._cols = K[:, dofs].toarray()                     # K_:T
        self._cols[~base.free] = 0.0                           # K_fT
        self._Y = base.solve(self._cols)                       # K_ff^-1 K_fT, zero off f
        K_TT = K[dofs][:, dofs].toarray()
        S = K_TT - self._cols.T @ self._Y
        S[np.diag_indices_from(S)] += base.shift * np.abs(np.diag(K_TT))
        try:
            self._S = sla.cho_factor(S, check_finite=False)
        except np.linalg.LinAlgError as err:
            raise NotPositiveDefinite(f"Schur complement of the freed dofs: {err}") from None

    def solve(self, rhs: np.ndarray, du_fixed: np.ndarray | None = None) -> np.ndarray:
        """As `Factor.solve`, on the larger free block."""
        b = _constrained_rhs(self._K, self.free, rhs, du_fixed)
        x = self._base.solve(b)                                # K_ff^-1 b_f (b_T masked out)
        xT = sla.cho_solve(self._S, b[self._dofs] - self._cols.T @ x, check_finite=False)
        x -= self._Y @ xT
        x[self._dofs] = xT
        if du_fixed is not None:
            fixed = ~self.free
            x[fixed] = du_fixed[fixed] if rhs.ndim == 1 else du_fixed[fixed, None]
        return x


def _constrained_rhs(K: sp.csr_matrix, free: np.ndarray, rhs: np.ndarray,
                     du_fixed: np.ndarray | None) -> np.ndarray:
    """rhs - K du_fixed on the free dofs and du_fixed on the constrained ones (0 if None)."""
    fixed = ~free
    mask = fixed if rhs.ndim == 1 else fixed[:, None]
    if du_fixed is None:
        return np.where(mask, 0.0, rhs)
    moved = np.where(fixed, du_fixed, 0.0)
    b = rhs - K @ moved if moved.any() else rhs      # a finite K @ 0 is +0: rhs - 0 is rhs
    return np.where(mask, du_fixed if rhs.ndim == 1 else du_fixed[:, None], b)
