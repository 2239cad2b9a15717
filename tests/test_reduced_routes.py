"""The lifetime's one entry point (reduced.solve_lifetime): registry dispatch, refusals that name
the field, one result type and one vocabulary of endings on every route, and physics through it
(the paper route against its quadrature; one model with one kappa on the paper and coupled routes
is tests/test_reduced_coupled.py's)."""

import math
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

import reduced
from reduced import (REASONS, ROUTES, LeakageModel, Lifetime, largest_holdable_force, reference_model,
                     register_route, solve_lifetime)
from reduced.critical_gap import illustrative_uc_table
from reduced.cup import CUP_A
from reduced.lifetime import lifetime_by_quadrature
from reduced.profile_leak import ContactProfile
from reduced.stiffness_curve import StiffnessCurve
from tests.test_reduced_coupled import paper_table


@pytest.fixture(scope="module")
def paper():
    return reference_model(CUP_A, illustrative_uc_table())


@pytest.fixture(scope="module")
def both(paper):
    """One model for the paper and coupled routes: the paper's cup with its own eqs (3)-(7) as
    the suction table (41 u x 81 dp), the interface gas at p_b as eq (6) has it."""
    return replace(paper, suction=paper_table(paper, 41, 81), interface="p_b")


@pytest.fixture(scope="module")
def profiled(paper):
    """The Appendix A curve with r, V, l of the cone and a uniform strip profile at eq 6's F0 load
    (none at u = 0, where nothing presses)."""
    cup, curve = paper.cup, paper.stiffness
    h = cup.h1_m - curve.u_m
    r = cup.radius(np.maximum(h, 1e-9))
    l = cup.contact_width(r)
    profiles = tuple(ContactProfile(np.array([a, a + w]), np.full(2, F / (2 * math.pi * a * w)))
                     if F > 0 else None for a, w, F in zip(r, l, curve.F0_N))
    return replace(paper, stiffness=StiffnessCurve(curve.u_m, curve.F0_N, cup.h1_m, r, l, cup.volume(r),
                                                   {"source": "test"}, profiles))


class _Toy:
    """A route that answers a fixed lifetime: what the entry point calls, recorded."""

    name = "toy"
    options = {"answer_s": 1.0}

    def __init__(self):
        self.calls = []

    def check(self, model, options):
        self.calls.append(("check", dict(options)))

    def solve(self, model, force_N, run, options):
        self.calls.append(("solve", force_N, run.rtol, dict(options)))
        return Lifetime(self.name, force_N, options["answer_s"], "reached_r1", "toy", 1.0,
                        {"t_s": [0.0, options["answer_s"]]})

    def largest_force(self, model, options):
        return 42.0


def test_a_registered_route_is_dispatched(paper):
    toy = register_route(_Toy())
    try:
        life = solve_lifetime(paper, 3.0, route="toy", rtol=1e-4, answer_s=7.0)
        assert life.lifetime_s == 7.0 and life.route == "toy"
        assert toy.calls == [("check", {"answer_s": 7.0}), ("solve", 3.0, 1e-4, {"answer_s": 7.0})]
        assert largest_holdable_force(paper, route="toy") == 42.0
        with pytest.raises(ValueError, match="route: 'toy' is registered already"):
            register_route(_Toy())
    finally:
        ROUTES.pop("toy")


@pytest.mark.parametrize("change,kw,field", [
    ({}, {"route": "wings"}, "route: unknown route 'wings'; registered: paper, profile, coupled"),
    ({}, {"route": "paper", "samples": 5}, "samples: not an option of route 'paper'"),
    ({}, {"route": "paper", "cup_laws": "sphere"}, "cup_laws:"),
    ({}, {"route": "coupled"}, "suction: the coupled route needs"),
    ({}, {"route": "profile"}, "stiffness: the profile route needs a curve with contact-pressure"),
    ({"stiffness": None}, {"route": "paper"}, "stiffness: the paper route needs"),
    ({"u_c": None}, {"route": "paper"}, "u_c: the paper route needs"),
    ({}, {"route": "profile", "cup_laws": "curve"}, "cup_laws: not an option of route 'profile'"),
])
def test_refusals_name_the_field(paper, change, kw, field):
    model = replace(paper, **change)
    with pytest.raises(ValueError) as err:
        solve_lifetime(model, 10.0, **kw)
    assert str(err.value).startswith(field) and "\n" not in str(err.value)


