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


def test_non_increasing_fit_is_scipys_isotonic_regression():
    from scipy.optimize import isotonic_regression

    from reduced.stiffness_curve import non_increasing_fit

    rng = np.random.default_rng(7)
    for n in (1, 2, 5, 40, 300):
        y = np.cumsum(rng.normal(-0.1, 1.0, n))
        w = rng.uniform(0.1, 2.0, n)
        expected = isotonic_regression(y, weights=w, increasing=False).x
        np.testing.assert_allclose(non_increasing_fit(y, w), expected, rtol=1e-12, atol=1e-12)


def test_the_contact_edge_keeps_a_monotone_r_c_and_the_force_balance_of_a_refined_curve(setting):
    """The FEM's r_c moves outwards between fine load steps (its edge jumps by node spacings); the
    force balance takes the monotone fit, and the largest force a refined curve holds is the default
    curve's (the rim, not a fold, limits both) where r_c itself put folds in (58 N instead of 111 N
    at a quarter of the default step)."""
    study, uc, cup = setting
    default, refined = _curve(None), _curve(None, max_step=0.0125)
    assert default.contact_edge_m is default.r_c_m      # monotone already: taken as it is
    strip = refined.l_m > 0
    assert np.any(np.diff(refined.r_c_m[strip]) > 0)
    edge = refined.contact_edge_m[strip]
    assert np.all(np.diff(edge) <= 0)
    # the fit keeps r_c's weighted mean over the strip phase (a least-squares projection onto a cone
    # that holds the constants)
    u = refined.u_m[strip]
    w = 0.5 * (np.diff(u, prepend=u[0]) + np.diff(u, append=u[-1]))
    assert np.sum(w * edge) == pytest.approx(np.sum(w * refined.r_c_m[strip]), rel=1e-12)
    forces = [solve_lifetime(_model(study, c, uc, cup), 50.0, route="profile") for c in (default, refined)]
    assert [f.reason for f in forces] == ["reached_r1", "reached_r1"]
    assert forces[1].largest_force_N == pytest.approx(forces[0].largest_force_N, rel=0.01)
