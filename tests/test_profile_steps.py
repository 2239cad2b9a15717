"""The profile route's lifetimes do not depend on where the FEM path ends: a path to u_max beyond
the default 0.9 h1 converges the default path's states (its load steps fall at the same u), so the
stiffness curve's samples, and the lifetimes interpolated between them, are the default's.

Before the steps were fractions of the default travel, cup A's coarse frictionless lifetime at
80 N was 25.26 s to the default u_max and 22.99 s to 8.466 mm (9 %), its sticking one at 5 N 2076 s
and 1639 s: the step-density part of the error is measured by benchmarks/bench_profile_steps.py."""

from __future__ import annotations

import numpy as np
import pytest

from fem.geometry import cup_geometry
from fem.interface import ContactLaw
from reduced.lifetime import solve_lifetime
from validation.bridge.pipeline import fem_curve, fem_path, neo_hookean
from validation.bridge.products import Products, _model
from validation.scenes.schema import load_scene

GEOMETRY = cup_geometry("A")
FORCES_N = (5.0, 80.0)


@pytest.fixture(scope="module")
def setting():
    """The main job's study (surface, cup) to feed the curves through."""
    from pathlib import Path

    study = load_scene(Path(__file__).resolve().parents[1] / "scenes" / "main.toml").study()
    products = Products(study)
    return study, products.uc_table(), products.cup()


def _curve(u_max_m, **opts):
    response = fem_path(GEOMETRY, neo_hookean(4e6, 0.49), ContactLaw("frictionless"), "coarse", u_max_m, **opts)
    return fem_curve(response, GEOMETRY.describe(), "coarse")


def _lifetimes(curve, setting):
    study, uc, cup = setting
    model = _model(study, curve, uc, cup)
    return np.array([solve_lifetime(model, F, route="profile").lifetime_s for F in FORCES_N])


def test_a_longer_path_samples_the_default_paths_states():
    default = _curve(None)
    longer = _curve(8.466e-3)
    shared = default.u_m[:-1]                 # the default's last step is shortened to end at 0.9 h1
    assert longer.u_m[-1] == pytest.approx(8.466e-3)
    np.testing.assert_array_equal(longer.u_m[:shared.size], shared)
    np.testing.assert_allclose(longer.F0_N[:shared.size], default.F0_N[:-1], rtol=1e-9)


def test_profile_lifetimes_do_not_depend_on_u_max(setting):
    default = _lifetimes(_curve(None), setting)
    for u_max_m in (8.466e-3, 9.0e-3):
        np.testing.assert_allclose(_lifetimes(_curve(u_max_m), setting), default, rtol=1e-3)


def test_a_shorter_path_keeps_its_resolution():
    short = _curve(0.3 * GEOMETRY.h1_m, max_step=0.1)
    assert short.u_m.size - 1 >= 10           # at least 1 / max_step steps of its own travel
