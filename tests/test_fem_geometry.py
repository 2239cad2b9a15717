"""The cup cross-section (fem.geometry): presets, the (s, t) map, validation, geometry files."""

import dataclasses
import json
import math

import numpy as np
import pytest

from fem.design_file import load_geometry
from fem.geometry import CupGeometry, LinearThickness, TabulatedThickness, cup_geometry, polygon_self_intersects

MM = 1e-3


@pytest.mark.parametrize("cup,alpha,d_inner", [("A", 33.0, 2.5), ("B", 21.0, 1.5)])
def test_presets_follow_table_1_and_sec_5_5(cup, alpha, d_inner):
    g = cup_geometry(cup)
    assert (g.r0_m, g.r1_m, g.alpha_deg) == (5 * MM, 19 * MM, alpha)
    assert g.h1_m == pytest.approx(14 * MM * math.tan(math.radians(alpha)), rel=1e-14)
    # the paper's line d(5 mm) = d_inner -> d(20 mm) = 0.3 mm, evaluated at the rim r1 = 19 mm
    d_rim = d_inner + (0.3 - d_inner) * (19 - 5) / (20 - 5)
    assert g.thickness_at(np.array([0.0, 1.0])) == pytest.approx([d_inner * MM, d_rim * MM], rel=1e-14)


def test_cavity_volume_is_eq_4_at_h1():
    # eq. (4): V = V0 [(r/r0)^3 - 1], V0 = pi r0^2 h0 / 3, h0 = r0 tan(alpha), at r = r1
    for cup in "AB":
        g = cup_geometry(cup)
        h0 = g.r0_m * math.tan(g.alpha_rad)
        v_eq4 = math.pi * g.r0_m ** 2 * h0 / 3 * ((g.r1_m / g.r0_m) ** 3 - 1)
        assert g.cavity_volume_m3() == pytest.approx(v_eq4, rel=1e-13)


@pytest.mark.parametrize("convention", ["normal", "vertical"])
def test_map_puts_the_lower_surface_on_the_cone_and_the_upper_at_distance_d(convention):
    g = cup_geometry("A", thickness_convention=convention)
    s = np.linspace(0, 1, 11)
    r, z = g.point(s, 0 * s)
    assert r == pytest.approx(g.r0_m + s * (g.r1_m - g.r0_m), rel=1e-14)
    assert z == pytest.approx(g.h1_m - (r - g.r0_m) * math.tan(g.alpha_rad), abs=1e-15)
    upper = g.point(s, 1 + 0 * s)
    d = g.thickness_at(s)
    if convention == "normal":   # distance from the upper point to the cone line (point-line formula)
        a = g.alpha_rad
        dist = (upper[0] - g.r0_m) * math.sin(a) + (upper[1] - g.h1_m) * math.cos(a)
        assert dist == pytest.approx(d, rel=1e-12)
    else:
        assert upper[0] == pytest.approx(r, rel=1e-14)
        assert upper[1] - z == pytest.approx(d, rel=1e-12)


@pytest.mark.parametrize("convention,factor", [("normal", 1.0), ("vertical", None)])
def test_cross_section_area_is_slant_length_times_mean_thickness(convention, factor):
    # Jacobian of the map is L d (normal) or L d cos(alpha) (vertical); d linear -> the mean is exact
    g = cup_geometry("B", thickness_convention=convention)
    factor = factor or math.cos(g.alpha_rad)
    poly = g.boundary_polygon(3)    # straight sides: the corners suffice
    x, y = poly[:, 0], poly[:, 1]
    shoelace = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    mean_d = g.thickness_at(np.array([0.0, 1.0])).mean()
    assert shoelace == pytest.approx(g.slant_length_m * mean_d * factor, rel=1e-12)


@pytest.mark.parametrize("overrides,field", [
    ({"r0_m": 19 * MM}, "r1_mm"),
    ({"r1_m": 4 * MM}, "r1_mm"),
    ({"r0_m": 0.0}, "r0_mm"),
    ({"alpha_deg": 0.0}, "alpha_deg"),
    ({"alpha_deg": 90.0}, "alpha_deg"),
    ({"alpha_deg": 95.0}, "alpha_deg"),
    ({"alpha_deg": float("nan")}, "alpha_deg"),
    ({"thickness": LinearThickness(5 * MM, 1 * MM, 15 * MM, 0.0)}, "thickness"),  # < 0 beyond 15 mm
    ({"thickness": TabulatedThickness((6 * MM, 19 * MM), (1 * MM, 1 * MM))}, "thickness"),
    ({"thickness_convention": "sideways"}, "thickness_convention"),
])
def test_invalid_geometry_is_rejected_with_a_one_line_message(overrides, field):
    with pytest.raises(ValueError) as err:
        cup_geometry("A", **overrides)
    message = str(err.value)
    assert message.startswith(field) and "\n" not in message


def test_geometry_is_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        cup_geometry("A").r0_m = 1.0


def test_self_intersection_detector():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    bowtie = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], float)
    assert not polygon_self_intersects(square)
    assert polygon_self_intersects(bowtie)


def test_thick_cone_wall_never_folds():
    # det(dx/ds, dx/dt) = L d > 0: even a wall as thick as it is long stays a simple polygon
    g = CupGeometry(5 * MM, 6 * MM, 80.0, LinearThickness(5 * MM, 20 * MM, 6 * MM, 0.1 * MM))
    assert not polygon_self_intersects(g.boundary_polygon(201))


def test_callable_and_tabulated_profiles():
    table = TabulatedThickness((5 * MM, 10 * MM, 19 * MM), (2 * MM, 1 * MM, 0.5 * MM))
    g = cup_geometry("A", thickness=table)
    r = g.lower_radius(np.array([0.0, 5 / 14, 1.0]))
    assert g.thickness(r) == pytest.approx([2 * MM, 1 * MM, 0.5 * MM])
    bump = cup_geometry("A", thickness=lambda r: 1 * MM + 0.2 * MM * np.sin(r / MM))
    assert bump.describe()["thickness_profile"]["kind"] == "callable"


def test_geometry_files(tmp_path):
    (tmp_path / "g.json").write_text(json.dumps({
        "cup": "B", "name": "thin B", "alpha_deg": 25,
        "thickness": {"r_mm": [5, 12, 19], "d_mm": [1.2, 0.8, 0.4]}}))
    g = load_geometry(tmp_path / "g.json")
    assert (g.name, g.alpha_deg, g.r1_m) == ("thin B", 25.0, 19 * MM)
    assert g.thickness_at(np.array([0.5])) == pytest.approx([0.8 * MM])
    (tmp_path / "g.toml").write_text('r0_mm = 4\nthickness_convention = "vertical"\n'
                                     '[thickness]\nr_mm = [4, 19]\nd_mm = [2, 0.5]\n')
    g = load_geometry(tmp_path / "g.toml")
    assert g.r0_m == 4 * MM and g.thickness_convention == "vertical"
    assert isinstance(g.thickness, LinearThickness)


@pytest.mark.parametrize("text,match", [
    ('{"alpha": 30}', "unknown key"),
    ('{"alpha_deg": "steep"}', "alpha_deg must be a number"),
    ('{"alpha_deg": 120}', "alpha_deg"),
    ('{"thickness": {"r_mm": [5]}}', "thickness"),
    ('{"alpha_deg": ', "cannot parse"),
])
def test_bad_geometry_files(tmp_path, text, match):
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(ValueError, match=match):
        load_geometry(path)
    with pytest.raises(ValueError, match="no such file"):
        load_geometry(tmp_path / "missing.json")
