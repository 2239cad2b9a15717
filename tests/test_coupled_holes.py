"""A suction table with holes (`reduced.coupled_holes`, `validation.bridge.coupled.around`): where
every state a value reads is built it is the full table's value to the last bit, a value that
would read a hole raises `MissingStates` naming those states, and the table built around the
paths of a goal gives the full table's lifetimes and largest holdable force from a fraction of its
states (on the paper's own eqs 3-7 sampled on a grid: no FEM)."""

from dataclasses import replace

import numpy as np
import pytest

from reduced.coupled import CoupledCavity
from reduced.critical_gap import illustrative_uc_table
from reduced.cup import cup_by_name
from reduced.lifetime import largest_holdable_force, reference_model, solve_lifetime
from reduced.lifetime.routes import ROUTES
from reduced.suction_table import MissingStates, SuctionTable
from reduced.viscoelastic import default_relaxation
from tests.test_reduced_coupled import paper_table
from validation.bridge.coupled.adaptive import SuctionGoal
from validation.bridge.coupled.around import AroundSpec, around_paths, holed_subtable

FORCES_N = (5.0, 20.0)


@pytest.fixture(scope="module")
def lattice():
    """Cup A's eqs (3)-(7) on a 41 x 41 grid and a goal of two forces (interface gas at p_b)."""
    model = reference_model(cup_by_name("A"), illustrative_uc_table())
    goal = SuctionGoal(replace(model, stiffness=None, interface="p_b"), FORCES_N)
    return paper_table(model, 41, 41), goal


@pytest.fixture(scope="module")
def around(lattice):
    table, goal = lattice
    asked = []

    def table_on(built):
        asked.append(built.copy())
        return holed_subtable(table, built)
    return around_paths(table_on, table.u_m.size, table.dp_Pa.size, goal, AroundSpec(u_every=8, dp_every=8)), asked


def _results(goal, table):
    model = replace(goal.model, suction=table)
    return np.array([solve_lifetime(model, F, route="coupled").lifetime_s for F in goal.forces_N]
                    + [largest_holdable_force(model, route="coupled")])


def test_built_values_are_the_full_tables_to_the_bit(lattice):
    """F1, V and the leak read where their cells are built are the full table's bit for bit; a
    point whose cell reads a hole raises MissingStates naming exactly the missing states."""
    table, goal = lattice
    built = np.zeros(table.built.shape, dtype=bool)
    built[10:20, 5:12] = True
    full = CoupledCavity(table, goal.model.u_c, interface="p_b")
    holed = CoupledCavity(holed_subtable(table, built), goal.model.u_c, interface="p_b")
    u, dp = table.u_m, table.dp_Pa
    rng = np.random.default_rng(1)
    for a, b in zip(rng.uniform(u[11], u[18], 50), rng.uniform(dp[5], dp[11], 50)):
        assert (holed.F1(a, b), holed.V(a, b), holed.Ndot(a, b)) == (full.F1(a, b), full.V(a, b), full.Ndot(a, b))
    a, b = 0.5 * (u[18] + u[19]), 0.5 * (dp[8] + dp[9])      # monotone cubic along u: reads rows 17 ... 20
    with pytest.raises(MissingStates) as err:
        holed.F1(a, b)
    assert err.value.nodes == ((20, 8), (20, 9))
    assert err.value.u_m == (u[20], u[20]) and err.value.dp_Pa == (dp[8], dp[9])


def test_a_path_leaving_the_built_cells_raises(lattice):
    """A lifetime whose path runs out of the built states is an error naming states the table
    lacks, never a value read from a hole."""
    table, goal = lattice
    built = np.zeros(table.built.shape, dtype=bool)
    built[:, :] = True
    built[:, 20:] = False                                      # no state beyond dp = 48 kPa
    built[:8, :] = False                                       # nor below u = 0.2 h1
    model = replace(goal.model, suction=holed_subtable(table, built))
    with pytest.raises(MissingStates) as err:
        solve_lifetime(model, 5.0, route="coupled")
    assert err.value.nodes and not any(built[i, j] for i, j in err.value.nodes)


def test_table_around_the_paths_gives_the_full_tables_lifetimes(lattice, around):
    """Built around the goal's paths, the table with holes gives the full table's lifetimes and
    largest holdable force (to the root finders' tolerances) from under half its states, and
    every round asked only for more states."""
    table, goal = lattice
    build, asked = around
    np.testing.assert_allclose(_results(goal, build.table), _results(goal, table), rtol=1e-9, atol=0)
    assert build.asked.sum() < 0.5 * table.built.size and not build.table.complete
    rounds = asked[-len(build.rounds):]                      # the tables of the rounds, after the seed's
    assert len(rounds) >= 2 and all(np.all(later[earlier]) for earlier, later in zip(rounds, rounds[1:]))


