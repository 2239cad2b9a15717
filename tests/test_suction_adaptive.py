"""The adaptive suction table (`validation.bridge.coupled.adaptive`): the states it keeps are the
full grid's states, its refinement goes only where its error estimate asks, and its lifetimes
are the full grid's (slow: cup A's coarse FEM table)."""

import math
from dataclasses import replace

import numpy as np
import pytest

from fem.cup import cup_height
from fem.geometry import cup_geometry
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from fem.solver import SolverOptions
from fem.suction import SuctionStates, suction_grid
from reduced.critical_gap import illustrative_uc_table
from reduced.cup import cup_by_name
from reduced.lifetime import largest_holdable_force, reference_model, solve_lifetime
from tests.test_reduced_coupled import paper_table
from validation.bridge.coupled.adaptive import AdaptiveSpec, SuctionGoal, adaptive_axes, lattice_subtable


@pytest.fixture(scope="module")
def coarse_cup():
    mesh = cup_mesh(cup_geometry("A"), "coarse")
    return mesh, cup_height(mesh)


def test_kept_states_are_the_grids_states(coarse_cup):
    """Asked in the grid's order the solves are the grid's (bitwise); grown by rows and columns
    afterwards, each state is solved once and is the grid's to the solver's tolerance."""
    mesh, h1 = coarse_cup
    u, dp = np.array([0.1, 0.2, 0.3]) * h1, np.array([0.0, 5e3, 10e3, 20e3])
    full = suction_grid(mesh, NeoHookean(), u, dp)
    same = SuctionStates(mesh, NeoHookean()).grid(u, dp)
    assert np.array_equal(same.F1_N, full.F1_N) and np.array_equal(same.V_m3, full.V_m3)
    grown = SuctionStates(mesh, NeoHookean())
    grown.grid(u[[0, 2]], dp[[0, 3]])                 # the coarse grid first
    assert grown.solved == 4
    fine = grown.grid(u, dp)                           # then its midpoints
    assert grown.solved == u.size * dp.size
    tol = SolverOptions().rtol                         # Newton's relative residual tolerance
    np.testing.assert_allclose(fine.F1_N, full.F1_N, rtol=0, atol=tol * np.abs(full.F1_N).max())
    np.testing.assert_allclose(fine.V_m3, full.V_m3, rtol=tol, atol=0)
    np.testing.assert_allclose(fine.seal_r_m, full.seal_r_m, rtol=tol, atol=0)
    p_max = max(p.p_Pa.max() for row in full.profiles for p in row)
    for row, row_full in zip(fine.profiles, full.profiles):
        for p, q in zip(row, row_full):
            np.testing.assert_allclose(p.r_m, q.r_m, rtol=tol, atol=0)
            np.testing.assert_allclose(p.p_Pa, q.p_Pa, rtol=0, atol=tol * p_max)


# ---------------------------------------------------------------- refinement, on the paper's own table
@pytest.fixture(scope="module")
def paper_lattice():
    """Cup A's eqs (3)-(7) sampled on a 41 x 41 lattice (no FEM) and a goal of two forces."""
    model = reference_model(cup_by_name("A"), illustrative_uc_table())
    goal = SuctionGoal(replace(model, stiffness=None, interface="p_b"), (5.0, 20.0))
    return paper_table(model, 41, 41), goal


def _lifetimes(goal, table):
    model = replace(goal.model, suction=table)
    return np.array([solve_lifetime(model, F, route="coupled").lifetime_s for F in goal.forces_N]
                    + [largest_holdable_force(model, route="coupled")])


def _adaptive(lattice, goal, tol):
    asked = set()

    def table_on(iu, jd):
        asked.update((i, j) for i in iu for j in jd)
        return lattice_subtable(lattice, iu, jd)
    axes = adaptive_axes(table_on, lattice.u_m.size, lattice.dp_Pa.size, goal,
                         AdaptiveSpec(u_every=8, dp_every=8, tol=tol))
    return axes, asked


def test_refined_to_the_lattice_it_is_the_full_table(paper_lattice):
    """tol = 0 splits every interval a path crosses down to the lattice: the lifetimes are the
    full table's (the rows and columns no path reads do not enter), from fewer states."""
    lattice, goal = paper_lattice
    axes, asked = _adaptive(lattice, goal, 0.0)
    np.testing.assert_allclose(_lifetimes(goal, lattice_subtable(lattice, axes.u_index, axes.dp_index)),
                               _lifetimes(goal, lattice), rtol=1e-9)
    assert len(asked) < 0.5 * lattice.u_m.size * lattice.dp_Pa.size


