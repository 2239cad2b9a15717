"""Assembly: vectorized kernels = plain weak forms; tangent = finite differences; homogeneous
finite-strain patch solves = closed-form neo-Hookean states (both formulations)."""

import numpy as np
import pytest
from scipy.optimize import brentq

from fem.blocks import mapped_block
from fem.forms import Mechanics, energy_form, internal_force_form, tangent_form
from fem.kinematics import Kinematics
from fem.material import NeoHookean
from fem.solver import SolverOptions, follow_path

TIGHT = SolverOptions(rtol=1e-11)   # Newton to (near) round-off for the patch tests


def distorted_annulus(n=3, a=1e-3, b=2e-3, H=1e-3, wiggle=0.08):
    """Annular block a <= R <= b, 0 <= Z <= H with a curved, distorted interior (straight sides)."""
    def x(s, t):
        bump = wiggle * np.sin(np.pi * s) * np.sin(np.pi * t)
        return a + (b - a) * (s + bump), H * (t + 0.5 * bump * np.cos(3 * s))
    return mapped_block(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1), x)


def random_state(kin, amplitude=0.02, seed=0):
    rng = np.random.default_rng(seed)
    return amplitude * 1e-3 * rng.standard_normal(kin.ndofs)


@pytest.fixture(scope="module")
def kin():
    return Kinematics.of(distorted_annulus())


def test_vectorized_kernels_equal_plain_weak_forms(kin):
    """Same integrals, different summation order: agreement to round-off (1e-12 relative)."""
    mat = NeoHookean(4e6, 0.45)
    mech = Mechanics(kin, mat)
    u = random_state(kin)
    b = kin.basis
    uh = b.interpolate(u)
    r, K = mech.linearize(u)
    r_ref = internal_force_form(mat).assemble(b, u=uh)
    K_ref = tangent_form(mat).assemble(b, u=uh)
    assert np.max(np.abs(r - r_ref)) <= 1e-12 * np.max(np.abs(r))
    assert abs(K - K_ref).max() <= 1e-12 * abs(K).max()
    assert mech.energy(u) == pytest.approx(energy_form(mat).assemble(b, u=uh), rel=1e-12)


@pytest.mark.parametrize("formulation, nu", [("displacement", 0.45), ("mixed", 0.45),
                                             ("mixed", 0.4999)])
def test_tangent_matches_finite_differences(kin, formulation, nu):
    """K du vs central differences of r (h = 1e-6 of the state): truncation O(h^2), round-off
    ~1e-16/h relative to ||K du|| times cond ~ 1e3 (nu = 0.4999): bound 1e-6."""
    mech = Mechanics(kin, NeoHookean(4e6, nu, formulation))
    u = random_state(kin, seed=2)
    r, K = mech.linearize(u)
    rng = np.random.default_rng(3)
    du = 1e-3 * rng.standard_normal(kin.ndofs)
    h = 1e-6
    fd = (mech.internal_force(u + h * du) - mech.internal_force(u - h * du)) / (2 * h)
    Kdu = K @ du
    assert np.linalg.norm(fd - Kdu) <= 1e-6 * np.linalg.norm(Kdu)
    # and r is the gradient of the stored energy (includes the hoop term u_r / R)
    dE = (mech.energy(u + h * du) - mech.energy(u - h * du)) / (2 * h)
    assert dE == pytest.approx(r @ du, rel=1e-6)
    hoop_only = np.zeros_like(du)
    hoop_only[0::2] = du[0::2]
    assert np.linalg.norm(K @ hoop_only) > 0


