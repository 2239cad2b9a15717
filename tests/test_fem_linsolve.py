"""Static condensation of the element-interior nodes (`fem.condensation`) against the plain banded
Cholesky on the same systems: exact elimination, so the two agree to round-off (K's condition
number is ~1e6 on the cup meshes, hence 1e-9 relative), including prescribed values, several
right-hand sides, a Levenberg-Marquardt shift, freed contact dofs and the definiteness verdict;
the banded solve against a dense one; and the reuse of a factor (`fem.factorization.ShiftPolicy`),
which must leave a path unchanged to the bit."""

import numpy as np
import pytest
import scipy.sparse as sp

from fem.condensation import CondensedCholesky, interior_nodes, make_solver
from fem.factorization import ShiftPolicy
from fem.forms import Mechanics
from fem.geometry import cup_geometry
from fem.kinematics import Kinematics
from fem.linsolve import BandedCholesky, NotPositiveDefinite
from fem.material import NeoHookean
from fem.mesh import cup_mesh


@pytest.fixture(scope="module")
def system():
    mesh = cup_mesh(cup_geometry("A"), "coarse")
    mech = Mechanics(Kinematics.of(mesh), NeoHookean())
    rng = np.random.default_rng(4)
    K = mech.linearize(1e-7 * rng.normal(size=mech.kin.ndofs))[1]      # a perturbed state
    n = K.shape[0]
    top = np.flatnonzero(np.isclose(mesh.doflocs[0], mesh.doflocs[0].min()))
    rim = np.flatnonzero(np.isclose(mesh.doflocs[1], 0.0))                # nodes on the plane
    free = np.ones(n, bool)
    free[np.concatenate([2 * top, 2 * top + 1, 2 * rim[:3] + 1])] = False
    du_fixed = np.where(free, 0.0, rng.normal(size=n) * 1e-6)
    return mesh, K, free, du_fixed, rim, rng


def _close(x, ref):
    return np.max(np.abs(x - ref)) <= 1e-9 * np.max(np.abs(ref))


def test_quad9_meshes_are_condensed_with_a_narrower_band(system):
    mesh, K, *_ = system
    solver = make_solver(K, mesh.doflocs, mesh)
    assert isinstance(solver, CondensedCholesky)
    assert len(interior_nodes(mesh, K)) == mesh.t.shape[1]         # one centre node per element
    assert solver.kd < BandedCholesky(K, mesh.doflocs, mesh).kd
    tri = cup_mesh(cup_geometry("A"), "coarse", element="tri")
    K_tri = Mechanics(Kinematics.of(tri), NeoHookean()).linearize(np.zeros(2 * tri.doflocs.shape[1]))[1]
    assert isinstance(make_solver(K_tri, tri.doflocs, tri), BandedCholesky)


def test_a_mesh_keeps_its_solver_while_its_pattern_and_nodes_are_the_same(system):
    """make_solver on the same mesh, pattern and coordinates returns the solver it built, whose
    factor solves like a new solver's to the last bit; moved nodes or another pattern build anew."""
    mesh, K, free, du_fixed, _, rng = system
    solver = make_solver(K, mesh.doflocs, mesh)
    assert make_solver(K.copy(), mesh.doflocs.copy(), mesh) is solver
    fresh = CondensedCholesky(K, mesh.doflocs, mesh, interior_nodes(mesh, K))
    rhs = rng.normal(size=K.shape[0])
    assert np.array_equal(solver.factor(K, free).solve(rhs, du_fixed), fresh.factor(K, free).solve(rhs, du_fixed))
    assert make_solver(K, mesh.doflocs * 1.01, mesh) is not solver
    assert make_solver(K, mesh.doflocs, mesh) is not solver            # the last call's is kept
    n = K.shape[0]
    other = sp.csr_matrix(K + sp.coo_matrix(([1.0, 1.0], ([0, n - 1], [n - 1, 0])), shape=K.shape))
    assert other.nnz == K.nnz + 2                                      # one more coupling
    assert make_solver(other, mesh.doflocs, mesh) is not make_solver(K, mesh.doflocs, mesh)


