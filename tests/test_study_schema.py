"""One schema, three spellings: the scene parser, the sweep parser's study part and `cupcheck
example`'s options are derived from `validation.study_schema.FIELDS`, so one value means one study
whichever way it is written, and one bad value is refused by the same rule, named as written."""

from __future__ import annotations

import argparse
from dataclasses import fields as dataclass_fields

import pytest

from tests.cli import run_cli
from validation.bridge.study import Study
from validation.cli import build_parser
from validation.scenes import schema
from validation.scenes.schema import scene_from_mapping
from validation.study_schema import FIELDS, field_of, study_from_values
from validation.sweeps import spec
from validation.sweeps.evaluate import geometry_of, study_of
from validation.sweeps.spec import sweep_from_mapping


def test_the_fields_defaults_are_the_studys():
    assert study_from_values({}) == Study()
    for f in FIELDS:
        if f.attr and f.scene:
            assert study_from_values({f.key: f.default}) == Study(), f.key
    attrs = {f.attr.split(".")[0] for f in FIELDS if f.attr}
    assert attrs <= {fd.name for fd in dataclass_fields(Study)}


def test_the_parsers_tables_are_the_fields():
    for f in FIELDS:
        table, key = f.key.split(".")
        if f.scene:
            assert schema._TABLES[table][key] == f.default and schema.MEANING[f.key] == f.meaning
        if f.sweep and f.sweep not in spec._OPTIONAL:
            assert spec._BASE_DEFAULTS[f.sweep] == f.default_in("sweep")
            assert spec.MEANING[f"base.{f.sweep}"] == f.meaning


def _example_actions() -> dict[str, argparse.Action]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {a.option_strings[-1]: a for a in sub.choices["example"]._actions if a.option_strings}


def test_examples_flags_are_the_fields():
    from validation.commands.example import KEYS

    actions = _example_actions()
    for key in (*KEYS, "contact.law", "contact.friction"):
        f = field_of(key)
        action = actions[f.flag]
        assert action.dest == f.dest, key
        if f.type == "choice" and action.choices is not None:
            assert tuple(action.choices) == f.choices_in("cli"), key
        if key != "stiffness.route":                       # example's own default route: profile
            assert action.default == f.default_in("cli"), key


def test_one_value_is_one_study_in_every_spelling():
    scene = scene_from_mapping({"contact": {"law": "coulomb", "friction": 0.3}, "loads": {"r_start_mm": 13},
                                "stiffness": {"route": "fem", "fidelity": "medium"},
                                "outputs": [{"kind": "lifetimes"}]}).study()
    design = sweep_from_mapping({"base": {"contact": "coulomb", "friction": 0.3, "r_start_mm": 13, "route": "fem",
                                          "fidelity": "medium"}}).designs()[0]
    swept = study_of(design, geometry_of(design))
    args = build_parser().parse_args(["example", "--out", "o", "--contact", "coulomb", "--friction", "0.3",
                                      "--r-start-mm", "13", "--route", "fem", "--fidelity", "medium"])
    from validation.commands._cup import contact_choice
    from validation.commands.example import study_of as example_study
    cli = example_study(args, contact_choice(args))
    for study in (swept, cli):
        assert (study.route, study.fidelity, study.material, study.surface) == \
               (scene.route, scene.fidelity, scene.material, scene.surface)
        assert (study.contact.law, study.contact.friction) == ("coulomb", 0.3)
        assert study.loads.r_start_mm == scene.loads.r_start_mm == 13.0


@pytest.mark.parametrize("value", [-1, 0])
def test_one_rule_refuses_a_bad_value_named_as_written(value, capsys, tmp_path):
    with pytest.raises(ValueError, match=rf"^loads.r_start_mm: must be > 0, got {value}$"):
        scene_from_mapping({"loads": {"r_start_mm": value}, "outputs": [{"kind": "lifetimes"}]})
    with pytest.raises(ValueError, match=rf"^base.r_start_mm: must be > 0, got {value}$"):
        sweep_from_mapping({"base": {"r_start_mm": value}})
    code, _, err = run_cli(capsys, "example", "--out", tmp_path / "o", "--r-start-mm", str(value))
    assert code == 2 and err.strip().endswith(f"--r-start-mm: must be > 0, got {value}")
    assert not (tmp_path / "o").exists()


def test_one_route_rule_in_every_spelling(capsys, tmp_path):
    with pytest.raises(ValueError, match=r"^loads.press_force_N: the cup is pressed one way: give one of "
                                         r"loads.r_start_mm, loads.press_force_N$"):
        scene_from_mapping({"loads": {"r_start_mm": 12, "press_force_N": 5}, "stiffness": {"route": "fem"},
                            "outputs": [{"kind": "lifetimes"}]})
    code, _, err = run_cli(capsys, "example", "--out", tmp_path / "o", "--route", "fem", "--r-start-mm", "12",
                           "--press-force-N", "5")
    assert code == 2 and err.strip().endswith("--press-force-N: the cup is pressed one way: give one of "
                                              "--r-start-mm, --press-force-N")
