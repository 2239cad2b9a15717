"""`fem.free_block.solve_free_block` against a dense solve of the same free block: the banded
Cholesky path (identity rows, K_ff definite), with combined rows (Coulomb's sliding rows:
unsymmetric) by the Woodbury identity on the same factor, and the sparse LU where K_ff is
indefinite; several right-hand sides at once.
K's condition number is ~1e6 on the cup meshes, hence 1e-9 relative."""

import numpy as np
import pytest
import scipy.sparse as sp

import fem.free_block as free_block
from fem.forms import Mechanics
from fem.geometry import cup_geometry
from fem.kinematics import Kinematics
from fem.material import NeoHookean
from fem.mesh import cup_mesh


@pytest.fixture(scope="module")
def system():
    mesh = cup_mesh(cup_geometry("A"), "coarse")
    mech = Mechanics(Kinematics.of(mesh), NeoHookean())
    rng = np.random.default_rng(7)
    K = mech.linearize(1e-7 * rng.normal(size=mech.kin.ndofs))[1]
    n = K.shape[0]
    top = np.flatnonzero(np.isclose(mesh.doflocs[0], mesh.doflocs[0].min()))
    rim = np.argsort(mesh.doflocs[1], kind="stable")[:8]                 # the lowest nodes
    free = np.ones(n, bool)
    free[np.concatenate([2 * top, 2 * top + 1, 2 * rim[:3] + 1])] = False
    rhs = rng.normal(size=(int(free.sum()), 3))
    return mech.kin, sp.csr_matrix(K), free, rhs, rim


def _dense(A, free, rhs):
    return np.linalg.solve(A.toarray()[np.ix_(free, free)], rhs)


def _close(x, ref):
    return np.max(np.abs(x - ref)) <= 1e-9 * np.max(np.abs(ref))


def test_identity_rows_take_the_banded_cholesky_and_match_a_dense_solve(system, monkeypatch):
    kin, K, free, rhs, _ = system
    monkeypatch.setattr(free_block.spla, "splu", lambda *a, **k: pytest.fail("sparse LU used"))
    x = free_block.solve_free_block(K, sp.identity(K.shape[0], format="csr"), free, rhs, kin)
    assert x.shape == rhs.shape and _close(x, _dense(K, free, rhs))


@pytest.mark.parametrize("held", [True, False])
def test_combined_rows_take_the_woodbury_identity_and_match_a_dense_solve(system, monkeypatch, held):
    """Sliding nodes' radial rows gain mu s times their normal row, held (fixed) or not; a
    combined row of a fixed dof is outside the block."""
    kin, K, free, rhs, rim = system
    n = K.shape[0]
    nodes = rim[:4] if held else rim[3:]               # rim[:3] are held on the plane (fixture)
    slip = np.where(np.arange(nodes.size) % 2, -1.0, 1.0)
    R = sp.identity(n, format="csr") + sp.csr_matrix((0.4 * slip, (2 * nodes, 2 * nodes + 1)), shape=(n, n))
    R = sp.csr_matrix(R + sp.csr_matrix(([0.3], ([2 * rim[0] + 1], [2 * rim[1] + 1])), shape=(n, n)))
    monkeypatch.setattr(free_block.spla, "splu", lambda *a, **k: pytest.fail("sparse LU used"))
    x = free_block.solve_free_block(K, R, free, rhs, kin)
    assert _close(x, _dense(R @ K, free, rhs))


def test_an_indefinite_block_falls_back_to_sparse_lu(system):
    kin, K, free, rhs, _ = system
    shift = 0.5 * np.max(K.diagonal())                 # K - shift I: indefinite, still regular
    A = (K - shift * sp.identity(K.shape[0])).tocsr()
    A.sort_indices()
    assert A.nnz == K.nnz                              # the same pattern (diagonal present)
    x = free_block.solve_free_block(A, sp.identity(K.shape[0], format="csr"), free, rhs, kin)
    assert _close(x, _dense(A, free, rhs))


def test_a_woodbury_solve_above_the_backward_error_falls_back_to_sparse_lu(system, monkeypatch):
    kin, K, free, rhs, rim = system
    n = K.shape[0]
    R = sp.csr_matrix(sp.identity(n) + sp.csr_matrix(([0.4], ([2 * rim[4]], [2 * rim[4] + 1])), shape=(n, n)))
    calls = []
    splu = free_block.spla.splu
    monkeypatch.setattr(free_block, "BACKWARD_ERROR", 0.0)         # no solve meets it
    monkeypatch.setattr(free_block.spla, "splu", lambda A: calls.append(A) or splu(A))
    x = free_block.solve_free_block(K, R, free, rhs, kin)
    assert len(calls) == 1 and _close(x, _dense(R @ K, free, rhs))