def test_refinement_goes_only_where_the_estimate_asks(paper_lattice):
    """After the first split of the crossed intervals, an interval is split again only where its
    error estimate exceeded tol; with an infinite tol nothing is split twice, and the lifetimes
    come closer to the full table's as tol falls."""
    lattice, goal = paper_lattice
    full = _lifetimes(goal, lattice)
    errors = {}
    for tol in (math.inf, 1e-3):
        axes, _ = _adaptive(lattice, goal, tol)
        for before, after in zip(axes.rounds, axes.rounds[1:]):
            for split, error, start in ((after.split_u, before.error_u, 8), (after.split_dp, before.error_dp, 8)):
                for a, b in split:
                    parents = [p for p in error if p[0] <= a and b <= p[1]]
                    if b - a < start:          # a half of an earlier split: only if that one erred
                        assert parents and all(error[p] > tol for p in parents), (tol, a, b)
        gaps = np.diff(axes.u_index[:-1])
        if math.isinf(tol):
            assert len(axes.rounds) == 2 and gaps.min() >= 4
        errors[tol] = np.abs(_lifetimes(goal, lattice_subtable(lattice, axes.u_index, axes.dp_index)) / full - 1)
    assert errors[1e-3].max() < 1e-3 < errors[math.inf].max()


# ---------------------------------------------------------------- cup A's FEM table (slow)
@pytest.fixture(scope="module")
def pressed_tables():
    """Cup A, coarse, frictionless, pmma-1.89, built for 5, 10, 20, 40 N on the default grid's
    pressed rows (u > 0; the raised rows: tests/test_fem_route.py's mu0 check): the goal, the full
    table, the table with holes around the paths (the default) and the tensor sub-grid."""
    from validation.bridge.coupled.build import PRESSED_GRID, AdaptiveSpec, suction_table_for
    from validation.cli import build_parser
    from validation.commands.lifetime import build_model, build_uc

    args = build_parser().parse_args(["lifetime", "--surface", "pmma-1.89"])
    model = build_model(args).model
    goal = SuctionGoal(replace(model, stiffness=None, u_c=build_uc(args)), (5.0, 10.0, 20.0, 40.0))
    full = suction_table_for("A", fidelity="coarse", grid=PRESSED_GRID)
    around = suction_table_for("A", fidelity="coarse", goal=goal, grid=PRESSED_GRID)
    tensor = suction_table_for("A", fidelity="coarse", goal=goal, adaptive=AdaptiveSpec(), grid=PRESSED_GRID)
    return goal, full, around, tensor


@pytest.mark.slow
def test_adaptive_lifetimes_are_the_full_tables(pressed_tables):
    """The table around the paths gives the full grid's lifetimes and largest holdable force to the
    FEM solver's tolerance (its states are the grid's, reached by other ramps); the tensor
    sub-grid (AdaptiveSpec) to 0.5 %."""
    goal, full, around, tensor = pressed_tables
    expected = _lifetimes(goal, full)
    assert np.all(expected[:3] > 0) and expected[3] == 0.0      # 40 N: over the largest force
    np.testing.assert_allclose(_lifetimes(goal, around), expected, rtol=SolverOptions().rtol, atol=0)
    assert not around.complete
    np.testing.assert_allclose(_lifetimes(goal, tensor), expected, rtol=5e-3)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="since the largest holdable force follows the whole raise at N0 and "
                   "short gaps are filled, the around build solves 1,513 states (675 before), more than a tenth")
def test_the_table_around_the_paths_solves_a_tenth_of_the_grid(pressed_tables):
    _, full, around, _ = pressed_tables
    assert around.provenance["states_solved"] < full.u_m.size * full.dp_Pa.size / 10


@pytest.mark.slow
def test_the_tensor_subgrid_solves_a_third_of_the_grid(pressed_tables):
    _, full, _, tensor = pressed_tables
    assert tensor.provenance["states_solved"] < full.u_m.size * full.dp_Pa.size / 3


def test_goal_only_where_the_adaptive_table_holds():
    """Products build the adaptive table for frictionless contact without relaxation only."""
    from fem.interface import ContactLaw
    from reduced.viscoelastic import default_relaxation
    from validation.bridge.coupled.adaptive import goal_for

    model = reference_model(cup_by_name("A"), illustrative_uc_table())
    goal = goal_for(model, [5, 10], ContactLaw())
    assert goal.forces_N == (5.0, 10.0) and goal.model.stiffness is None and goal.model.suction is None
    assert goal_for(model, [5], ContactLaw("sticking")) is None
    assert goal_for(replace(model, relaxation=default_relaxation(), phi0_s=13.0), [5]) is None
    with pytest.raises(ValueError, match="forces_N"):
        goal_for(model, [0.0])


