"""Water in the cavity in the FEM (fem/water_cavity.py, fem/water_branch.py): the augmented
Lagrangian's force and tangent against finite differences, the constrained state against the
dp-driven state of fem.suction with the same volume (path independence at mu = 0), global
equilibrium, the bordered sensitivities against neighbouring states, water as the incompressible
limit of the trapped gas, and the branch at a held pull."""

from dataclasses import replace

import numpy as np
import pytest

from fem.geometry import cup_geometry
from fem.gas_path import CupWithGas
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from fem.suction import suction_grid
from fem.water_branch import cavity_pressure_difference, largest_pull, pull_sensitivities, water_branch
from fem.water_cavity import CupWithWater, WaterMechanics

RTOL = 1e-9      # tight solver tolerance: states compared across two paths to ~1e-6


@pytest.fixture(scope="module")
def mesh():
    return cup_mesh(cup_geometry("A"), "coarse")


@pytest.fixture(scope="module")
def path(mesh):
    """Pressed to 3 mm (water expelled), sealed, the plate raised to 2.5 mm, water let in by 1 %."""
    cup = CupWithWater.of(mesh, NeoHookean(), rtol=RTOL)
    pressed = cup.press(3e-3)
    pulled = cup.move_plate(pressed[-1], 2.5e-3, steps=2)
    leaked = cup.let_in(pulled[-1], 1.01 * pulled[-1].V_w_m3)
    return cup, pressed, pulled, leaked


def test_pressing_expels_the_water_and_sealed_stages_keep_the_constraint(path):
    """Pressed, p_b = p_a and V_w is the cavity's volume; pulled, V_w stays and the cavity volume
    equals it to 1e-9; raising the plate at fixed V_w pulls harder (p_b falls), letting water in
    at the held plate relaxes the pull."""
    cup, pressed, pulled, leaked = path
    assert all(s.p_b_Pa == cup.p_a_Pa and s.V_w_m3 == s.V_m3 for s in pressed)
    assert np.all(np.diff([s.V_w_m3 for s in pressed]) < 0)           # water expelled
    assert len({s.V_w_m3 for s in pulled}) == 1
    for s in pulled[1:] + leaked[1:]:
        assert s.V_m3 == pytest.approx(s.V_w_m3, rel=1e-9)
    assert pulled[-1].F1_N > pulled[1].F1_N > pressed[-1].F1_N
    assert pulled[-1].p_b_Pa < pulled[1].p_b_Pa < cup.p_a_Pa
    assert leaked[-1].F1_N < pulled[-1].F1_N and leaked[-1].p_b_Pa > pulled[-1].p_b_Pa


def test_augmented_lagrangian_force_and_tangent_are_exact(mesh, path):
    """The force is the energy's gradient and the tangent (with its rank-one term) the force's
    derivative: central differences along a random direction and towards the leaked state, off the
    constraint (V != V_w). The nodes on the plane keep their height (V_cav is cut there)."""
    cup, _, pulled, leaked = path
    s = pulled[-1]
    mech = WaterMechanics(cup.cup.mech, cup.cavity, 0.999 * s.V_w_m3, s.dp_Pa, cup.penalty(s.V_w_m3))
    u = s.state.u
    on_plane = np.flatnonzero(mech.coordinates(u)[1] <= cup.cavity.tolerance_m)
    assert on_plane.size > 3
    _, r, K = mech.evaluate(u)
    for d in (np.random.default_rng(7).standard_normal(u.size) * 1e-9, 1e-3 * (leaked[-1].state.u - u)):
        d[2 * on_plane + 1] = 0.0
        fd_E = (mech.energy(u + d) - mech.energy(u - d)) / 2.0
        assert fd_E == pytest.approx(r @ d, rel=1e-6)
        fd_r = (mech.internal_force(u + d) - mech.internal_force(u - d)) / 2.0
        assert np.linalg.norm(fd_r - K @ d) <= 1e-5 * np.linalg.norm(K @ d)
    # as the water flows in (the cavity grows as a whole) the penalty's rank-one term is most of it
    assert np.linalg.norm(fd_r - K.plain() @ d) > 0.1 * np.linalg.norm(K @ d)


def test_water_state_equals_the_dp_driven_state_of_its_volume(mesh, path):
    """Frictionless states are path independent: the water state at (u, V_w) is the state of
    `suction_grid` (pressed to u, dp ramped at the held plate) at the water's dp, and that state's
    volume is V_w; its pull and seal agree (to 3e-6 of the suction's resultant)."""
    _, _, pulled, leaked = path
    for s in (pulled[-1], leaked[-1]):
        g = suction_grid(mesh, NeoHookean(), u_m=[s.u_m], dp_Pa=[0.0, s.dp_Pa], rtol=RTOL)
        scale = s.dp_Pa * np.pi * s.seal_r_m**2
        assert g.V_m3[0, 1] == pytest.approx(s.V_w_m3, rel=1e-6)
        assert abs(g.F1_N[0, 1] - s.F1_N) <= 3e-6 * scale
        assert abs(g.contact_force_N[0, 1] - s.contact_force_N) <= 3e-6 * scale
        assert g.seal_r_m[0, 1] == pytest.approx(s.seal_r_m, rel=1e-6)


