"""validation.bridge.lifetimes: the one way the toolkit asks for lifetimes (reduced.solve_lifetime per force,
reduced.largest_holdable_force once), checked against second methods."""

import math
import warnings
from dataclasses import replace

import pytest

import reduced
from reduced.lifetime import lifetime_by_quadrature
from validation.bridge.lifetimes import ROUTES, lifetimes, route_laws, route_options


@pytest.fixture(scope="module")
def model():
    uc = reduced.uc_table(reduced.preset("pmma-1.89").spectrum(), 0.5)
    return reduced.reference_model(reduced.CUP_A, uc)


def test_route_names_are_reduced_registry():
    from validation.bridge.fem_route import register
    register()                             # the fem route registers itself on first use
    assert set(ROUTES) <= set(reduced.ROUTES)
    assert set(ROUTES) == {"paper", "profile", "coupled", "fem"}


def test_paper_route_agrees_with_the_quadrature(model):
    out = lifetimes(model, [10.0, 20.0], "paper", **route_options("paper"))
    assert [r.force_N for r in out] == [10.0, 20.0]
    assert all(isinstance(r, reduced.Lifetime) and r.route == "paper" for r in out)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for r in out:
            assert r.lifetime_s == pytest.approx(lifetime_by_quadrature(model, r.force_N), rel=1e-4)


def test_largest_force_is_where_the_cup_lets_go_at_once(model):
    largest = lifetimes(model, [], "paper", cup_laws="cone").largest_force_N
    assert 0 < largest < math.pi * reduced.CUP_A.r1_m ** 2 * model.p_a_Pa
    above, below = lifetimes(model, [1.001 * largest, 0.99 * largest], "paper", cup_laws="cone")
    assert above.reason == "over_force" and above.lifetime_s == 0
    assert below.lifetime_s > 0


def test_kappa_field_is_the_scaled_curve(model):
    """The model's kappa and a curve scaled by kappa are one cup (the paper's stiffness factor)."""
    by_field = lifetimes(replace(model, kappa=2.0), [20.0], "paper", cup_laws="cone")[0]
    by_curve = lifetimes(replace(model, stiffness=model.stiffness.scaled(2.0)), [20.0], "paper", cup_laws="cone")[0]
    assert by_field.lifetime_s == pytest.approx(by_curve.lifetime_s, rel=1e-12)


def test_progress_after_each_force(model):
    seen = []
    lifetimes(model, [10.0, 20.0], "paper", cup_laws="cone", progress=lambda f, m: seen.append((f, m)))
    assert seen == [(0.5, "F1 = 10 N"), (1.0, "F1 = 20 N")]


@pytest.mark.parametrize("route, laws, message", [("profile", "cone", "--cup-laws"),
                                                  ("coupled", "curve", "--cup-laws")])
def test_route_laws_refuse_what_the_route_cannot_use(route, laws, message):
    with pytest.raises(ValueError, match=message):
        route_laws(route, laws)


def test_route_laws_defaults():
    assert route_laws("paper") == "cone" and route_laws("paper", "curve") == "curve"
    assert route_laws("profile") == "curve"
    assert route_options("paper", "curve") == {"cup_laws": "curve"} and route_options("profile") == {}
