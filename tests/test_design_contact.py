"""The contact law is part of a design (issue 14): a design file's [contact] table, the command
line's --contact/--friction (which win), the Python API and scenes, checked in one place
(`fem.interface`) and recorded with the curve."""

import json
from pathlib import Path

import numpy as np
import pytest

from fem.design_file import Design, geometry_from_mapping, load_design, load_geometry
from fem.interface import (API, CONTACT_LAWS, FILE, ContactChoice, ContactLaw, choose_contact,
                           contact_law)
from reduced.design import ContactRecord
from reduced.stiffness_curve import StiffnessCurve
from tests.cli import run_cli as _run

COULOMB_TOML = '[contact]\nlaw = "coulomb"\nfriction = 0.3\n'
FAST = ["--fidelity", "coarse", "--u-max-mm", "1"]



def _design(tmp_path: Path, text: str, name: str = "d.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# ------------------------------------------------------------------ the data and its checks
def test_a_design_file_carries_its_contact_law_apart_from_the_shape(tmp_path):
    toml = _design(tmp_path, 'alpha_deg = 30\n' + COULOMB_TOML)
    design = load_design(toml)
    assert design.contact == ContactLaw("coulomb", 0.3)
    assert design.geometry == load_geometry(toml) and design.geometry.alpha_deg == 30
    assert not hasattr(design.geometry, "contact")               # the shape knows no interface
    assert design.describe()["contact"] == {"law": "coulomb", "friction": 0.3}
    as_json = _design(tmp_path, json.dumps({"contact": {"law": "sticking"}}), "d.json")
    assert load_design(as_json).contact == ContactLaw("sticking")
    assert load_design(_design(tmp_path, "alpha_deg = 30\n", "plain.toml")).contact is None
    # the mapping form: geometry_from_mapping checks the table and returns the shape
    assert geometry_from_mapping({"contact": {"law": "frictionless"}}) == Design(
        geometry_from_mapping({})).geometry
    with pytest.raises(ValueError, match="contact.friction: Coulomb's friction coefficient must be in"):
        geometry_from_mapping({"contact": {"law": "coulomb", "friction": -1}})


def test_every_input_checks_the_law_with_the_same_rules():
    assert CONTACT_LAWS == ("frictionless", "sticking", "coulomb")
    from fem.contact import CONTACT_LAWS as PLANE_LAWS
    from validation.commands._cup import CONTACT_CHOICES
    assert PLANE_LAWS == CONTACT_LAWS == CONTACT_CHOICES
    for law, mu, message in [("glued", 0.0, "contact: must be one of frictionless, sticking, coulomb"),
                             ("sticking", 0.5, "friction: applies to contact='coulomb' only, got 0.5"),
                             ("coulomb", 101.0, "friction: Coulomb's friction coefficient must be in [0, 100]"),
                             ("coulomb", float("nan"), "got nan"),
                             ("coulomb", "0.3", "must be a number in [0, 100], got '0.3'")]:
        with pytest.raises(ValueError) as exc:
            ContactLaw(law, mu)
        assert message in str(exc.value), exc.value
    assert ContactLaw("coulomb").friction == 0.0                 # the API: mu defaults to 0
    with pytest.raises(ValueError, match='contact.friction: law = "coulomb" needs friction = MU'):
        contact_law("coulomb", None, FILE)                       # a file or the command line: required
    # the FEM's own setup checks through ContactLaw
    from fem.cup import CupSetup
    from fem.geometry import cup_geometry
    from fem.material import NeoHookean
    from fem.mesh import cup_mesh
    with pytest.raises(ValueError, match="friction: Coulomb's friction coefficient must be in"):
        CupSetup.of(cup_mesh(cup_geometry("A"), "coarse"), NeoHookean(), "coulomb", 150.0)


def test_the_explicit_law_wins_over_the_design_file_which_wins_over_frictionless():
    design = ContactLaw("coulomb", 0.3)
    assert choose_contact(None, None, "command line") == ContactChoice(ContactLaw(), "default")
    assert choose_contact(None, None, "command line", design, "geometry file d.toml") == \
        ContactChoice(design, "geometry file d.toml")
    assert choose_contact("sticking", None, "command line", design, "geometry file d.toml") == \
        ContactChoice(ContactLaw("sticking"), "command line")
    mu = choose_contact(None, 0.6, "command line", design, "geometry file d.toml")
    assert mu.contact == ContactLaw("coulomb", 0.6)
    assert mu.source == "geometry file d.toml (law), command line (friction)"
    with pytest.raises(ValueError, match='friction: applies to contact=.coulomb. only, but the geometry '
                                         'file d.toml has law = "sticking"'):
        choose_contact(None, 0.6, "command line", ContactLaw("sticking"), "geometry file d.toml", API)


# ------------------------------------------------------------------ the commands
def test_stiffness_takes_the_files_law_and_the_command_line_wins(capsys, tmp_path):
    design = _design(tmp_path, COULOMB_TOML)
    runs = {"file": ["--geometry", design], "cli": ["--contact", "coulomb", "--friction", "0.3"],
            "override": ["--geometry", design, "--contact", "frictionless"],
            "frictionless": [], "mu": ["--geometry", design, "--friction", "0.6"]}
    curves = {}
    for name, options in runs.items():
        code, out, err = _run(capsys, "stiffness", *options, *FAST, "--out", tmp_path / f"{name}.csv")
        assert code == 0, err
        curves[name] = StiffnessCurve.from_csv(tmp_path / f"{name}.csv")
    # the file's law is the command line's, to the solver's tolerance
    np.testing.assert_allclose(curves["file"].F0_N, curves["cli"].F0_N, rtol=1e-9, atol=1e-12)
    assert curves["file"].contact == ContactRecord("coulomb", 0.3, "geometry file d.toml")
    assert curves["cli"].contact == ContactRecord("coulomb", 0.3, "command line")
    sidecar = json.loads((tmp_path / "file.json").read_text())["provenance"]
    assert (sidecar["contact"], sidecar["friction"], sidecar["contact_source"]) == \
        ("coulomb", 0.3, "geometry file d.toml")
    # --contact on the command line wins over the file
    assert curves["override"].contact == ContactRecord("frictionless", 0.0, "command line")
    np.testing.assert_allclose(curves["override"].F0_N, curves["frictionless"].F0_N, rtol=1e-9, atol=1e-12)
    assert curves["frictionless"].contact.source == "default"
    assert curves["file"].F0_N[-1] > 1.05 * curves["frictionless"].F0_N[-1]   # the law made a difference
    # --friction alone sets the mu of a coulomb file
    assert curves["mu"].contact.friction == 0.6
    assert curves["mu"].contact.source == "geometry file d.toml (law), command line (friction)"


def test_a_lifetime_refuses_a_design_file_whose_contact_contradicts_the_curve(capsys, tmp_path):
    design = _design(tmp_path, COULOMB_TOML)
    code, _, err = _run(capsys, "stiffness", "--geometry", design, *FAST, "--out", tmp_path / "c.csv")
    assert code == 0, err
    other = _design(tmp_path, '[contact]\nlaw = "sticking"\n', "sticky.toml")
    code, _, err = _run(capsys, "lifetime", "--stiffness", tmp_path / "c.csv", "--geometry", other,
                        "--force", "1", "--out", tmp_path / "life")
    assert code == 2 and err.count("\n") == 1, err
    assert ("c.csv' was computed with coulomb (mu = 0.3) contact, but --geometry" in err
            and "sticky.toml says sticking; drop the option" in err), err
    assert not (tmp_path / "life").exists()
    # the same design file is accepted, and the lifetime's cup record names the curve's interface
    from validation.bridge.design import resolve_cup
    choice = resolve_cup(StiffnessCurve.from_csv(tmp_path / "c.csv"), geometry_file=design)
    assert choice.describe()["contact"] == {"law": "coulomb", "friction": 0.3, "source": "geometry file d.toml"}


def test_example_offers_coulomb_and_records_where_the_law_came_from(capsys, tmp_path):
    code, out, err = _run(capsys, "example", "--contact", "coulomb", "--friction", "0.3", "--fidelity",
                          "coarse", "--out", tmp_path / "cli")
    assert code == 0, err
    assert "FEM coulomb mu = 0.3 stiffness (from the command line;" in out
    prov = StiffnessCurve.from_csv(tmp_path / "cli" / "stiffness_fem.csv").provenance
    assert (prov["contact"], prov["friction"], prov["contact_source"]) == ("coulomb", 0.3, "command line")
    # the design file's law, when the command line gives none, fails on its table's errors as stiffness does
    bad = _design(tmp_path, '[contact]\nlaw = "sticking"\nfriction = 0.3\n')
    code, _, err = _run(capsys, "example", "--geometry", bad, "--out", tmp_path / "bad")
    assert code == 2 and 'd.toml: contact.friction: applies to law = "coulomb" only' in err
    assert not (tmp_path / "bad").exists()


def test_suction_takes_the_files_law(capsys, tmp_path):
    design = _design(tmp_path, COULOMB_TOML)
    code, _, err = _run(capsys, "suction", "--geometry", design, "--fidelity", "coarse", "--u-mm", "0.5", "1",
                        "--dp-kPa", "0", "10", "--out", tmp_path / "s.json")
    assert code == 0, err
    prov = json.loads((tmp_path / "s.json").read_text())["provenance"]
    assert (prov["contact"], prov["friction"], prov["contact_source"]) == ("coulomb", 0.3, "geometry file d.toml")


# ------------------------------------------------------------------ scenes
def test_a_scene_takes_its_design_files_law_unless_it_names_one(tmp_path):
    from validation.scenes.schema import scene_from_mapping

    _design(tmp_path, COULOMB_TOML)
    out = [{"kind": "curve"}]
    scene = scene_from_mapping({"cup": {"geometry": "d.toml"}, "outputs": out}, base=tmp_path, source="s.toml")
    assert scene["contact"] == {"law": "coulomb", "friction": 0.3}
    assert scene.contact_source == "geometry file d.toml"
    assert scene.resolved()["contact"]["source"] == "geometry file d.toml"
    own = scene_from_mapping({"cup": {"geometry": "d.toml"}, "contact": {"law": "sticking"}, "outputs": out},
                             base=tmp_path, source="s.toml")
    assert own["contact"] == {"law": "sticking", "friction": None} and own.contact_source == "scene file s.toml"
    mu = scene_from_mapping({"cup": {"geometry": "d.toml"}, "contact": {"friction": 0.7}, "outputs": out},
                            base=tmp_path, source="s.toml")
    assert mu["contact"] == {"law": "coulomb", "friction": 0.7}
    _design(tmp_path, '[contact]\nlaw = "sticking"\n', "sticky.toml")
    with pytest.raises(ValueError, match='contact.friction: applies to law = "coulomb" only, but the '
                                         'geometry file sticky.toml has law = "sticking"'):
        scene_from_mapping({"cup": {"geometry": "sticky.toml"}, "contact": {"friction": 0.7}, "outputs": out},
                           base=tmp_path)
    plain = scene_from_mapping({"outputs": out})
    assert plain["contact"]["law"] == "frictionless" and plain.contact_source == "default"


def test_a_scene_run_records_the_design_files_law_with_its_curve(capsys, tmp_path):
    _design(tmp_path, COULOMB_TOML)
    (tmp_path / "s.toml").write_text('[cup]\ngeometry = "d.toml"\n[[outputs]]\nkind = "curve"\n')
    code, _, err = _run(capsys, "run", tmp_path / "s.toml", "--out", tmp_path / "out", "--no-cache")
    assert code == 0, err
    curve = StiffnessCurve.from_csv(tmp_path / "out" / "curve.csv")
    assert curve.contact == ContactRecord("coulomb", 0.3, "geometry file d.toml")
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert manifest["scene"]["contact"] == {"law": "coulomb", "friction": 0.3, "source": "geometry file d.toml"}