def test_the_coupled_route_refuses_what_it_does_not_model(both):
    with pytest.raises(ValueError, match="^fluid: the coupled route"):
        solve_lifetime(replace(both, fluid="water"), 10.0, route="coupled")
    with pytest.raises(ValueError, match="^refine: the coupled route"):
        solve_lifetime(both, 10.0, route="coupled", refine=4)
    with pytest.raises(ValueError, match="^force_N:"):
        solve_lifetime(both, -1.0, route="coupled")


def test_every_route_gives_one_result_type(both, profiled):
    runs = [solve_lifetime(both, 10.0), solve_lifetime(both, 10.0, route="paper", cup_laws="cone"),
            solve_lifetime(profiled, 10.0, route="profile"),
            solve_lifetime(both, 10.0, route="coupled", radial="strip"),
            solve_lifetime(both, 500.0, route="coupled"), solve_lifetime(both, 500.0),
            solve_lifetime(both, 10.0, t_max_s=1.0)]
    for life in runs:
        assert type(life) is Lifetime and life.reason in REASONS
        assert life.provenance["route"] == life.route
        s = life.summary()
        assert list(s)[:4] == ["force_N", "lifetime_s", "reason", "sealed"] and list(s)[-1] == "message"
        assert "t_s" in life.trajectory and "p_b_Pa" in life.trajectory
        assert not life.trajectory["t_s"].flags.writeable
    assert [r.reason for r in runs[4:]] == ["over_force", "over_force", "horizon"]
    assert runs[4].lifetime_s == runs[5].lifetime_s == 0.0 and runs[6].lifetime_s == math.inf
    assert runs[0].summary() == runs[1].summary()
    with pytest.raises(ValueError, match="^reason:"):
        Lifetime("x", 1.0, 1.0, "exploded", "", 1.0, {"t_s": [0.0]})


def test_the_paper_route_is_its_quadrature(paper):
    """Without relaxation the entry point's time integration is the quadrature t = int dN / Ndot."""
    for F1 in (5.0, 40.0):
        life = solve_lifetime(paper, F1, route="paper", rtol=1e-8)
        assert life.lifetime_s == pytest.approx(lifetime_by_quadrature(paper, F1), rel=1e-6)


def test_the_paper_routes_cup_laws_default_to_the_cone(profiled):
    """The route, not the model, chooses the cup laws: no route is the paper route on the cone."""
    assert solve_lifetime(profiled, 10.0).summary() == solve_lifetime(profiled, 10.0, route="paper",
                                                                      cup_laws="cone").summary()
    assert solve_lifetime(profiled, 10.0, cup_laws="curve").summary() != solve_lifetime(profiled, 10.0).summary()
    assert not hasattr(profiled, "seal") and not hasattr(profiled, "geometry")


def test_import_reduced_is_cheap_and_exposes_its_nouns():
    code = ("import sys, reduced; heavy = [m for m in sys.modules if m.split('.')[0] in "
            "('fem', 'validation', 'matplotlib', 'scipy', 'skfem')]; print(','.join(heavy)); "
            "[getattr(reduced, n) for n in reduced.__all__]; "
            "print(','.join(sorted(m for m in sys.modules if m.split('.')[0] in ('fem', 'matplotlib'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.splitlines() == ["", ""]
    assert {"LeakageModel", "solve_lifetime", "Lifetime", "ROUTES", "UcTable", "SuctionTable"} <= set(reduced.__all__)


def test_results_and_tables_survive_the_disk_cache():
    """The scenes' cache pickles u_c tables and lifetimes: a round trip gives the same values
    (read-only mappings are rebuilt by the constructor)."""
    import pickle

    from reduced import CUP_A, reference_model, solve_lifetime
    from reduced.critical_gap import illustrative_uc_table

    table = illustrative_uc_table()
    again = pickle.loads(pickle.dumps(table))
    assert (again.u_c_m == table.u_c_m).all() and (again.p_over_E == table.p_over_E).all()
    result = solve_lifetime(reference_model(CUP_A, table), 10.0)
    back = pickle.loads(pickle.dumps(result))
    assert back.summary() == result.summary()
    assert all((back.trajectory[k] == v).all() for k, v in result.trajectory.items())
