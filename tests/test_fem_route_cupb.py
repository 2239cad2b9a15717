"""Cup B on the route "fem": the shallow, thin cup (h1 = 5.37 mm, wall 15.0 mm long) held at 20 and
40 N is pulled far above its touching height before it lets go (the seal opens at u = -7.58 mm
at 20 N, the branch folds at u = -8.2 mm at 40 N), below the plate's old floor -h1; its walk ends
at the floor `fem.branch_end.plate_floor_m`, the apex twice the wall's length above the plane.

Independent checks: the wall's length against the cone's slant (r1 - r0) / cos(alpha); on every
state of the 20 N branch the pull is F1 and plate, contact pressure and suction balance; where
the seal opens the contact carries nothing, so the pull is the suction on the seal's disc,
F1 = dp pi r_k^2; at the 40 N fold dN/du changes sign; the lifetime is the integral of dN/Q up
to that detachment; the largest pull at N0 is a maximum inside the walk (the pull falls after
it), not where the walk stopped.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

import reduced
from fem.branch_end import FLOOR_STRETCH, plate_floor_m, up_to_most_gas, wall_length_m
from fem.gas_branch import equilibrium_branch
from fem.geometry import cup_geometry
from fem.interface import ContactLaw
from fem.gas_pull import largest_pull_checked
from validation.bridge.fem_route import DEFAULT_DU_M, FemCup, lifetime_integral, register
from validation.bridge.pipeline import surface_uc_table


@pytest.fixture(scope="module")
def model():
    return reduced.reference_model(reduced.CUP_B, surface_uc_table())


@pytest.fixture(scope="module")
def sealed(model):
    route = register()
    return route.seal(model, {**route.options, "cup": FemCup("B", "coarse")})


@pytest.fixture(scope="module")
def held_20(sealed):
    return equilibrium_branch(sealed.cup, sealed.state, 20.0, du_m=DEFAULT_DU_M)


def test_the_floor_is_the_apex_twice_the_wall_above_the_plane(sealed):
    g = cup_geometry("B")
    slant = (g.r1_m - g.r0_m) / math.cos(math.radians(g.alpha_deg))
    assert wall_length_m(sealed.cup) == pytest.approx(slant, rel=1e-9)
    assert plate_floor_m(sealed.cup) == pytest.approx(g.h1_m - FLOOR_STRETCH * slant, rel=1e-9)


def test_a_fold_ends_with_the_most_gas_held():
    states = [SimpleNamespace(N=n) for n in (1.0, 2.0, 3.0, 2.9)]
    assert [s.N for s in up_to_most_gas(states)] == [1.0, 2.0, 3.0]
    assert up_to_most_gas(states[:3]) == states[:3]


def test_cup_b_at_20_N_lets_go_where_its_seal_opens_with_plate_contact_and_suction_balanced(sealed, held_20):
    cup, b = sealed.cup, held_20
    assert b.reason == "seal opened" and b.detachment is b.states[-1]
    end = b.detachment
    assert plate_floor_m(cup) < end.u_m < -cup.h1_m           # past the old floor, inside the new
    assert b.N_max > 10.0 * b.states[0].N
    rim = cup.mesh.doflocs[0, cup.cavity.nodes[-1]]
    for s in b.states:
        scale = cup.p_a_Pa * math.pi * rim**2                  # the largest suction force
        assert abs(s.F1_N - 20.0) <= cup.options.rtol * scale   # the walk's root tolerance
        contact = float(np.sum(s.profile.p_gauss_Pa * s.profile.w_m2))
        assert abs(s.F1_N + contact - s.dp_Pa * math.pi * s.cut_r_m**2) <= 1e-7 * scale
    # the seal carries nothing when it opens: the pull is the suction on the seal's disc
    assert abs(end.contact_force_N) <= 0.02 * 20.0
    assert end.dp_Pa * math.pi * end.seal_r_m**2 == pytest.approx(20.0, rel=0.02)


def test_cup_b_at_40_N_folds(sealed):
    b = equilibrium_branch(sealed.cup, sealed.state, 40.0, du_m=DEFAULT_DU_M)
    assert b.reason == "fold" and b.detachment is b.states[-1]
    assert b.N_max == b.column("N").max()
    assert np.all(b.dN_du[:-1] < 0.0)                          # N rises as the plate rises ...
    assert abs(b.dN_du[-1]) <= 0.1 * abs(b.dN_du[0])          # ... up to its fold, dN/du = 0
    assert plate_floor_m(sealed.cup) < b.detachment.u_m < -sealed.cup.h1_m


def test_cup_b_holds_its_largest_pull_inside_the_walk(sealed):
    largest, partial = largest_pull_checked(sealed.cup, sealed.state)
    rim = sealed.cup.mesh.doflocs[0].max()
    assert partial is None and 40.0 < largest < sealed.cup.p_a_Pa * math.pi * rim**2   # below full vacuum


@pytest.mark.slow
def test_cup_b_at_20_N_has_a_lifetime_to_its_detachment(model, held_20):
    life = reduced.solve_lifetime(model, 20.0, route="fem", cup=FemCup("B", "coarse"))
    assert life.reason == "reached_r1" and 0.0 < life.lifetime_s < math.inf
    tr = life.trajectory
    assert np.allclose(tr["F_plate_N"], 20.0, atol=0.05)
    assert np.all(np.diff(tr["N"]) > 0) and np.all(np.diff(tr["t_s"]) >= 0)
    assert tr["N"][-1] == pytest.approx(held_20.N_max, rel=1e-12)
    assert life.lifetime_s == pytest.approx(lifetime_integral(tr["N"], tr["N_dot_per_s"])[-1], rel=1e-12)
    assert "largest_force_lower_bound" not in life.details and life.largest_force_N > 20.0


@pytest.mark.slow
def test_cup_b_at_40_N_with_mu_half_lets_go_with_the_most_gas_it_held(model, sealed):
    """Its walk crosses a slip to a state holding less gas (5.13 -> 4.98 N0), whose branch then
    folds: the leak never brings the cup there, it lets go at the slip with the most gas held."""
    cup = FemCup("B", "coarse", contact=ContactLaw("coulomb", 0.5))
    route = register()
    s = route.seal(model, {**route.options, "cup": cup})
    b = equilibrium_branch(s.cup, s.state, 40.0, du_m=DEFAULT_DU_M)
    life = reduced.solve_lifetime(model, 40.0, route="fem", cup=cup)
    assert b.reason == "fold" and life.reason == "fold"
    N = b.column("N")
    tr = life.trajectory
    assert np.all(np.diff(tr["N"]) > 0) and tr["N"][-1] == pytest.approx(N.max(), rel=1e-12)
    assert life.details["N_max"] == tr["N"][-1] >= b.N_max
    assert life.lifetime_s == pytest.approx(lifetime_integral(tr["N"], tr["N_dot_per_s"])[-1], rel=1e-12)
