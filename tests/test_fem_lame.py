"""Linear limit: Lame's thick-walled cylinder under internal pressure (plane strain, u_z = 0)."""

import numpy as np
import pytest
from skfem import FacetBasis, LinearForm

from fem.blocks import mapped_block
from fem.forms import Mechanics
from fem.kinematics import Kinematics
from fem.material import NeoHookean
from fem.solver import follow_path

A, B, H = 10e-3, 20e-3, 2e-3


def lame_u_r(r, p, E, nu):
    """Radial displacement of Lame's cylinder in plane strain (textbook closed form)."""
    return p * A**2 * (1 + nu) / (E * (B**2 - A**2)) * ((1 - 2 * nu) * r + B**2 / r)


def lame_hoop(r, p):
    return p * A**2 / (B**2 - A**2) * (1 + B**2 / r**2)


def solve_lame(material, n_r=8, p=1e-4 * 4e6):
    mesh = mapped_block(np.linspace(0, 1, n_r + 1), np.linspace(0, 1, 2),
                        lambda s, t: (A + (B - A) * s, H * t))
    kin = Kinematics.of(mesh)
    mech = Mechanics(kin, material)
    fb = FacetBasis(mesh, kin.basis.elem, facets=mesh.boundaries["left"])

    @LinearForm
    def inner_pressure(v, w):      # traction p e_r on the inner face, dead load, 2 pi R ds
        return p * v[0] * 2 * np.pi * w.x[0]

    f = inner_pressure.assemble(fb)
    zdofs = np.unique(np.concatenate([kin.basis.get_dofs(mesh.boundaries[n]).all()
                                      for n in ("bottom", "top")]))
    zdofs = zdofs[zdofs % 2 == 1]
    out = []
    follow_path(mech, lambda t: (zdofs, np.zeros(len(zdofs))), 1.0, f_ext=lambda t: t * f,
                on_step=out.append)
    return kin, mech, out[-1].u, p


@pytest.mark.parametrize("formulation, nu", [("displacement", 0.3), ("mixed", 0.3),
                                             ("mixed", 0.4999)])
def test_lame_cylinder(formulation, nu):
    """Displacement of the inner and outer faces and the mean hoop stress within 0.5 % (the spec);
    p = 1e-4 E, so finite-strain effects are ~1e-4."""
    mat = NeoHookean(4e6, nu, formulation)
    kin, mech, u, p = solve_lame(mat)
    X = kin.node_coordinates()
    for R in (A, B):
        at = np.isclose(X[0], R)
        assert np.allclose(u[0::2][at], lame_u_r(R, p, mat.E_Pa, nu), rtol=5e-3)
    # hoop stress: element means against the closed form at the element centroid radius
    from fem.fields import element_cauchy_stress
    s = element_cauchy_stress(mech, u)
    Rc = np.sum(kin.R * kin.dV, axis=1) / kin.dV.sum(axis=1)
    assert np.allclose(s[2], lame_hoop(Rc, p), rtol=5e-3)


def test_plain_displacement_formulation_locks_near_incompressibility():
    """The same cylinder at nu = 0.4999: the mixed form stays within 0.5 %, the plain displacement
    form on the same mesh is visibly too stiff (why the mixed option exists)."""
    nu = 0.4999
    errors = {}
    for form in ("displacement", "mixed"):
        mat = NeoHookean(4e6, nu, form)
        kin, _, u, p = solve_lame(mat, n_r=2)
        at = np.isclose(kin.node_coordinates()[0], A)
        errors[form] = abs(u[0::2][at].mean() / lame_u_r(A, p, mat.E_Pa, nu) - 1)
    assert errors["mixed"] < 5e-3
    assert errors["displacement"] > 2 * errors["mixed"]
