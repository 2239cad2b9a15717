"""The route "fem" (`validation.bridge.fem_route`): coarse cup A pressed to r_start, sealed, held
at F1 along its FEM branch, the leak through each state's own profile.

Independent checks: at mu = 0 the lifetime equals the table-coupled route's (the same cup through
its (u, dp) suction table, started from the same sealed content N0, to the seal's opening) to 1 %
(slow: the default grid's table around the paths); the lifetime converges as the branch's plate step is halved; the quadrature against
Simpson's rule on the same states; the detachment from the branch, not from the solver."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import simpson
from scipy.optimize import brentq

import reduced
from fem.interface import ContactLaw
from validation.bridge.fem_route import FemCup, Press, lifetime_integral
from validation.bridge.lifetimes import lifetimes
from validation.bridge.pipeline import surface_uc_table


@pytest.fixture(scope="module")
def model():
    return reduced.reference_model(reduced.CUP_A, surface_uc_table())


@pytest.fixture(scope="module")
def frictionless(model):
    return lifetimes(model, [10.0], "fem", cup=FemCup("A", "coarse"))


def test_frictionless_branch_holds_F1_to_its_detachment(frictionless):
    life = frictionless[0]
    assert life.route == "fem" and life.reason in ("fold", "reached_r1")
    assert 0.0 < life.lifetime_s < math.inf
    tr = life.trajectory
    assert np.allclose(tr["F_plate_N"], 10.0, atol=0.05)         # every state holds the pull
    assert np.all(np.diff(tr["N"]) > 0) and np.all(np.diff(tr["t_s"]) > 0)   # gas in, time on
    assert tr["N"][0] == pytest.approx(life.details["N0"], rel=0.02)          # pulled at N0
    # the gas law at every state, p_b V = N k_B T
    assert np.allclose(tr["p_b_Pa"] * tr["V_mm3"] * 1e-9, tr["N"] * reduced.AIR.kT_J, rtol=1e-9)
    assert frictionless.largest_force_N > 10.0


def test_quadrature_in_N_agrees_with_simpson(frictionless):
    """The trapezoid of 1/Q in N against Simpson's rule on the same branch states."""
    tr = frictionless[0].trajectory
    q, N = tr["N_dot_per_s"], tr["N"]
    inv = np.where(np.isinf(q), 0.0, 1.0 / q)
    assert lifetime_integral(N, q)[-1] == pytest.approx(simpson(inv, x=N), rel=5e-3)


def test_over_force_detaches_at_once(model, frictionless):
    F = 1.2 * frictionless.largest_force_N
    life = reduced.solve_lifetime(model, F, route="fem", cup=FemCup("A", "coarse"))
    assert life.reason == "over_force" and life.lifetime_s == 0.0


def test_bad_options_name_the_field(model):
    with pytest.raises(ValueError, match="^cup: "):
        lifetimes(model, [10.0], "fem")
    with pytest.raises(ValueError, match="^press: "):
        Press("depth", 1.0)
    with pytest.raises(ValueError, match="^du_m: "):
        lifetimes(model, [10.0], "fem", cup=FemCup(), du_m=-1.0)
    with pytest.raises(ValueError, match="^largest: "):
        lifetimes(model, [10.0], "fem", cup=FemCup(), largest="no")


def test_the_largest_force_is_computed_only_when_asked(model, monkeypatch):
    """largest=False: no largest pull run (it would raise here), the result says it was not
    computed instead of a bare NaN, and the lifetime is the one computed with it (a press of
    its own, so no cached pull of another test answers)."""
    import fem.gas_pull

    cup, press = FemCup("A", "coarse"), Press("r_start_m", 12.1e-3)
    with monkeypatch.context() as m:
        m.setattr(fem.gas_pull, "largest_pull_checked", _refuse)
        life = reduced.solve_lifetime(model, 10.0, route="fem", cup=cup, press=press, largest=False)
        with pytest.raises(AssertionError, match="largest pull ran"):
            reduced.solve_lifetime(model, 10.0, route="fem", cup=cup, press=press)
    assert math.isnan(life.largest_force_N) and "not computed" in life.details["largest_force"]
    full = reduced.solve_lifetime(model, 10.0, route="fem", cup=cup, press=press)
    assert full.lifetime_s == life.lifetime_s and full.largest_force_N > 10.0


def _refuse(*args, **kwargs):
    raise AssertionError("the largest pull ran")


def test_coulomb_run_completes(model):
    life = reduced.solve_lifetime(model, 10.0, route="fem",
                                  cup=FemCup("A", "coarse", contact=ContactLaw("coulomb", 0.5)))
    assert life.reason in ("fold", "reached_r1") and 0.0 < life.lifetime_s < math.inf


