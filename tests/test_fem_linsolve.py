"""Static condensation of the element-interior nodes (`fem.condensation`) against the plain banded
Cholesky on the same systems: exact elimination, so the two agree to round-off (K's condition
number is ~1e6 on the cup meshes, hence 1e-9 relative), including prescribed values, several
right-hand sides, a Levenberg-Marquardt shift, freed contact dofs and the definiteness verdict."""

import numpy as np
import pytest
import scipy.sparse as sp

from fem.condensation import CondensedCholesky, interior_nodes, make_solver
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
