"""The contact law as one object from the caller to the solver (`fem.laws`).

Independent checks: the plain-data `ContactLaw` and the older keyword pair (contact=, friction=)
give the same path to the last bit (one conversion point, not two code paths); mu given twice
is refused, and a bad law or mu is refused with the field's name.
"""

from __future__ import annotations

import numpy as np
import pytest

from fem.cup import compress_cup
from fem.geometry import cup_geometry
from fem.interface import ContactLaw
from fem.laws import Coulomb, Frictionless, Sticking, plane_law
from fem.material import NeoHookean
from fem.mesh import cup_mesh

MAT = NeoHookean(E_Pa=4e6, nu=0.49)


@pytest.fixture(scope="module")
def mesh():
    return cup_mesh(cup_geometry("A"), "coarse")


@pytest.mark.parametrize("law,mu", [("frictionless", 0.0), ("sticking", 0.0), ("coulomb", 0.5)])
def test_contact_law_object_and_keywords_give_the_same_path(mesh, law, mu):
    a = compress_cup(mesh, MAT, contact=ContactLaw(law, mu), u_max_m=1.5e-3)
    b = compress_cup(mesh, MAT, contact=law, friction=mu, u_max_m=1.5e-3)
    assert np.array_equal(a.F0_N, b.F0_N) and np.array_equal(a.r_c_m, b.r_c_m)
    assert a.contact_law == b.contact_law == ContactLaw(law, mu)


def test_plane_law_is_the_one_conversion():
    assert plane_law(ContactLaw("coulomb", 0.3)) == plane_law("coulomb", 0.3) == Coulomb(0.3)
    assert isinstance(plane_law("sticking"), Sticking) and isinstance(plane_law(), Frictionless)
    assert plane_law(ContactLaw("coulomb", 2.0)).contact == ContactLaw("coulomb", 2.0)
    with pytest.raises(ValueError, match="^friction: give Coulomb's mu in the ContactLaw"):
        plane_law(ContactLaw("coulomb", 0.3), friction=0.2)
    with pytest.raises(ValueError, match=r"^friction: .*\[0, 100\]"):
        Coulomb(-1.0)
    with pytest.raises(ValueError, match="^contact: must be one of"):
        plane_law("glued")