# ---------------------------------------------------------------- raised states (u <= 0)
def test_raised_states_are_the_sealed_gas_cups_and_open_without_suction(coarse_cup, tmp_path):
    """Above the touching height (u < 0) a dp-driven state, reached by raising the plate at fixed
    dp, is the state of the sealed cup raised at fixed gas content N (`fem.gas_path`, a path in
    N, not in dp) at that state's dp: frictionless states do not depend on the path. Without
    suction the raised cup hangs free: no seal, no pull. Unsealed states are null in the table
    and a value that reads one raises SealOpen."""
    from fem.gas_branch import equilibrium_branch
    from fem.gas_path import CupWithGas
    from reduced.suction_table import SealOpen, SuctionTable
    from reduced.coupled import CoupledCavity
    from validation.bridge.coupled.table import suction_table

    mesh, h1 = coarse_cup
    gas = CupWithGas.of(mesh, NeoHookean())
    branch = equilibrium_branch(gas, gas.press(0.5 * h1)[-1], F1_N=10.0)   # held at 10 N, N rising
    raised = next(s for s in branch.states if s.u_m < 0)
    dp = gas.p_a_Pa - raised.p_b_Pa
    assert dp > 0 and raised.F1_N == pytest.approx(10.0, rel=0.01)
    states = SuctionStates(mesh, NeoHookean())
    F1, N, V, r_k, *_, closed, _ = states.state(raised.u_m, dp)
    assert closed and N > 0
    assert F1 == pytest.approx(raised.F1_N, rel=1e-5, abs=1e-5 * abs(raised.F1_N) + 1e-6)
    assert V == pytest.approx(raised.V_m3, rel=1e-6) and r_k == pytest.approx(raised.seal_r_m, rel=1e-6)

    u, dps = np.array([raised.u_m, 0.1 * h1]), np.array([0.0, dp])
    grid = SuctionStates(mesh, NeoHookean()).grid(u, dps)
    assert grid.sealed.tolist() == [[False, True], [True, True]]
    assert abs(grid.F1_N[0, 0]) < 1e-9                       # the free cup carries nothing
    assert grid.F1_N[0, 1] == pytest.approx(F1, rel=1e-9)      # raised from the anchor, then kept
    table = suction_table(grid)
    assert np.isnan(table.F1_N[0, 0]) and table.profiles[0][0] is None and table.built.all()
    back = SuctionTable.from_json(table.to_json(tmp_path / "table.json"))
    assert back.sealed.tolist() == table.sealed.tolist() and np.isnan(back.V_m3[0, 0])
    cavity = CoupledCavity(table, lambda x: 1e-6, along_u="linear")
    with pytest.raises(SealOpen, match="seal is open"):
        cavity.F1(u[0], 0.5 * dp)
    assert cavity.F1(u[0], dp) == pytest.approx(F1, rel=1e-12)