@pytest.mark.parametrize("shift", [0.0, 1e-3])
def test_condensed_solve_equals_the_full_factorization(system, shift):
    mesh, K, free, du_fixed, _, rng = system
    condensed = make_solver(K, mesh.doflocs, mesh).factor(K, free, shift)
    full = BandedCholesky(K, mesh.doflocs, mesh).factor(K, free, shift)
    rhs = rng.normal(size=(K.shape[0], 4))
    assert _close(condensed.solve(rhs[:, 0], du_fixed), full.solve(rhs[:, 0], du_fixed))
    assert _close(condensed.solve(rhs), full.solve(rhs))


def test_condensed_factor_frees_contact_dofs_like_a_new_factorization(system):
    mesh, K, free, du_fixed, rim, rng = system
    freed = 2 * rim[:3] + 1
    larger = free.copy()
    larger[freed] = True
    x = make_solver(K, mesh.doflocs, mesh).factor(K, free).freeing(freed)
    ref = BandedCholesky(K, mesh.doflocs, mesh).factor(K, larger)
    rhs = rng.normal(size=K.shape[0])
    assert _close(x.solve(rhs, du_fixed), ref.solve(rhs, du_fixed))


def test_condensed_factor_refuses_an_indefinite_matrix(system):
    mesh, K, free, *_ = system
    with pytest.raises(NotPositiveDefinite):
        make_solver(K, mesh.doflocs, mesh).factor(sp.csr_matrix(-K), free)


@pytest.mark.parametrize("moved", [True, False])
def test_banded_solve_equals_a_dense_solve_of_the_free_block(system, moved):
    """The band (constrained rows and columns zeroed in it) against numpy's dense solve of
    K_ff x_f = b_f - K_fc du_c, with and without prescribed motion of the constrained dofs."""
    mesh, K, free, du_fixed, _, rng = system
    du = du_fixed if moved else np.zeros_like(du_fixed)
    rhs = rng.normal(size=K.shape[0])
    A = K.toarray()
    x_f = np.linalg.solve(A[np.ix_(free, free)], rhs[free] - A[np.ix_(free, ~free)] @ du[~free])
    for solver in (BandedCholesky(K, mesh.doflocs, mesh), make_solver(K, mesh.doflocs, mesh)):
        x = solver.factor(K, free).solve(rhs, du)
        assert _close(x[free], x_f) and np.array_equal(x[~free], du[~free])


def test_shift_policy_reuses_a_factor_only_for_the_same_read_only_tangent(system):
    """The same read-only K, free set and shift: the same factor, not counted again; a different
    free set, shift or a writable K (which may have changed in place): a new factorization."""
    mesh, K, free, *_ = system
    solver = make_solver(K, mesh.doflocs, mesh)
    frozen = K.copy()
    frozen.data.flags.writeable = False
    policy = ShiftPolicy()
    first = policy.factor(solver, frozen, free, 0.0)
    assert policy.factor(solver, frozen, free.copy(), 0.0) is first and policy.factorizations == 1
    fewer = free.copy()
    fewer[np.flatnonzero(free)[0]] = False
    assert policy.factor(solver, frozen, fewer, 0.0) is not first
    assert policy.factor(solver, frozen, fewer, 1e-3) is not first and policy.factorizations == 3
    writable = K.copy()
    policy.factor(solver, writable, free, 0.0)
    assert policy.factor(solver, writable, free, 0.0) is not None and policy.factorizations == 5


def test_a_path_with_factor_reuse_equals_one_without(monkeypatch):
    """Cup A, coarse, frictionless, to 0.3 h1: reusing the converged state's factor in the next
    step's first iteration changes no bit of the path (the same matrix, the same factor)."""
    import fem.solver
    from fem.cup import compress_cup

    class Fresh(ShiftPolicy):
        def factor(self, solver, K, free, shift):
            self._last = None
            return super().factor(solver, K, free, shift)

    g = cup_geometry("A")
    mesh = cup_mesh(g, "coarse")
    reused = compress_cup(mesh, NeoHookean(), "frictionless", u_max_m=0.3 * g.h1_m)
    monkeypatch.setattr(fem.solver, "ShiftPolicy", Fresh)
    fresh = compress_cup(mesh, NeoHookean(), "frictionless", u_max_m=0.3 * g.h1_m)
    assert reused.stats.factorizations < fresh.stats.factorizations
    assert np.array_equal(reused.u_m, fresh.u_m) and np.array_equal(reused.F0_N, fresh.F0_N)
    assert all(np.array_equal(a, b) for a, b in zip(reused.displacements, fresh.displacements))
