"""The largest pull of a frictionless cup scouted with double steps (`fem.gas_pull`) against the
same pull followed in single steps all the way: the same maximum, in fewer Newton iterations."""

from __future__ import annotations

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


def test_the_scouted_pull_is_the_single_step_pull(sealed, monkeypatch):
    cup, state = sealed
    pull = gas_pull._Pull(cup, state, 0.02)
    (single, why), single_its = _counted(monkeypatch, lambda: pull.largest(*pull.follow(1)))
    (scouted, why2), scouted_its = _counted(monkeypatch, lambda: gas_pull.largest_pull_checked(cup, state))
    print(single, scouted, single_its, scouted_its)
    assert why is None and why2 is None
    assert scouted == pytest.approx(single, rel=1e-7)
    assert scouted_its < 0.8 * single_its