def test_the_table_reads_a_lone_rim_corner_as_the_fem_route_does(tmp_path):
    """A cup pressed until its rim corner alone touches: the table records the corner as a ring
    load of its reaction, the plate's force (global equilibrium), and keeps it through its JSON;
    the leak through the table's state is the fem route's through the same cup pressed by its own
    path (`validation.bridge.fem_leak`), to the solver's tolerance, and not the lumped profile's."""
    from reduced.profile_leak import profile_leak_rate, ring_gaps
    from reduced.suction_table import SuctionTable
    from reduced.table_surface import solid_profile
    from validation.bridge.coupled.table import suction_table
    from validation.bridge.fem_leak import state_leak_rate
    from validation.bridge.fem_route import FemCup
    from validation.bridge.pipeline import surface_uc_table

    model = replace(reference_model(cup_by_name("A"), surface_uc_table()), interface="p_b")
    cup = FemCup("A", "coarse").build(model.gas.T_K, model.p_a_Pa)
    gas_state = cup.press(0.2e-3)[-1]
    grid = suction_grid(cup.mesh, NeoHookean(E_Pa=4e6, nu=0.49), [0.1e-3, 0.2e-3], [0.0, 1e3])
    table = SuctionTable.from_json(suction_table(grid).to_json(tmp_path / "table.json"))
    r, F = table.seal_rings[1][0]
    assert r.size == 1 and F[0] == pytest.approx(-table.F1_N[1, 0], rel=1e-9)   # the plate's force
    assert F[0] == pytest.approx(-gas_state.F1_N, rel=1e-5)

    p_b = 0.7 * model.p_a_Pa
    patch = model.u_c.patch_length_m

    def table_leak(t):
        solid = solid_profile(t, 1, 0, 1.0, 0.0, "p_b", patch)
        return profile_leak_rate(model.gas, model.p_a_Pa, p_b, solid.r_m, ring_gaps(solid, model.u_c, 4e6))
    fem = state_leak_rate(replace(gas_state, p_b_Pa=p_b, dp_Pa=model.p_a_Pa - p_b), model, 4e6,
                          plane=cup.cup.plane)
    assert table_leak(table) == pytest.approx(fem, rel=1e-4)
    lumped = replace(table, seal_rings=None)          # the reading before: the lumped profile
    assert table_leak(lumped) != pytest.approx(fem, rel=0.05)
    ring_off_profile = tuple(tuple(None if p is None else (np.array([0.5 * p.r_m[0]]), np.array([1.0])) for p in row)
                             for row in table.profiles)
    with pytest.raises(ValueError, match="seal_rings"):
        replace(table, seal_rings=ring_off_profile)


def test_a_raised_state_no_raise_reaches_holds_no_seal(coarse_cup, monkeypatch):
    """Where the raise at fixed dp cannot reach u (here: rejected below u = -0.2 h1, as a wall
    folding onto itself is) the state is one without a seal, and so is every deeper state at that
    dp, without another solve; the table says how many and why (SealOpen where a path reads it)."""
    from fem.integrity import StateRejected
    from fem.interface import ContactLaw
    from validation.bridge.coupled.table import holed_suction_table

    mesh, h1 = coarse_cup
    states = SuctionStates(mesh, NeoHookean())
    real, calls = states._segment, []

    def segment(mech, dirichlet, t_max, start, u_plate, where, options=None, predict=None):
        calls.append(u_plate)
        if u_plate < -0.2 * h1:
            raise StateRejected(f"{where}: the wall folds onto itself", step=0, t_from=0.0, t_to=1.0, cause="folds")
        return real(mech, dirichlet, t_max, start, u_plate, where, options, predict)
    monkeypatch.setattr(states, "_segment", segment)
    u, dp = np.array([-0.4 * h1, -0.3 * h1, -0.1 * h1, 0.05 * h1]), np.array([0.0, 3e4])
    built = np.zeros((4, 2), dtype=bool)
    built[:, 1] = True
    table = holed_suction_table(states, u, dp, built, ContactLaw())
    assert table.sealed[:, 1].tolist() == [False, False, True, True]
    assert np.isnan(table.F1_N[:2, 1]).all() and table.profiles[0][1] is None
    assert sum(c < -0.2 * h1 for c in calls) == 1                 # the deeper one not tried again
    assert table.provenance["unreached"]["states"] == 1 and "folds" in table.provenance["unreached"]["cause"]


def test_the_default_grids_raised_rows_reach_the_plate_floor(coarse_cup):
    """540 raised rows evenly from u = 0 down to the plate's floor h1 - 2 L (below it the states
    are refused before any solve); a full table keeps those down to -0.6 h1."""
    from fem.suction import plate_floor_of
    from validation.bridge.coupled.build import DEFAULT_GRID, FULL_DEPTH_H1, SuctionGridSpec, full_rows

    mesh, h1 = coarse_cup
    floor = plate_floor_of(mesh)
    assert floor < -h1                                         # cup A: -24.3 mm, h1 = 9.09 mm
    u = DEFAULT_GRID.u_m(h1, floor)
    raised = u[u <= 0]
    assert raised.size == DEFAULT_GRID.raised_rows + 1 and raised[0] == pytest.approx(floor, rel=1e-12)
    np.testing.assert_allclose(np.diff(raised), -floor / DEFAULT_GRID.raised_rows, rtol=1e-9)
    pressed = np.minimum(np.array(DEFAULT_GRID.u_fractions[1:]) * h1, h1)
    assert pressed.size == 105 and np.array_equal(u[u > 0], pressed)
    full = full_rows(DEFAULT_GRID, mesh)
    assert full[0] >= -FULL_DEPTH_H1 * h1 * (1 + 1e-12) and full[0] - (-FULL_DEPTH_H1 * h1) < -floor / 540
    with pytest.raises(ValueError, match="floor_m"):
        DEFAULT_GRID.u_m(h1)
    with pytest.raises(ValueError, match="raised_rows"):
        SuctionGridSpec((0.1,), (0.0, 1.0), raised_rows=-1)
    with pytest.raises(ValueError, match=r"u_m: .*h1 - 2 L"):
        SuctionStates(mesh, NeoHookean()).grid([1.01 * floor, 0.1 * h1], [0.0, 1e3])