@pytest.mark.slow
@pytest.mark.parametrize("force_N", [10.0, 20.0])
def test_lifetime_converges_as_the_plate_step_is_halved(model, force_N):
    """At 20 N the seal's contact narrows to its last ring and Q falls 7-fold within two default
    plate steps: the route's refinement of the branch there keeps the lifetime within 1 % of the
    halved step's (unrefined it was 5 % short)."""
    cup = FemCup("A", "coarse")
    coarse = reduced.solve_lifetime(model, force_N, route="fem", cup=cup)
    fine = reduced.solve_lifetime(model, force_N, route="fem", cup=cup,
                                  du_m=0.5 * coarse.provenance["options"]["du_m"])
    assert fine.lifetime_s == pytest.approx(coarse.lifetime_s, rel=0.01)


@pytest.fixture(scope="module")
def sealed_start(model):
    """The fem route's sealed cup and the plate displacement where, raised at its N0, it pulls
    nothing: the table route's start with the same sealed content."""
    from validation.bridge.fem_route import register

    route = register()
    sealed = route.seal(model, {**route.options, "cup": FemCup("A", "coarse")})
    return brentq(lambda u: sealed.cup.move_plate(sealed.state, u)[-1].F1_N,
                  0.3 * sealed.state.u_m, (1 - 1e-6) * sealed.state.u_m, xtol=1e-10)


@pytest.fixture(scope="module")
def fem_lives(model):
    return {F: reduced.solve_lifetime(model, F, route="fem", cup=FemCup("A", "coarse")) for F in (5.0, 10.0, 20.0)}


@pytest.fixture(scope="module")
def table(model, sealed_start, fem_lives):
    """The default grid's suction table around the table route's paths at 5, 10 and 20 N from
    that start, its build hinted with the FEM branches' (u, dp) (where to look, not values); the
    largest holdable force's path is not built (`benchmarks/bench_coupled_raised.py`)."""
    from validation.bridge.coupled.adaptive import SuctionGoal
    from validation.bridge.coupled.build import suction_table_for

    hint = []
    for life in fem_lives.values():
        u, dp = 1e-3 * life.trajectory["u_mm"], model.p_a_Pa - life.trajectory["p_b_Pa"]
        hint += list(zip(u, dp)) + [(sealed_start + s * (u[0] - sealed_start), s * dp[0])
                                    for s in np.linspace(0.0, 1.0, 40)]       # the pull, at N0
    goal = SuctionGoal(dataclasses.replace(model, suction=None, stiffness=None), (5.0, 10.0, 20.0),
                       u_start_m=sealed_start, hint=tuple(hint), largest=False)
    return suction_table_for("A", fidelity="coarse", goal=goal)


@pytest.mark.slow
@pytest.mark.parametrize("force_N", [5.0, 10.0, 20.0])
def test_mu0_equals_the_table_coupled_route(model, table, sealed_start, fem_lives, force_N):
    """Two paths to one answer: the FEM branch at N as unknown against the (u, dp) table's branch,
    started from the same sealed content, both ending where the seal opens (the table's states
    above the touching height, u < 0, say where no node of the cavity is on the plane), both
    reading a seal narrowed to one node by its reaction (`reduced.coupled_seal`): whole lifetimes
    within 1 %."""
    from reduced.lifetime.routes import ROUTES

    route = ROUTES["coupled"]          # its cavity, as the route builds it from the model
    cavity, u_start, _ = route.cavity(dataclasses.replace(model, suction=table),
                                      {**route.options, "u_start_m": sealed_start})
    life = fem_lives[force_N]
    coupled = cavity.lifetime(force_N, u_start)
    tr = life.trajectory
    assert coupled.N[0] == pytest.approx(tr["N"][0], rel=2e-3)
    assert life.reason == coupled.reason == "reached_r1"
    assert coupled.u_m[-1] < 0 and tr["u_mm"][-1] < 0
    assert coupled.lifetime_s == pytest.approx(life.lifetime_s, rel=0.01)


@pytest.mark.slow
def test_the_largest_pull_of_a_sticking_cup_is_searched_past_its_slips():
    """Raised at fixed N, the sticking cup's pull drops by ~20 % where its seal slips and then
    rises again: the search goes on past the slip (it stopped there before, at 16.07 N), so the
    largest pull exceeds every pull before the first slip; frictionless (no slips) is unchanged."""
    from fem.interface import ContactLaw
    from reduced.cup import CUPS
    from fem.gas_pull import largest_pull_checked
    from validation.bridge.fem_route import FemCup

    seen = {}
    for law in ("sticking", "frictionless"):
        cup = FemCup("A", "coarse", contact=ContactLaw(law)).build(293.15, 1e5)
        sealed = cup.press_to(r_start_m=CUPS["A"].r_start_m)[-1]
        seen[law] = largest_pull_checked(cup, sealed)
    print(seen)
    assert seen["sticking"][1] is None and seen["sticking"][0] > 1.5 * 16.07
    assert seen["frictionless"] == (pytest.approx(51.5653, rel=1e-5), None)