def test_plate_contact_and_pressure_balance(path):
    """Global equilibrium of every state: the plate's pull, the contact resultant (the integral
    of the contact pressure) and the water's dp over the wall's projection up to the loaded
    chain's end balance to round-off; the multiplier recovered from the equilibrium alone
    (`cavity_pressure_difference`) is the solved dp."""
    cup, pressed, pulled, leaked = path
    for s in pressed[-1:] + pulled[1:] + leaked[1:]:
        contact = float(np.sum(s.profile.p_gauss_Pa * s.profile.w_m2))
        suction = s.dp_Pa * np.pi * s.cut_r_m**2
        assert abs(s.F1_N + contact - suction) <= 1e-7 * max(contact, abs(s.F1_N))
        assert cavity_pressure_difference(cup, s.state) == pytest.approx(s.dp_Pa, rel=1e-5, abs=1e-3)


def test_water_is_the_incompressible_limit_of_the_trapped_gas(mesh, path):
    """A gas sealed at p_a and pulled at fixed N resists the cavity's growth with p_a / V: as
    p_a grows the gas state's dp = p_a - p_b tends to the water state's (the volume held), the
    distance falling ~ 1 / p_a."""
    _, _, pulled, _ = path
    water = pulled[1]                                  # the plate raised by 0.25 mm
    gap = []
    for p_a in (1e8, 1e9):
        gas = CupWithGas.of(mesh, NeoHookean(), p_a_Pa=p_a, rtol=RTOL)
        s = gas.move_plate(gas.press(3e-3)[-1], water.u_m)[-1]
        gap.append(abs(s.dp_Pa - water.dp_Pa) / water.dp_Pa)
    assert gap[1] < 2e-3 and gap[1] == pytest.approx(0.1 * gap[0], rel=0.2)


def test_pull_sensitivities_match_neighbouring_states(path):
    """dF1/dV_w and dF1/du of the bordered system against central differences of constrained
    states at V_w (1 +- 1e-5) and u +- 1e-4 mm."""
    cup, _, pulled, _ = path
    s = pulled[-1]
    dF1_dV, dF1_du = pull_sensitivities(cup, s)
    options = replace(cup.options, initial_step=1.0, max_step=1.0)

    def pull(u_m, V):
        step, _, _ = cup.solve_water(s.state, s.dp_Pa, s.u_m, u_m, s.V_w_m3, V, options)
        return float(np.sum(step.r_int[2 * cup.cup.top + 1]))
    dV, du = 1e-5 * s.V_w_m3, 1e-7
    assert (pull(s.u_m, s.V_w_m3 + dV) - pull(s.u_m, s.V_w_m3 - dV)) / (2 * dV) == pytest.approx(dF1_dV, rel=1e-4)
    assert (pull(s.u_m + du, s.V_w_m3) - pull(s.u_m - du, s.V_w_m3)) / (2 * du) == pytest.approx(dF1_du, rel=1e-4)


def test_branch_holds_the_pull_as_water_flows_in(mesh):
    """At a held pull the branch's states pull F1 with the cavity full (V = V_w) and balance;
    V_w rises along it to the detachment, which is its largest V_w (fold) or the last state with
    the seal closed."""
    cup = CupWithWater.of(mesh, NeoHookean())
    b = water_branch(cup, cup.press(4e-3)[-1], 10.0, du_m=0.5e-3)
    assert b.reason in ("fold", "seal opened") and b.detachment is b.states[-1]
    V_w = b.column("V_w_m3")
    assert np.all(np.diff(V_w) > 0) and b.N_max == V_w.max() > 2 * V_w[0]
    for s in b.states:
        scale = cup.p_a_Pa * np.pi * s.seal_r_m**2
        assert abs(s.F1_N - 10.0) <= 1e-6 * scale
        assert s.V_m3 == pytest.approx(s.V_w_m3, rel=1e-9)
        contact = float(np.sum(s.profile.p_gauss_Pa * s.profile.w_m2))
        # to the solver's tolerance (the default rtol 1e-6 of the reaction)
        assert abs(s.F1_N + contact - s.dp_Pa * np.pi * s.cut_r_m**2) <= cup.options.rtol * scale


def test_bad_input_is_refused(mesh):
    cup = CupWithWater.of(mesh, NeoHookean())
    pressed = cup.press(1e-3)[-1]
    with pytest.raises(ValueError, match="V_end_m3"):
        cup.let_in(pressed, -1.0)
    with pytest.raises(ValueError, match="u_m"):
        cup.move_plate(pressed, pressed.u_m)
    with pytest.raises(ValueError, match="p_a_Pa"):
        CupWithWater.of(mesh, NeoHookean(), p_a_Pa=0.0)
    with pytest.raises(TypeError, match="CupWithWater"):
        water_branch(CupWithGas.of(mesh, NeoHookean()), pressed, 10.0)


def test_water_holds_a_larger_pull_than_the_gas_sealed_alike(mesh, path):
    """Raised at a fixed content from the same pressed state, the gas expands (p_b >= 0: the pull
    is bounded by the ambient pressure on the seal) while the water goes into tension: the largest
    pull held in water exceeds the gas's, and exceeds p_a pi r_k^2 of the sealed state."""
    from fem.gas_pull import largest_pull_checked

    cup, pressed, _, _ = path
    water, why = largest_pull(cup, pressed[-1])
    gas_cup = CupWithGas.of(mesh, NeoHookean(), rtol=RTOL)
    sealed = gas_cup.press(3e-3)[-1]
    gas, _ = largest_pull_checked(gas_cup, sealed)
    assert water > gas > 0.0
    assert water > cup.p_a_Pa * np.pi * pressed[-1].seal_r_m**2
