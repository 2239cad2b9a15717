"""The design and interface a curve records, read back as typed values (reduced.design), and the
bridge's shapes of FEM designs (validation.bridge.design.shape_of)."""

from dataclasses import replace

import pytest

from fem.geometry import cup_geometry
from reduced.cup import CUPS
from reduced.design import ContactRecord, CupShape, recorded_contact, recorded_design
from reduced.stiffness_curve import StiffnessCurve
from validation.bridge.design import preset_design, shape_of


@pytest.mark.parametrize("name", ["A", "B"])
def test_a_shape_read_from_the_fem_record_is_the_fem_cup(name):
    geometry = cup_geometry(name, thickness_convention="vertical")
    shape = shape_of(geometry)
    # the FEM computes its own h1 and thickness; the reduced model's cone (eq 3) its own h1
    assert shape.h1_m == pytest.approx(geometry.h1_m, rel=1e-14)
    assert shape.cone_height_m == pytest.approx(CUPS[name].h1_m, rel=1e-14)
    assert (shape.d_at_r0_m, shape.d_at_r1_m) == pytest.approx(tuple(geometry.thickness_at([0.0, 1.0])), rel=1e-14)
    assert shape.thickness_convention == "vertical" and shape.name == f"cup {name}"
    again = CupShape.from_record(shape.describe())
    assert again.same_cup(shape) and again.name == shape.name
    assert not shape.same_cup(preset_design(name))                 # the convention tells them apart


def test_same_cup_compares_the_shape_not_the_name():
    a = preset_design("A")
    assert replace(a, name="my copy of A").same_cup(a)
    assert replace(a, r0_m=a.r0_m * (1 + 1e-7)).same_cup(a)              # within the record's rounding
    assert not replace(a, r1_m=21e-3).same_cup(a)
    assert not preset_design("B").same_cup(a)                           # cup B: another angle, thinner wall
    assert not replace(a, d_at_r1_m=2 * a.d_at_r1_m).same_cup(a)
    bare = replace(a, d_at_r0_m=None, d_at_r1_m=None)                   # a record without the thickness
    assert bare.same_cup(a) and a.same_cup(bare)


def test_a_curve_reads_its_design_and_law_from_the_sidecar(tmp_path):
    geometry = cup_geometry("B")
    provenance = {"source": "fem", "geometry": geometry.describe(), "contact": "coulomb", "friction": 0.4,
                  "contact_source": "command line"}
    u = [0.0, 1e-3, 2e-3]
    StiffnessCurve(u_m=u, F0_N=[0.0, 1.0, 3.0], h1_m=geometry.h1_m, provenance=provenance).to_csv(tmp_path / "c.csv")
    curve = StiffnessCurve.from_csv(tmp_path / "c.csv")
    assert curve.design.same_cup(preset_design("B")) and not curve.design.same_cup(preset_design("A"))
    assert curve.contact == ContactRecord("coulomb", 0.4, "command line")
    assert curve.contact.same_law(ContactRecord("coulomb", 0.4)) and not curve.contact.same_law(ContactRecord("coulomb", 0.5))
    assert not curve.contact.same_law(ContactRecord("sticking"))
    assert curve.contact.label() == "coulomb (mu = 0.4)" and ContactRecord("sticking").label() == "sticking"


def test_a_record_without_a_design_or_law_names_none():
    assert recorded_design({"source": "measured"}) is None
    assert recorded_design({"geometry": {"r0_mm": 5, "r1_mm": 19, "alpha_deg": 33}}) is None   # no h1_mm
    assert recorded_contact({"contact": None}) is None and recorded_contact({}) is None
    with pytest.raises(ValueError, match="geometry.alpha_deg: expected a number"):
        recorded_design({"geometry": {"r0_mm": 5, "r1_mm": 19, "alpha_deg": "33", "h1_mm": 9}})


def test_a_suction_table_of_a_custom_design_gives_its_cup_without_strip_widths():
    """The coupled route's table records its design but no l(r_c): a custom design's eq (5) widths
    are then not used (formerly an AttributeError)."""
    from validation.bridge.coupled.route import _TableDesign
    from validation.bridge.design import resolve_cup

    wide = replace(preset_design("A"), r1_m=21e-3, name="wide rim")
    wide = replace(wide, h1_m=wide.cone_height_m)
    choice = resolve_cup(_TableDesign(wide, wide.h1_m), laws="curve")
    assert choice.cup.r1_m == pytest.approx(21e-3) and choice.cup.r_start_m == pytest.approx(13e-3)
    assert choice.l_source.startswith("not used") and choice.label.startswith("wide rim (r0 5 mm, r1 21 mm")
    with pytest.raises(ValueError, match="l0_mm, l1_mm: wide rim .* is not a Table 1 cup"):
        resolve_cup(_TableDesign(wide, wide.h1_m), laws="cone")
