"""The fem route as a Study route: scene files, sweep files and `cupcheck example` spell it, the
schema refuses what the route does not model (one line naming the key), and a real coarse run of a
scene gives the Python call's lifetime, a trajectory whose t = int dN / Q closes, and the largest
holdable force."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from tests.cli import run_cli
from validation.bridge import products as products_module
from validation.bridge.products import Products, fem_route_options
from validation.scenes.schema import scene_from_mapping
from validation.sweeps.evaluate import geometry_of, study_of
from validation.sweeps.spec import sweep_from_mapping

LIFE = [{"kind": "lifetimes"}]


def _fem(**tables):
    return {"stiffness": {"route": "fem", **tables.pop("stiffness", {})}, "outputs": LIFE, **tables}


def test_a_fem_scene_is_the_fem_routes_cup_and_press():
    study = scene_from_mapping(_fem(contact={"law": "coulomb", "friction": 0.5}, material={"E_MPa": 5.0},
                                    loads={"press_force_N": 20, "F1_N": [10]},
                                    stiffness={"fidelity": "medium", "du_mm": 0.1})).study()
    options = fem_route_options(study)
    cup, press = options["cup"], options["press"]
    assert (cup.geometry, cup.fidelity, cup.E_Pa, cup.nu) == ("A", "medium", 5e6, 0.49)
    assert (cup.contact.law, cup.contact.friction) == ("coulomb", 0.5)
    assert (press.kind, press.value, options["du_m"]) == ("force_N", 20.0, pytest.approx(1e-4))
    pressed = scene_from_mapping(_fem(loads={"press_u_mm": 4})).study()
    assert (fem_route_options(pressed)["press"].kind, fem_route_options(pressed)["press"].value) == ("u_m", 4e-3)
    at_r_start = scene_from_mapping(_fem(loads={"r_start_mm": 13})).study()
    assert fem_route_options(at_r_start)["press"] is None                # pressed to the cup's r_start
    assert Products(at_r_start).cup().r_start_m == pytest.approx(13e-3)


@pytest.mark.parametrize("data,message", [
    (_fem(stiffness={"source": "appendix-a"}), "stiffness.route: 'fem' needs source = \"fem\""),
    (_fem(material={"relaxation": "default"}), "material.relaxation: the fem route's wall"),
    (_fem(loads={"kappa": 2}), "loads.kappa: the fem route's stiffness is the FEM's own"),
    (_fem(sweep={"key": "loads.kappa", "values": [1, 2]}), "sweep.key: the fem route's stiffness"),
    (_fem(loads={"r_start_mm": 12, "press_u_mm": 3}), "loads.press_u_mm: the cup is pressed one way"),
    (_fem(loads={"press_force_N": -1}), "loads.press_force_N: must be > 0"),
    (_fem(stiffness={"du_mm": 0}), "stiffness.du_mm: must be > 0"),
    ({"loads": {"press_u_mm": 3}, "outputs": LIFE}, "loads.press_u_mm: only for stiffness.route = \"fem\""),
    ({"stiffness": {"du_mm": 0.1}, "outputs": LIFE}, "stiffness.du_mm: only for stiffness.route = \"fem\""),
    ({**_fem(), "outputs": [{"kind": "figure", "figure": "r_pb_vs_time"}]}, "outputs[0].figure: r_pb_vs_time draws"),
])
def test_the_scene_schema_refuses_what_the_fem_route_does_not_model(data, message):
    with pytest.raises(ValueError) as exc:
        scene_from_mapping(data)
    assert message in str(exc.value) and "\n" not in str(exc.value)


def test_a_sweep_file_takes_the_fem_route():
    spec = sweep_from_mapping({"base": {"route": "fem", "F1_N": [10]}, "axes": [{"name": "r_start_mm",
                                                                                   "values": [11, 13]}]})
    design = spec.designs()[1]
    study = study_of(design, geometry_of(design))
    assert (study.route, study.cup_laws, study.loads.r_start_mm) == ("fem", None, 13.0)
    assert fem_route_options(study)["cup"].geometry is study.design.geometry
    plain = sweep_from_mapping({}).designs()[0]
    assert "route" not in plain and study_of(plain, geometry_of(plain)).route == "paper"   # hashes unchanged
    with pytest.raises(ValueError, match="base.route: expected one of paper, profile, fem, got 'coupled'"):
        sweep_from_mapping({"base": {"route": "coupled"}})


@pytest.mark.parametrize("argv,message", [
    (["--press-u-mm", "3"], "--press-u-mm: only for --route fem"),
    (["--route", "fem", "--r-start-mm", "12", "--press-force-N", "5"], "--press-force-N: the cup is pressed one way"),
    (["--route", "fem", "--l0-mm", "1", "--l1-mm", "1"], "--l0-mm: the fem route's seal"),
    (["--route", "fem", "--du-mm", "-1"], "--du-mm: must be > 0, got -1"),
    (["--route", "fem", "--press-force-N", "2e6"], "--press-force-N = 2e+06: did you give mN?"),
    (["--route", "fem", "--cup-laws", "cone"], "--cup-laws: the fem route"),
])
def test_example_refuses_bad_fem_route_options_before_any_work(capsys, tmp_path, argv, message):
    code, _, err = run_cli(capsys, "example", "--out", tmp_path / "out", *argv)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_a_fem_scene_gives_the_python_calls_lifetime_and_a_closed_trajectory(tmp_path):
    import reduced
    from validation.bridge.fem_route import FemCup
    from validation.bridge.pipeline import surface_uc_table
    from validation.scenes.outputs import run_scene

    scene = _fem(loads={"F1_N": [10]}, outputs=[{"kind": "lifetimes"}, {"kind": "trajectories"}])
    run_scene(scene, tmp_path / "out", cache_dir=tmp_path / "cache")
    with open(tmp_path / "out" / "lifetimes.csv", newline="") as f:
        row, = list(csv.DictReader(f))
    model = reduced.reference_model(reduced.CUP_A, surface_uc_table())
    life = reduced.solve_lifetime(model, 10.0, route="fem", cup=FemCup("A", "coarse"))
    assert (row["route"], row["reason"]) == ("fem", life.reason)
    assert float(row["lifetime_s"]) == pytest.approx(life.lifetime_s, rel=1e-9)
    assert float(row["largest_force_N"]) == pytest.approx(life.largest_force_N, rel=1e-9)
    assert float(row["largest_force_N"]) > 10.0                       # it held 10 N for a while
    with open(tmp_path / "out" / "trajectories_F1_10N.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert {"t_s", "N", "p_b_Pa", "u_mm", "F_plate_N", "V_mm3", "r_c_mm", "r_out_mm", "N_dot_per_s"} <= set(rows[0])
    N, q, t = (np.array([float(r[k]) for r in rows]) for k in ("N", "N_dot_per_s", "t_s"))
    inv = np.where(np.isinf(q), 0.0, 1.0 / q)                         # t = int dN / Q, by the trapezoid
    assert np.sum(0.5 * (inv[1:] + inv[:-1]) * np.diff(N)) == pytest.approx(t[-1], rel=1e-9)
    assert math.isclose(t[-1], float(row["lifetime_s"]), rel_tol=1e-9)
    before = products_module.COMPUTED["lifetimes"]
    run_scene(scene, tmp_path / "again", cache_dir=tmp_path / "cache")
    assert products_module.COMPUTED["lifetimes"] == before             # cached by content
