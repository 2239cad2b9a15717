"""The route "fem" in water (`validation.bridge.fem_route`, model.fluid = "water"): coarse cup A
pressed to r_start with the water expelled, sealed at V_w0, held at 10 N along its water branch,
water flowing in by eq (24) through each state's own profile.

Independent checks: every state holds the pull with the cavity full (V = V_w); the lifetime is
t = int dV_w / Q_w (the trapezoid against Simpson's rule on the same states); the inflow is
eq (24)'s, inversely proportional to the liquid's viscosity at each state with the mechanics
unchanged; the command line prints the Python call's numbers; the scene schema, the command line
and `example` take the fluid, and what the route does not model is refused before any work."""

from __future__ import annotations

import csv
import math
import re
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import simpson

import reduced
from tests.cli import run_cli
from validation.bridge.fem_route import FemCup, lifetime_integral, register, state_leak_rate
from validation.bridge.lifetimes import lifetimes
from validation.bridge.pipeline import surface_uc_table
from validation.bridge import products as products_module
from validation.bridge.products import Products, fem_route_options
from validation.scenes.schema import scene_from_mapping


@pytest.fixture(scope="module")
def model():
    return replace(reduced.reference_model(reduced.CUP_A, surface_uc_table()), fluid="water")


@pytest.fixture(scope="module")
def held(model):
    return lifetimes(model, [10.0], "fem", cup=FemCup("A", "coarse"))


def test_water_branch_holds_F1_with_the_cavity_full_to_its_detachment(held):
    life = held[0]
    assert life.route == "fem" and life.reason in ("fold", "reached_r1")
    assert 0.0 < life.lifetime_s < math.inf
    tr = life.trajectory
    assert np.allclose(tr["F_plate_N"], 10.0, atol=0.05)                      # every state holds the pull
    assert np.all(np.diff(tr["V_w_mm3"]) > 0) and np.all(np.diff(tr["t_s"]) >= 0)
    # incompressible: V = V_w to the multiplier's tolerance, c |V - V_w| <= 1 Pa = 1e-7 AL_FACTOR p_a
    assert np.allclose(tr["V_mm3"], tr["V_w_mm3"], rtol=1e-7, atol=0)
    assert tr["V_w_mm3"][0] == pytest.approx(life.details["V_w0_mm3"], rel=1e-12)   # pulled at V_w0
    assert life.details["V_w_max_mm3"] == pytest.approx(tr["V_w_mm3"][-1])
    assert "N" not in tr and "N_dot_per_s" not in tr
    assert held.largest_force_N > 10.0


def test_lifetime_is_the_integral_of_dV_w_over_Q_w(held):
    """t = int dV_w / Q_w: the trajectory's t is the trapezoid of its own columns, which agrees with
    Simpson's rule on the same states."""
    life = held[0]
    tr = life.trajectory
    V, q = 1e-9 * tr["V_w_mm3"], 1e-9 * tr["Q_w_mm3_per_s"]
    assert lifetime_integral(V, q)[-1] == pytest.approx(life.lifetime_s, rel=1e-12)
    assert tr["t_s"][-1] == pytest.approx(life.lifetime_s, rel=1e-12)
    inv = np.where(np.isinf(q), 0.0, 1.0 / q)
    assert simpson(inv, x=V) == pytest.approx(life.lifetime_s, rel=1e-2)


def test_the_inflow_is_eq_24_inverse_in_the_viscosity(model):
    """At the same states (the mechanics does not know the viscosity) the inflow scales as 1 / eta,
    and the gas law's flow through the same profile is another number (the route uses the liquid's)."""
    route = register()
    options = {**route.options, "cup": FemCup("A", "coarse")}
    sealed = route.seal(model, options)
    states = sealed.cup.move_plate(sealed.state, sealed.state.u_m - 0.2e-3, steps=2)[1:]
    thick = replace(model, liquid_viscosity_Pa_s=3.0 * model.liquid_viscosity_Pa_s)
    plane = sealed.cup.cup.plane
    for s in states:
        q = state_leak_rate(s, model, 4e6, plane=plane)
        assert 0.0 < q < math.inf
        assert state_leak_rate(s, thick, 4e6, plane=plane) == pytest.approx(q / 3.0, rel=1e-12)
        assert state_leak_rate(s, replace(model, fluid="air"), 4e6, plane=plane) != pytest.approx(q, rel=0.5)


def test_the_command_line_prints_the_python_calls_lifetime(capsys, tmp_path, held):
    out = tmp_path / "fem"
    code, text, err = run_cli(capsys, "lifetime", "--route", "fem", "--fluid", "water", "--cup", "A",
                              "--surface", "pmma-1.89", "--force", "10", "--fidelity", "coarse", "--out", out)
    assert code == 0, err
    head, columns, row = text.splitlines()
    life, d = held[0], held[0].details
    assert row.split() == ["10", f"{life.lifetime_s:.6g}", life.reason, f"{d['u_final_mm']:.3f}",
                           f"{d['p_b_final_Pa'] / 1e3:.4g}", f"{d['seal_r_final_mm']:.3f}"]
    assert f"water V_w0 = {d['V_w0_mm3']:.4g} mm^3" in head and f"{held.largest_force_N:.4g} N" in head
    with open(out / "trajectory_F1_10N.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert set(rows[0]) >= {"cup", "t_s", "V_w_mm3", "p_b_Pa", "u_mm", "F_plate_N", "V_mm3", "seal_r_mm",
                            "Q_w_mm3_per_s"}
    assert float(rows[-1]["t_s"]) == pytest.approx(life.lifetime_s, rel=1e-9)


def test_cavitation_is_refused_before_any_fem_work(capsys, tmp_path):
    out = tmp_path / "never"
    code, text, err = run_cli(capsys, "lifetime", "--route", "fem", "--fluid", "water", "--cavitation-kPa",
                              "2.34", "--out", out)
    assert code == 2 and text == ""
    line, = err.strip().splitlines()
    assert re.search("error: --route: .*drop --cavitation-kPa", line), line
    assert not out.exists()
    model = replace(reduced.reference_model(reduced.CUP_A, surface_uc_table()), fluid="water",
                    cavitation_pressure_Pa=2340.0)
    with pytest.raises(ValueError, match="^cavitation_pressure_Pa: the fem route's water"):
        reduced.solve_lifetime(model, 10.0, route="fem", cup=FemCup("A", "coarse"))


def test_scenes_and_example_take_the_fluid(capsys, tmp_path):
    """A scene's [fluid] kind = "water" reaches the fem route's model; `example --fluid water` the
    study; the coupled route, which models gas only, refuses water before any work."""
    study = scene_from_mapping({"stiffness": {"route": "fem"}, "fluid": {"kind": "water"},
                                "loads": {"F1_N": [10]}, "outputs": [{"kind": "lifetimes"}]}).study()
    assert study.loads.fluid == "water"
    products = Products(study)
    model = products_module._model(study, None, products.uc_table(), products.cup())
    assert model.fluid == "water"
    register().check(model, {**register().options, **fem_route_options(study)})     # accepted
    code, _, err = run_cli(capsys, "example", "--route", "coupled", "--fluid", "water", "--out", tmp_path / "x")
    assert code == 2 and "--fluid: --route coupled models a gas-filled cavity only" in err
    assert not (tmp_path / "x").exists()
