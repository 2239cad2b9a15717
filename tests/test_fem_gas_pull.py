"""The largest pull of a frictionless cup scouted with double steps (`fem.gas_pull`) against the
same pull followed in single steps all the way: the same maximum, in fewer Newton iterations; and
Coulomb's pull in double steps where the contact makes no history (`fem.gas_pull._Pull.resumed`)."""

from __future__ import annotations

import numpy as np
import pytest

import fem.gas_pull as gas_pull
from fem.interface import ContactLaw
from reduced.cup import CUPS
from validation.bridge.fem_route import FemCup


@pytest.fixture(scope="module")
def sealed():
    cup = FemCup("A", "coarse", contact=ContactLaw("frictionless")).build(293.15, 1e5)
    return cup, cup.press_to(r_start_m=CUPS["A"].r_start_m)[-1]


def _counted(monkeypatch, run):
    """run() and the Newton iterations of the paths it followed."""
    iterations = []
    follow = gas_pull.follow_gas_path

    def counting(*args, on_step, **kwargs):
        def step(s):
            iterations.append(s.iterations)
            on_step(s)
        return follow(*args, on_step=step, **kwargs)
    monkeypatch.setattr(gas_pull, "follow_gas_path", counting)
    return run(), sum(iterations)


@pytest.fixture(scope="module")
def sealed_coulomb():
    cup = FemCup("A", "coarse", contact=ContactLaw("coulomb", 0.5)).build(293.15, 1e5)
    return cup, cup.press_to(r_start_m=CUPS["A"].r_start_m)[-1]


@pytest.mark.parametrize("cup_fixture, rel", [("sealed", 1e-7), ("sealed_coulomb", 1e-9)])
def test_the_fast_pull_is_the_single_step_pull(cup_fixture, rel, request, monkeypatch):
    """The pull as `largest_pull_checked` takes it against every single step, in under 80 % of
    the Newton iterations: frictionless scouted with double steps (the same states whatever the
    steps before); Coulomb 0.5, coarse, in double steps where no node lands, sticks again or
    turns (`_Pull.resumed`: the same states all the way, its maximum to Newton's tolerance, not
    the ~2e-6 by which halving the steps moves it; 192 against 253 iterations)."""
    cup, state = request.getfixturevalue(cup_fixture)
    pull = gas_pull._Pull(cup, state, 0.02)
    (single, why), single_its = _counted(monkeypatch, lambda: pull.largest(*pull.follow(1)))
    (fast, why2), fast_its = _counted(monkeypatch, lambda: gas_pull.largest_pull_checked(cup, state))
    assert why is None and why2 is None
    assert fast == pytest.approx(single, rel=rel)
    assert fast_its < 0.8 * single_its


def test_a_double_step_that_lands_or_resticks_a_node_makes_history():
    """`_history_free`: nodes may start to slide or leave the plane; a landing node, a sliding
    node that sticks again or turns makes a history the steps decide."""
    from fem.contact import ContactState

    def state(active, slip):
        return ContactState(np.array(active, bool), np.zeros(len(active)), np.array(slip, np.int8))
    a = state([1, 1, 1, 0], [0, -1, -1, 0])
    assert gas_pull._history_free(a, state([1, 1, 0, 0], [-1, -1, 0, 0]))     # slides, leaves
    assert not gas_pull._history_free(a, state([1, 1, 1, 1], [0, -1, -1, 0]))  # lands
    assert not gas_pull._history_free(a, state([1, 1, 1, 0], [0, 0, -1, 0]))   # sticks again
    assert not gas_pull._history_free(a, state([1, 1, 1, 0], [0, 1, -1, 0]))   # turns