def test_a_raise_started_on_the_secant_reaches_the_cold_started_state(coarse_cup, monkeypatch):
    """A raised state whose Newton starts on the secant of the two kept rows above it (at the same
    dp) is the state raised from the row above without that guess, to the solver's tolerance, in
    fewer Newton iterations."""
    import fem.suction

    mesh, h1 = coarse_cup
    du, dp = 0.005 * h1, 6e4
    rows = [-k * du for k in range(1, 7)]
    solved, iterations = {}, {}
    for name in ("cold", "warm"):
        states = SuctionStates(mesh, NeoHookean())
        for u in rows[:2]:
            states.state(u, dp)
        before = states.stats.newton_iterations
        with monkeypatch.context() as m:
            if name == "cold":                          # Newton from the row above as it is
                m.setattr(fem.suction, "_secant", lambda *args: None)
            solved[name] = [states.state(u, dp) for u in rows[2:]]
        iterations[name] = states.stats.newton_iterations - before
    tol = SolverOptions().rtol
    for w, c in zip(solved["warm"], solved["cold"]):
        assert w[8] and c[8]                            # both sealed
        assert abs(w[0] - c[0]) <= 10 * tol * abs(c[0])     # F1
        assert abs(w[2] - c[2]) <= 10 * tol * c[2]          # V
        assert w[3] == pytest.approx(c[3], rel=10 * tol)    # the seal radius
    assert iterations["warm"] < iterations["cold"]


def test_a_raised_state_far_below_its_column_is_ramped_in_its_row(coarse_cup):
    """A raised state with no kept state at its dp close above, but a sealed one at a smaller dp
    in its row, is ramped from that one: the same state (F1, V, r_k to the solver's tolerance)
    as the one raised from the anchor row, in fewer Newton iterations."""
    from fem.suction import RAISE_REACH_H1

    mesh, h1 = coarse_cup
    u, dp = -0.1 * h1, 5.1e4
    assert u < -RAISE_REACH_H1 * h1
    ramped, raised = SuctionStates(mesh, NeoHookean()), SuctionStates(mesh, NeoHookean())
    ramped.state(u, 5e4)
    spent = lambda states: states.stats.newton_iterations if states.stats else 0      # noqa: E731
    before = [spent(ramped), spent(raised)]
    r, c = ramped.state(u, dp), raised.state(u, dp)        # both solve the anchor row's state at dp
    iterations = [spent(ramped) - before[0], spent(raised) - before[1]]
    assert r[8] and c[8]
    tol = SolverOptions().rtol
    assert abs(r[0] - c[0]) <= 10 * tol * abs(c[0]) and abs(r[2] - c[2]) <= 10 * tol * c[2]
    assert r[3] == pytest.approx(c[3], rel=10 * tol)
    assert iterations[0] < iterations[1]


def test_a_guessed_raise_whose_state_folds_is_not_repeated(coarse_cup, monkeypatch):
    """A raise started on the secant that converges to a rejected state (the wall folds onto
    itself) is that raise's state: it is not solved again without the guess, and the state holds
    no seal, with the cause kept in `unreached`."""
    from fem.integrity import StateRejected

    mesh, h1 = coarse_cup
    du, dp = 0.005 * h1, 6e4
    states = SuctionStates(mesh, NeoHookean())
    for u in (-du, -2 * du):
        assert states.state(u, dp)[8]
    real, guessed = states._segment, []

    def segment(mech, dirichlet, t_max, start, u_plate, where, options=None, predict=None):
        guessed.append(predict is not None)
        if u_plate < -2.5 * du:
            raise StateRejected(f"{where}: the wall folds onto itself", step=0, t_from=0.0, t_to=1.0, cause="folds")
        return real(mech, dirichlet, t_max, start, u_plate, where, options, predict)
    monkeypatch.setattr(states, "_segment", segment)
    assert not states.state(-3 * du, dp)[8]
    assert guessed == [True]                                   # started on the secant, once
    assert "folds" in states.unreached[(-3 * du, dp)]