def test_a_line_names_first_the_states_next_to_the_paths_last_point(lattice):
    """Along a line with nothing built near the crossing, the states named are those of the cells
    within NEAR_CELLS of the path's last point (the whole line's without one), and once those
    are built the gap's own rule names the rest; where the crossing is bracketed by built cells
    `near` changes nothing."""
    from reduced.coupled_holes import NEAR_CELLS, Holes

    table, goal = lattice
    u, dp = table.u_m, table.dp_Pa
    built = np.zeros(table.built.shape, dtype=bool)
    holes = Holes(built, u, dp, "pchip")
    at = u[20]                                                 # on a node: the line reads row 20 only
    value = lambda d: d                                        # noqa: E731  crosses 30.5 kPa in cell 30
    with pytest.raises(MissingStates) as whole:
        holes.root_cell("dp", at, value, dp[30] + 0.5 * (dp[31] - dp[30]), rising=True)
    assert whole.value.nodes == tuple((20, j) for j in range(dp.size))
    with pytest.raises(MissingStates) as near:
        holes.root_cell("dp", at, value, dp[30] + 0.5 * (dp[31] - dp[30]), rising=True, near=dp[27])
    assert near.value.nodes == tuple((20, j) for j in range(27 - NEAR_CELLS, 27 + NEAR_CELLS + 2))
    built[20, 27 - NEAR_CELLS:27 + NEAR_CELLS + 2] = True      # built: the crossing lies above them
    holes = Holes(built, u, dp, "pchip")
    with pytest.raises(MissingStates) as gap:
        holes.root_cell("dp", at, value, dp[30] + 0.5 * (dp[31] - dp[30]), rising=True, near=dp[27])
    assert gap.value.nodes == tuple((20, j) for j in range(27 + NEAR_CELLS + 2, dp.size))
    built[20, :] = True
    holes = Holes(built, u, dp, "pchip")
    target = dp[30] + 0.5 * (dp[31] - dp[30])
    assert holes.root_cell("dp", at, value, target, rising=True, near=dp[3]) == \
        holes.root_cell("dp", at, value, target, rising=True) == (dp[30], dp[31])


def test_the_paths_last_point_saves_states_not_values(lattice, monkeypatch):
    """Built with the missing states named next to each path's last point, the table gives the
    same lifetimes and largest force as when whole gaps are named, from fewer states."""
    import reduced.coupled_holes as coupled_holes

    table, goal = lattice
    near = around_paths(lambda built: holed_subtable(table, built), table.u_m.size, table.dp_Pa.size, goal,
                        AroundSpec(u_every=8, dp_every=8))
    monkeypatch.setattr(coupled_holes, "NEAR_CELLS", 10**6)     # every gap named whole
    whole = around_paths(lambda built: holed_subtable(table, built), table.u_m.size, table.dp_Pa.size, goal,
                         AroundSpec(u_every=8, dp_every=8))
    np.testing.assert_allclose(_results(goal, near.table), _results(goal, whole.table), rtol=1e-9, atol=0)
    assert near.asked.sum() < whole.asked.sum()


def test_a_branch_that_folds_reads_no_state_past_its_fold(lattice):
    """A branch whose gas content folds (here: the paper's table with a cavity that shrinks
    below u = h1 / 2) ends at the fold, and its walks stop there: with every state three rows
    past the fold missing, its lifetime is the complete table's (to the root finders' tolerance:
    they bracket inside built cells), not MissingStates."""
    table, goal = lattice
    h1 = goal.model.cup.h1_m
    shrink = 1 - 0.8 * np.clip((0.5 * h1 - table.u_m) / (0.5 * h1), 0, 1)
    folding = replace(table, V_m3=table.V_m3 * shrink[:, None])
    def lifetime(suction):
        cavity, u_start, _ = ROUTES["coupled"].cavity(replace(goal.model, suction=suction), ROUTES["coupled"].options)
        return cavity.lifetime(5.0, u_start)
    full = lifetime(folding)
    assert full.reason == "fold"
    built = np.ones(table.built.shape, dtype=bool)
    built[table.u_m < full.u_m[-1] - 3 * (table.u_m[1] - table.u_m[0])] = False
    assert not built.all()
    holed = lifetime(holed_subtable(folding, built))
    assert holed.reason == "fold" and holed.lifetime_s == pytest.approx(full.lifetime_s, rel=1e-9, abs=0)


def test_stiffer_cup_reads_its_own_paths(lattice):
    """kappa = 2: the cup answers dp as the table's does dp / 2, and its top dp (p_a) falls inside
    the table's last cell; built around its paths the table still gives the full one's results."""
    table, goal = lattice
    stiff = SuctionGoal(replace(goal.model, kappa=2.0), (5.0, 60.0))
    build = around_paths(lambda built: holed_subtable(table, built), table.u_m.size, table.dp_Pa.size, stiff,
                         AroundSpec(u_every=8, dp_every=8))
    np.testing.assert_allclose(_results(stiff, build.table), _results(stiff, table), rtol=1e-9, atol=0)
    assert build.asked.sum() < 0.5 * table.built.size


def test_holed_table_json_round_trip_and_checks(lattice, tmp_path):
    """Holes are null in the JSON and come back as holes; a hole must be one in every grid, with
    no profile, and relaxation refuses a table with holes."""
    table, goal = lattice
    built = np.ones(table.built.shape, dtype=bool)
    built[3, 4] = built[30, 0] = False
    holed = holed_subtable(table, built)
    back = SuctionTable.from_json(holed.to_json(tmp_path / "t.json"))
    assert np.array_equal(back.built, built) and not back.complete
    assert '"F1_N": [[' in (tmp_path / "t.json").read_text() and "NaN" not in (tmp_path / "t.json").read_text()
    np.testing.assert_array_equal(back.F1_N[built], table.F1_N[built])
    V = np.array(holed.V_m3)
    V[3, 4] = 1e-6
    with pytest.raises(ValueError, match="V_m3: .*nan only at a hole"):
        replace(holed, V_m3=V)
    with pytest.raises(ValueError, match="profiles: expected null at every hole"):
        replace(holed, profiles=table.profiles)
    with pytest.raises(ValueError, match="relaxation needs a table without holes"):
        CoupledCavity(holed, goal.model.u_c, relaxation=default_relaxation(), phi0_s=13.0)
