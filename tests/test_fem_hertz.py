"""Hertz: an elastic paraboloid z = r^2 / (2 R_s) pressed on the rigid plane (frictionless).

The body is a block 0 <= r <= L, z_b(r) <= z <= H, L = H = 50 a, with Q2 cells graded
geometrically towards the contact. The top moves down; the far field's compliance only changes
the indentation, not the relation between the force and the contact radius, which is Hertz's
F = 4 E* a^3 / (3 R_s), E* = E / (1 - nu^2) (to O((a/L)^3) and O(a/R_s) for finite strain).

The contact radius is measured from the contact force distribution, not from the last node in
contact (which is quantized by the mesh): for Hertz's p = p0 sqrt(1 - r^2/a^2),
<r^2>_p = int p r^2 dA / int p dA = 2 a^2 / 5, so a = sqrt(5/2 <r^2>_p), and <r^2>_p is the
nodal-reaction moment sum(lambda r^2) / sum(lambda) exactly (the projection is consistent).
"""

import numpy as np
import pytest
from scipy.optimize import brentq

from fem.blocks import graded, mapped_block
from fem.contact import RigidPlane
from fem.forms import Mechanics
from fem.kinematics import Kinematics
from fem.material import NeoHookean
from fem.solver import follow_path

RS = 10e-3          # sphere radius [m]
A_TARGET = 0.01 * RS


def first_cell_grading(n: int, first: float) -> np.ndarray:
    """n cells on [0, 1] in geometric progression with the first one of size `first`."""
    q = brentq(lambda q: (q - 1) / (q**n - 1) - first, 1 + 1e-9, 3.0)
    return graded(n, q ** (n - 1))


def hertz_block(n: int, cells_per_a: float, size: float = 50.0):
    """Block of L = H = size * a; n graded cells each way, the first one a / cells_per_a."""
    L = H = size * A_TARGET

    def x(s, t):
        r = L * s
        zb = r**2 / (2 * RS)
        return r, zb + (H - zb) * t

    s = first_cell_grading(n, 1.0 / (size * cells_per_a))
    return mapped_block(s, s, x)


def press(n: int, cells_per_a: float, nu: float = 0.3, formulation="displacement"):
    mesh = hertz_block(n, cells_per_a)
    kin = Kinematics.of(mesh)
    mat = NeoHookean(4e6, nu, formulation)
    mech = Mechanics(kin, mat)
    plane = RigidPlane.on(kin, ["bottom"])
    axis = np.unique(kin.basis.get_dofs(mesh.boundaries["left"]).all() // 2)
    top = np.unique(kin.basis.get_dofs(mesh.boundaries["top"]).all() // 2)
    dofs = np.concatenate([2 * axis, 2 * top + 1])
    # indentation giving a ~ A_TARGET on a half-space: delta = a^2 / R_s (plus the far field)
    delta = 1.3 * A_TARGET**2 / RS

    def dirichlet(t):
        return dofs, np.concatenate([np.zeros(len(axis)), np.full(len(top), -t)])

    out = []
    follow_path(mech, dirichlet, delta, plane=plane, on_step=out.append)
    last = out[-1]
    lam = plane.reactions(last.r_int) * last.contact.active
    r = kin.node_coordinates()[0, plane.nodes] + last.u[2 * plane.nodes]
    F = lam.sum()
    a = np.sqrt(2.5 * np.sum(lam * r**2) / F)
    E_star = mat.E_Pa / (1 - nu**2)
    a_node = r[last.contact.active].max()
    return F, a, E_star, a_node, plane.largest_penetration(last.u), (plane, last)


def hertz_force(a, E_star):
    return 4 * E_star * a**3 / (3 * RS)


def test_hertz_default_mesh():
    """Default-suite version on a 20 x 20 mesh (first cell a/10). Observed on the sequence
    (16, a/5), (20, a/10), (30, a/20), (40, a/40): force errors 3.8, 1.5, 1.1, 0.34 %; so here
    the force within 2 % and the radius (error / 3) within 1 %."""
    F, a, E_star, a_node, pen, _ = press(20, 10)
    assert a == pytest.approx(A_TARGET, rel=0.3)          # the indentation was sized for it
    assert F == pytest.approx(hertz_force(a, E_star), rel=0.02)
    a_hertz = (3 * F * RS / (4 * E_star)) ** (1 / 3)
    assert a == pytest.approx(a_hertz, rel=0.01)
    assert abs(a_node - a) < 0.15 * a                     # the last node in contact: within ~1 cell
    assert pen < 0.01 * A_TARGET**2 / RS                  # nodes on the plane; edges dip < 1 % of delta


@pytest.mark.slow
@pytest.mark.parametrize("formulation, nu", [("displacement", 0.3), ("mixed", 0.49)])
def test_hertz_converged_mesh(formulation, nu):
    """Converged mesh (40 x 40, first cell a/40): force and contact radius within 1 % (spec)."""
    F, a, E_star, a_node, pen, _ = press(40, 40, nu, formulation)
    a_hertz = (3 * F * RS / (4 * E_star)) ** (1 / 3)
    print(f"\nHertz, 40 x 40, {formulation}, nu = {nu}: F / F_Hertz(a) - 1 = "
          f"{100 * (F / hertz_force(a, E_star) - 1):+.2f} %, a / a_Hertz(F) - 1 = {100 * (a / a_hertz - 1):+.2f} %")
    assert F == pytest.approx(hertz_force(a, E_star), rel=0.01)
    assert a == pytest.approx(a_hertz, rel=0.01)