def _nodes_on(kin, name):
    return np.unique(kin.basis.get_dofs(kin.mesh.boundaries[name]).all() // 2)


def closed_form_cauchy(mat, l):
    J = np.prod(l)
    return (mat.mu * (np.asarray(l) ** 2 - 1) + mat.lam * np.log(J)) / J


def triangle_annulus(a=1e-3, b=2e-3, H=1e-3):
    """The annulus as 6-node triangles (users' unstructured meshes), tags left/right/bottom/top."""
    from skfem import MeshTri1, MeshTri2
    m = MeshTri1.init_tensor(np.linspace(a, b, 4), np.linspace(0, H, 4))
    return MeshTri2.from_mesh(m).with_defaults()


@pytest.mark.parametrize("formulation, element", [("displacement", "quad"), ("mixed", "quad"),
                                                  ("displacement", "tri"), ("mixed", "tri")])
def test_uniaxial_patch_solve(formulation, element):
    """Stretch the distorted annulus along z by 1.3 (bottom and top held in z, r free): the FE
    solution must be the homogeneous state with lateral stretch from sigma_rr = 0, the top
    reaction sigma_zz * current area. Q2 reproduces linear fields: tolerance 1e-8 (Newton to 1e-11, cond ~1e3)."""
    mat = NeoHookean(4e6, 0.45, formulation)
    a, b, H, lz = 1e-3, 2e-3, 1e-3, 1.3
    mesh = distorted_annulus(a=a, b=b, H=H) if element == "quad" else triangle_annulus(a, b, H)
    kin = Kinematics.of(mesh)
    mech = Mechanics(kin, mat)
    bottom, top = _nodes_on(kin, "bottom"), _nodes_on(kin, "top")
    dofs = np.concatenate([2 * bottom + 1, 2 * top + 1])

    def dirichlet(t):
        return dofs, np.concatenate([np.zeros(len(bottom)), np.full(len(top), t * (lz - 1) * H)])

    out = []
    follow_path(mech, dirichlet, 1.0, options=TIGHT, on_step=out.append)
    u, r_int = out[-1].u, out[-1].r_int
    lt = brentq(lambda x: closed_form_cauchy(mat, [x, lz, x])[0], 0.5, 1.0)
    X = kin.node_coordinates()
    assert np.allclose(u[0::2], (lt - 1) * X[0], atol=1e-8 * H)
    assert np.allclose(u[1::2], (lz - 1) * X[1], atol=1e-8 * H)
    sz = closed_form_cauchy(mat, [lt, lz, lt])[1]
    F_top = np.sum(r_int[2 * top + 1])
    assert F_top == pytest.approx(sz * np.pi * (b**2 - a**2) * lt**2, rel=1e-8)


@pytest.mark.parametrize("formulation", ["displacement", "mixed"])
def test_equibiaxial_with_hoop_patch_solve(formulation):
    """Radial stretch 1.2 prescribed on the inner and outer faces (hoop stretch 1.2 too), bottom
    held in z, top free: lambda_z from sigma_zz = 0; the outer-face reaction is
    sigma_rr * 2 pi (b l) (H lambda_z)."""
    mat = NeoHookean(4e6, 0.45, formulation)
    a, b, H, lr = 1e-3, 2e-3, 1e-3, 1.2
    kin = Kinematics.of(distorted_annulus(a=a, b=b, H=H))
    mech = Mechanics(kin, mat)
    inner, outer, bottom = (_nodes_on(kin, n) for n in ("left", "right", "bottom"))
    X = kin.node_coordinates()
    dofs = np.concatenate([2 * inner, 2 * outer, 2 * bottom + 1])

    def dirichlet(t):
        return dofs, np.concatenate([t * (lr - 1) * X[0, inner], t * (lr - 1) * X[0, outer],
                                     np.zeros(len(bottom))])

    out = []
    follow_path(mech, dirichlet, 1.0, options=TIGHT, on_step=out.append)
    u, r_int = out[-1].u, out[-1].r_int
    lz = brentq(lambda x: closed_form_cauchy(mat, [lr, x, lr])[1], 0.3, 1.0)
    assert np.allclose(u[0::2], (lr - 1) * X[0], atol=1e-8 * H)
    assert np.allclose(u[1::2], (lz - 1) * X[1], atol=1e-8 * H)
    sr = closed_form_cauchy(mat, [lr, lz, lr])[0]
    F_outer = np.sum(r_int[2 * outer])
    assert F_outer == pytest.approx(sr * 2 * np.pi * b * lr * H * lz, rel=1e-8)


def test_evaluate_reuses_only_the_same_state():
    """The one-entry memo of `Mechanics.evaluate` returns the previous results for an equal u
    (read-only, so they cannot be spoiled), and recomputes when u changes, also in place."""
    from fem.geometry import cup_geometry
    from fem.mesh import cup_mesh

    mech = Mechanics(Kinematics.of(cup_mesh(cup_geometry("A"), "coarse")), NeoHookean())
    u = np.zeros(mech.kin.ndofs)
    W0, r0, K0 = mech.evaluate(u)
    assert mech.evaluate(u.copy())[1] is r0
    with pytest.raises(ValueError):
        r0[0] = 1.0
    u[1::2] = -1e-6 * mech.kin.node_coordinates()[1]          # a uniform vertical squeeze, in place
    W1, r1, K1 = mech.evaluate(u)
    assert W1 > W0 and r1 is not r0
    fresh = Mechanics(mech.kin, mech.material).evaluate(u)
    assert W1 == fresh[0] and np.array_equal(r1, fresh[1]) and np.array_equal(K1.data, fresh[2].data)
