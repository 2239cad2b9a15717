"""Coulomb's linearized contact problem condensed onto the contact dofs (`CondensedProblem`),
which `fem.friction.FrictionStep` solves by the semismooth Newton method of its docstring."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .contact import ContactState, RigidPlane
from .linsolve import solve_at

__all__ = ["CondensedProblem"]

_SSN_ITERATIONS = 30    # active-set guesses per Newton iteration (a cycle ends there)


class CondensedProblem:
    """The linearized frictional contact problem on the contact dofs (module docstring).

    Rows: the z- and r-dofs of the `held` nodes, then the z-dofs of free nodes the step would
    push through the plane. A held node's dofs are constrained in the base factor, a free node's
    are not; the unknown of a row's column is then a displacement increment (the column: the
    body's response to a unit increment of the dof) or a force (to a unit force). With the base
    step du0 and the columns Z, du = du0 + Z y and the reactions at the rows are f = q + F y. A
    held row gets its column only when its equation is not the base's own (a held node at the
    plane, g = 0, that stays pressed; a stuck one at its anchor that stays stuck): at the end of
    a sliding front most nodes slide, few change.

    Only the columns' entries at the rows and at the dofs their tangent rows couple to (the
    `support`) enter D = Z[rows] and F, and the columns' right-hand sides live there too: the
    columns are solved there alone (`solve_at` of the factor: the contact rows sit at the band's
    end, at the rim), and du = du0 + Z y is one whole solve of the combined right-hand side. The
    gas tangent's rank-one term c g g^T, whose g spans the cavity chain, enters by its weights
    g.Z, from v = K_ff^-1 g_f (K_ff symmetric).

    The gas load ends at the chain's cut, the last node on the plane (`fem.cavity`): sets that
    release the outermost held nodes take the faces beyond out of the gas region, sets that
    press a node beyond the cut bring them in, and the load jumps (`fem.chain_cut.ChainCut`).
    Linearized at the iterate's cut alone, the outer end of the seal peeled off one node per
    Newton iteration (each release moving the cut in by one). Sets that move the cut are
    solved again with the jump in the residual and its response in du0 (`_base`)."""

    def __init__(self, plane: RigidPlane, old: ContactState, u, res0, K: sp.csr_matrix, fac,
                 du0, held: np.ndarray, tol: float):
        self.plane, self.K, self.fac, self.du0, self.res0, self.tol = plane, K, fac, du0, res0, tol
        self.mu, self.held, self.nodes = plane.law.mu, held, held.copy()
        rd = 2 * plane.nodes
        self.rows = np.concatenate([rd[held] + 1, rd[held]])
        self.force = np.zeros(len(self.rows), bool)          # the unknown is a force
        self.has = np.zeros(len(self.rows), bool)            # the row has its column
        self.cols = np.zeros(0, int)
        self.An = np.ones(len(held), bool)
        self.slip = old.slip[held].astype(np.int8)
        self.g_all = plane.gap(u)
        self.d0 = u[rd[held]] - old.u_r_stick_m[held]
        self.rank_one = getattr(K, "rank_one", None)
        if self.rank_one is not None:
            solved = getattr(fac, "solved_g", None)           # K_ff^-1 g_f
            self._v = solved if solved is not None else fac.solve(np.where(fac.free, self.rank_one[1], 0.0))
            self._gv = float(self._v @ self.rank_one[1])
        self.chain_cut = getattr(K, "chain_cut", None)        # the gas load's cut (`fem.chain_cut.ChainCut`)
        if self.chain_cut is not None:
            self._chain_at = self.chain_cut.positions(plane.nodes)
            self._chain_on, self._cut0 = self.chain_cut.on_plane(), self.chain_cut.index
        self._bases: dict[tuple, tuple] = {}                  # `_base` by (cut, rows)
        self._jumps: dict[int, np.ndarray] = {}               # `ChainCut.load_change` by cut
        self._jump = None                                     # the cut's jump of the last sets
        self.support, self.E = np.zeros(0, int), np.zeros((0, 0))
        self._set_rows()
        self.Z = np.zeros((len(self.support), 0))
        self.F = np.zeros((len(self.rows), 0))               # the rows' reactions to the columns
        self.converged, self.y = False, np.zeros(0)
        # a held node off the plane or off its anchor (pressed or landed in the last iteration),
        # and the rows the iterate's own sets need (the first guess of `ssn`): one solve
        moved = np.concatenate([self.g_all[held] != 0.0, self.d0 != 0.0])
        self._columns(np.flatnonzero(moved | self._needed(self.An, self.slip)))

    def _set_rows(self) -> None:
        """The rows' tangent rows, the support (class docstring) and the rows' sparse part on it
        (dense, [rows, support]); the columns' right-hand sides moved onto a grown support."""
        self._Kc = _rows(self.K, self.rows)
        Ks = self._Kc.sparse if self.rank_one is not None else self._Kc
        old = self.support
        self.support = np.union1d(self.rows, Ks.indices)
        self._Kd = np.zeros((len(self.rows), len(self.support)))
        self._Kd[np.repeat(np.arange(len(self.rows)), np.diff(Ks.indptr)),
                 np.searchsorted(self.support, Ks.indices)] = Ks.data
        self._at = np.searchsorted(self.support, self.rows)     # the rows in the support
        self._diag = self._Kd[np.arange(len(self.rows)), self._at]
        if len(old) != len(self.support):
            E = np.zeros((len(self.support), self.E.shape[1]))
            E[np.searchsorted(self.support, old)] = self.E
            self.E = E

    def _solve(self, E: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The columns Z on the support of the right-hand sides E [support, k] (the sparse
        part's, zero on the constrained dofs) of rows `cols`, and their reactions at the rows."""
        dofs, disp = self.rows[cols], ~self.force[cols]
        k = np.arange(len(cols))
        sup = self.support
        if len(cols) == 0:
            return np.zeros((len(sup), 0)), np.zeros((len(self.rows), 0))
        Z = solve_at(self.fac, sup, E, sup, len(self.du0))
        if self.rank_one is not None:       # E's whole columns: -(K_s + c g g^T)_f,dof
            c, g = self.rank_one
            gd = np.where(disp, c * g[dofs], 0.0)
            Z -= np.multiply.outer(self._v[sup], gd)
            gZ = self._v[sup] @ E - self._gv * gd + np.where(disp, g[dofs], 0.0)
        Z[self._at[cols[disp]], k[disp]] = 1.0
        F = self._Kd @ Z
        if self.rank_one is not None:
            F += self.rank_one[0] * np.multiply.outer(self._Kc.g_rows, gZ)
        return Z, F

    def _columns(self, rows: np.ndarray) -> None:
        """Add the columns of `rows` (one multi-column solve with the base factor)."""
        rows = rows[~self.has[rows]]
        if len(rows) == 0:
            return
        k = np.arange(len(rows))
        force = self.force[rows]
        E = np.zeros((len(self.support), len(rows)))
        E[self._at[rows[force]], k[force]] = 1.0
        E[:, ~force] = -self._Kd[rows[~force]].T             # K symmetric: its columns
        E[~self.fac.free[self.support]] = 0.0
        Z, F = self._solve(E, rows)
        self.E, self.Z = np.hstack([self.E, E]), np.hstack([self.Z, Z])
        self.F = np.hstack([self.F, F])
        self.cols = np.concatenate([self.cols, rows])
        self.has[rows] = True

    def add(self, new: np.ndarray) -> None:
        """Free nodes the step pushes through the plane join as pressed (force unknowns)."""
        start = len(self.rows)
        self.rows = np.concatenate([self.rows, 2 * self.plane.nodes[new] + 1])
        self.force = np.concatenate([self.force, np.ones(len(new), bool)])
        self.has = np.concatenate([self.has, np.zeros(len(new), bool)])
        self.nodes = np.concatenate([self.nodes, new])
        self.An = np.concatenate([self.An, np.ones(len(new), bool)])
        self._set_rows()
        self.Z, self.F = self._solve(self.E, self.cols)      # on the larger support
        self._columns(np.arange(start, len(self.rows)))

    def _cut(self, An: np.ndarray) -> int | None:
        """The chain's cut after a step with the rows' nodes pressed where An: the last chain
        node on the plane, the rows' nodes on it where pressed, the others where they are."""
        if self.chain_cut is None:
            return None
        on, at = self._chain_on.copy(), self._chain_at[self.nodes]
        on[at[at >= 0]] = An[at >= 0]
        return self.chain_cut.cut_of(on)

    def _base(self, k: int | None) -> tuple[np.ndarray, np.ndarray, tuple | None]:
        """q and w0 (the base step's reactions and displacements at the rows) with the chain cut
        at k, and the jump on the free dofs (dofs, values; None at the iterate's cut): the cavity
        load's jump (`fem.chain_cut.ChainCut.load_change`) is a reaction on the held dofs and moves
        the body through the free ones, which is solved at the support only (`solve_at`: the
        jump is at the rim, at the band's end) and enters the whole step in `du`."""
        if k is None or k == self._cut0:
            return self.res0[self.rows] + self._Kc @ self.du0, self.du0[self.rows], None
        key = (k, len(self.rows))
        if key not in self._bases:
            if k not in self._jumps:
                self._jumps[k] = self.chain_cut.load_change(k)
            jump = self._jumps[k]
            free = np.flatnonzero((jump != 0.0) & self.fac.free)
            w = self.du0[self.support]
            gw = None if self.rank_one is None else self.rank_one[1] @ self.du0
            if free.size:
                w = w + solve_at(self.fac, free, -jump[free, None], self.support, len(self.du0))[:, 0]
                if gw is not None:                  # g.K_ff^-1 b = v.b (K_ff symmetric)
                    gw -= self._v[free] @ jump[free]
            q = (self.res0 + jump)[self.rows] + self._Kd @ w
            if gw is not None:
                q += self.rank_one[0] * self._Kc.g_rows * gw
            self._bases[key] = (q, w[self._at], (free, jump[free]) if free.size else None)
        return self._bases[key]

    def du(self) -> np.ndarray:
        """du0 + Z y: one solve of the columns' right-hand sides combined by y (and of the cavity
        load's jump on the free dofs, where the sets moved the cut)."""
        b = np.zeros(len(self.du0))
        if self._jump is not None:
            b[self._jump[0]] = -self._jump[1]
        if len(self.cols) == 0:
            return self.du0 + self.fac.solve(b) if self._jump is not None else self.du0.copy()
        dofs, disp = self.rows[self.cols], ~self.force[self.cols]
        b[self.support] += self.E @ self.y
        du = self.du0 + self.fac.solve(b)
        if self.rank_one is not None:
            du -= self._v * (self.rank_one[0] * self.rank_one[1][dofs[disp]] @ self.y[disp])
        du[dofs[disp]] += self.y[disp]
        return du

    def _needed(self, An: np.ndarray, slip: np.ndarray) -> np.ndarray:
        """The rows whose equation under the sets (An, slip) is not the base's own."""
        nh = len(self.held)
        need = np.zeros(len(self.rows), bool)
        need[:nh] = ~An[:nh]
        need[nh:2 * nh] = ~An[:nh] | (slip != 0)
        return need & ~self.has

    def ssn(self) -> None:
        """The semismooth Newton iteration on the condensed problem (module docstring), from the
        sets of the last call (first: the iterate's). Sets `y`, `An`, `slip`, `converged`.
        Under the trapped gas, sets that move the cavity chain's cut (class docstring) are
        iterated on with the load of the moved cut; if that finds no sets, those of the
        iterate's cut stand."""
        nh, nn = len(self.held), len(self.nodes)
        iz = np.concatenate([np.arange(nh), 2 * nh + np.arange(nn - nh)])
        ir = nh + np.arange(nh)
        g, d0, mu = self.g_all[self.nodes], self.d0, self.mu
        c = np.abs(self._diag)                      # the augmentation (module docstring)
        An, slip = self.An.copy(), self.slip.copy()
        self.converged, cut, carried = False, -1, False
        for _ in range(_SSN_ITERATIONS):
            at = self._cut(An) if carried else None
            if at != cut:                       # the load at that cut (`_base`)
                cut = at
                q, w0, jump = self._base(cut)
            self._columns(np.flatnonzero(self._needed(An, slip)))
            F, D = self.F, self.Z[self._at]
            A, b = F.copy(), -q.copy()          # default rows: reaction 0 (off the plane)
            on = iz[An]
            A[on], b[on] = D[on], -g[An] - w0[on]
            stuck = An[:nh] & (slip == 0)
            A[ir[stuck]], b[ir[stuck]] = D[ir[stuck]], -d0[stuck] - w0[ir[stuck]]
            sl = An[:nh] & (slip != 0)
            k = -mu * slip[sl]                   # t = -mu slip lambda
            A[ir[sl]] = F[ir[sl]] - k[:, None] * F[iz[:nh][sl]]
            b[ir[sl]] = -(q[ir[sl]] - k * q[iz[:nh][sl]])
            y = np.linalg.solve(A[self.cols], b[self.cols]) if len(self.cols) else np.zeros(0)
            f, w = q + F @ y, w0 + D @ y
            self.y, self.An, self.slip, self._jump = y, An, slip, jump
            An_new, slip_new = self._sets(f, w, c, g, An, slip, iz, ir)
            if np.array_equal(An_new, An) and np.array_equal(slip_new, slip):
                if not carried and self.chain_cut is not None and self._cut(An) != self._cut0:
                    carried, kept = True, (y, An, slip, jump)   # the sets move the cut: go on
                    seen = set()                                # with the load of theirs
                    continue
                self.converged = True
                break
            if carried:                         # a cycle at the moved cut: no sets there
                key = An_new.tobytes() + slip_new.tobytes()
                if key in seen:
                    break
                seen.add(key)
            An, slip = An_new, slip_new
        if carried and not self.converged:      # no sets at the moved cut: the iterate's cut's
            y, self.An, self.slip, self._jump = kept
            self.y = np.concatenate([y, np.zeros(len(self.cols) - len(y))])   # (columns added since)
            self.converged = True

    def _sets(self, f, w, c, g, An, slip, iz, ir):
        """The active sets of Alart and Curnier's functions at (f, w), with a hysteresis of the
        force tolerance so that a converged set stays put; a sliding node whose slide would
        reverse sticks first (going straight to the reverse slide let nodes next to the cone's
        edge flip for ever)."""
        nh = len(self.held)
        lam_hat = f[iz] - c[iz] * (g + w[iz])
        An_new = lam_hat > np.where(An, -self.tol, self.tol)
        zeta = f[ir] - c[ir] * (self.d0 + w[ir])
        bound = self.mu * np.maximum(lam_hat[:nh], 0.0) + np.where(slip == 0, self.tol, -self.tol)
        slip_new = np.where(np.abs(zeta) <= bound, 0, -np.sign(zeta)).astype(np.int8)
        slip_new[(slip != 0) & (slip_new == -slip)] = 0
        return An_new, np.where(An_new[:nh], slip_new, 0).astype(np.int8)


def _rows(K, dofs: np.ndarray):
    """Rows `dofs` of the tangent, its rank-one gas term included where it has one
    (`fem.trapped_gas.GasTangent`: then a `_RankOneRows`); plain slicing gives the sparse part only."""
    rank_one = getattr(K, "rank_one", None)
    return K[dofs] if rank_one is None else _RankOneRows(K.plain()[dofs], *rank_one, dofs)


class _RankOneRows:
    """Rows of K_s + c g g^T kept as the sparse rows of K_s and the term's factors, so that their
    products with the columns cost a product with g instead of a dense block added to K_s's rows
    (g spans the whole cavity chain)."""

    def __init__(self, sparse: sp.csr_matrix, c: float, g: np.ndarray, dofs: np.ndarray):
        self.sparse, self.c, self.g, self.g_rows = sparse, c, g, g[dofs]

    def __matmul__(self, X: np.ndarray) -> np.ndarray:
        return self.sparse @ X + self.c * np.multiply.outer(self.g_rows, self.g @ X)

    def toarray(self) -> np.ndarray:
        return self.sparse.toarray() + self.c * np.outer(self.g_rows, self.g)
