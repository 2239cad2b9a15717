"""The Study's fields, each defined once, and its three spellings derived from them.

A `validation.bridge.study.Study` is written three ways: a scene file's key path (``material.E_MPa``),
a sweep file's base key (``base.E_MPa``) and a command-line flag (``--E-MPa``). `FIELDS` defines
each field once: its key path as the scene writes it, the Study attribute it sets, its type, unit,
default, choices, meaning, the shared plausibility guard (`validation.guards`), its sweep key and
its flag, and where one spelling differs (a default, the routes it offers) that difference. The
scene parser, the sweep parser's study part and `cupcheck example`'s and `cupcheck lifetime`'s
options (those that are study fields) are derived from it
(`parse`, `add_flags`, `study_from_values`), and the rules that relate fields (`check_route`) are
written once with the names of the spelling the user wrote (`Field.name`, `Field.setting`), so an
error names the key path or the flag as given.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from validation.bridge.lifetimes import ROUTES
from validation.bridge.pipeline import DEFAULT_SURFACE

__all__ = ["Field", "FIELDS", "SPELLINGS", "field_of", "parse", "finite_number", "add_flags", "values_from_args",
           "study_from_values", "check_route", "check_surface_preset", "check_u_max"]

#: the spellings of a study: a scene file, a sweep file's [base], the command line
SPELLINGS = ("scene", "sweep", "cli")
#: Coulomb friction's and the FEM's mesh levels, spelled out so that the schema imports no fem
_LAWS = ("frictionless", "sticking", "coulomb")
_LEVELS = ("coarse", "medium", "fine")


@dataclass(frozen=True)
class Field:
    """One study field. key: the scene's key path; attr: the Study attribute it sets ("part.name"
    or a top-level name); type: "choice", "number", "numbers", "bool", "name" (a surface preset),
    "file"; positive: numbers must be > 0; guard: "modulus", "forces" or "plate_travel" (`validation.guards`);
    sweep: the sweep file's base key (None: not in sweep files); flag: the command-line flag
    (None: not on the command line); scene: whether scene files have it; spelled: per spelling,
    what differs ({"sweep": {"default": [10.0]}, "cli": {"choices": ROUTES, "dest": "force_N"}})."""

    key: str
    attr: str
    type: str
    default: Any
    meaning: str
    unit: str = ""
    choices: tuple[str, ...] = ()
    positive: bool = False
    guard: str | None = None
    sweep: str | None = None
    flag: str | None = None
    scene: bool = True
    spelled: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)

    def default_in(self, spelling: str) -> Any:
        return self.spelled.get(spelling, {}).get("default", self.default)

    def choices_in(self, spelling: str) -> tuple[str, ...]:
        return tuple(self.spelled.get(spelling, {}).get("choices", self.choices))

    def name(self, spelling: str) -> str:
        """The field as the user wrote it in `spelling`."""
        return {"scene": self.key, "sweep": f"base.{self.sweep}", "cli": self.flag}[spelling] or self.key

    def setting(self, spelling: str, value: Any) -> str:
        """The field set to `value` as the user would write it (``stiffness.route = "fem"``, ``--route fem``)."""
        if spelling == "cli":
            return f"{self.flag} {value}"
        shown = f'"{value}"' if isinstance(value, str) else f"{value:g}"
        return f"{self.name(spelling)} = {shown}"

    @property
    def dest(self) -> str:
        """The argparse attribute of the flag (the command line's own, where it names one)."""
        if "dest" in self.spelled.get("cli", {}):
            return self.spelled["cli"]["dest"]
        return (self.flag or self.key).lstrip("-").replace("-", "_").split(".")[-1]


FIELDS: tuple[Field, ...] = (
    Field("cup.preset", "design.preset", "choice", "A", "Table 1 cup the design starts from (A: alpha 33 deg; B: "
          "21 deg; a design file or the sweep's geometry keys modify it)", choices=("A", "B"), sweep="cup",
          flag="--cup", spelled={"cli": {"default": None}}),
    Field("cup.geometry", "design.file", "file", None, "a design file (.toml or .json, the keys of `cupcheck "
          "stiffness --geometry`), relative to the scene file; its [contact] table sets the law unless "
          "contact.law is given", flag="--geometry"),
    Field("cup.allow_unusual_design", "", "bool", False, "true: a cone angle outside 5..80 deg or a wall more "
          "than 400x longer than thick is run, not refused (a sweep makes it a failed row)",
          sweep="allow_unusual_design", flag="--allow-unusual-design"),
    Field("cup.l0_mm", "design.l0_mm", "number", None, "eq (5)'s strip width at r0 [mm] (default: Table 1's for "
          "the base cup, as measured for it)", unit="mm", positive=True, sweep="l0_mm", flag="--l0-mm",
          scene=False),
    Field("cup.l1_mm", "design.l1_mm", "number", None, "eq (5)'s strip width at r1 [mm] (default: Table 1's for "
          "the base cup)", unit="mm", positive=True, sweep="l1_mm", flag="--l1-mm", scene=False),
    Field("material.E_MPa", "material.E_MPa", "number", 4.0, "Young's modulus [MPa] of the wall (and of p/E)",
          unit="MPa", positive=True, guard="modulus", sweep="E_MPa", flag="--E-MPa"),
    Field("material.nu", "material.nu", "number", 0.49, "Poisson's ratio, in [0, 0.5)", sweep="nu"),
    Field("material.relaxation", "loads.relaxation", "choice", "none", "none, or the default power-law relaxation "
          "modulus (4.4 MPa at 1 s, 1.8 MPa at 3e4 s)", choices=("none", "default"), flag="--relaxation"),
    Field("contact.law", "contact.law", "choice", "frictionless", "the FEM's contact with the plane (default: "
          "the design file's [contact] law, else frictionless)", choices=_LAWS, sweep="contact", flag="--contact",
          spelled={"cli": {"default": None}}),
    Field("contact.friction", "contact.friction", "number", None, "Coulomb's mu, in [0, 100]: with law = "
          "\"coulomb\" only, which needs it", sweep="friction", flag="--friction"),
    Field("surface.preset", "surface.preset", "name", DEFAULT_SURFACE, "calibrated rough surface for u_c(p/E) "
          "(`cupcheck uc --list-surfaces`)", sweep="surface", flag="--surface", spelled={"cli": {"default": None}}),
    Field("surface.uc_table", "surface.uc_table", "file", None, "a u_c table CSV (columns p_over_E,u_c_m; u_c "
          "in m) instead of the preset", flag="--uc-table"),
    Field("fluid.kind", "loads.fluid", "choice", "air", "what fills the cavity and leaks in",
          choices=("air", "water"), flag="--fluid"),
    Field("loads.F1_N", "loads.forces_N", "numbers", [5.0, 10.0, 20.0, 40.0, 80.0], "pull forces F1 [N]: one "
          "lifetime (and trajectory) per force", unit="N", positive=True, guard="forces", sweep="F1_N",
          flag="--force", spelled={"sweep": {"default": [10.0]}, "cli": {"default": [10.0], "dest": "force_N"}}),
    Field("loads.r_start_mm", "loads.r_start_mm", "number", None, "start radius of the contact [mm] (default: "
          "Table 1's 12 mm for A and B, mid-wall otherwise)", unit="mm", positive=True, sweep="r_start_mm",
          flag="--r-start-mm"),
    Field("loads.kappa", "loads.kappa", "number", 1.0, "stiffness factor: F0 replaced by kappa F0 (the paper's "
          "Fig. 1stiffnessFactor)", positive=True, flag="--kappa"),
    Field("loads.press_u_mm", "loads.press_u_mm", "number", None, "route fem: press the cup to this plate "
          "displacement [mm] instead of to r_start", unit="mm", positive=True, flag="--press-u-mm"),
    Field("loads.press_force_N", "loads.press_force_N", "number", None, "route fem: press the cup with this "
          "force [N] instead of to r_start", unit="N", positive=True, guard="forces", flag="--press-force-N"),
    Field("stiffness.source", "stiffness", "choice", "fem", "F0(h) from the FEM or from Appendix A's formula",
          choices=("fem", "appendix-a")),
    Field("stiffness.route", "route", "choice", "paper", "how the FEM reaches the lifetime (README, Routes): "
          "eq (6)'s strip on the cone, the FEM's contact-pressure profile, or the cup's whole life in the "
          "FEM (fem: pressed, sealed, pulled and leaking; air, no relaxation, kappa 1) (profile and fem need "
          "source = \"fem\")", choices=("paper", "profile", "fem"), sweep="route", flag="--route",
          spelled={"cli": {"choices": ROUTES, "default": "profile"}}),
    Field("stiffness.fidelity", "fidelity", "choice", "coarse", "FEM mesh level", choices=_LEVELS,
          sweep="fidelity", flag="--fidelity", spelled={"cli": {"default": None}}),
    Field("stiffness.u_max_mm", "u_max_mm", "number", None, "the FEM stiffness curve's end: the largest plate "
          "displacement u [mm], in (0, h1] (default: 0.9 h1; at h1 the plate edge reaches the plane); in a scene "
          "or `cupcheck example` a path that fails before it keeps its converged part, flagged partial (exit "
          "status 3, naming the u_max that runs); in a sweep such a design is a failed row",
          unit="mm", positive=True, guard="plate_travel", sweep="u_max_mm", flag="--u-max-mm"),
    Field("stiffness.du_mm", "loads.du_mm", "number", 0.25, "route fem: the plate step [mm] along the cup's "
          "equilibrium branch", unit="mm", positive=True, flag="--du-mm"),
)
_BY_KEY = {f.key: f for f in FIELDS}


def field_of(key: str) -> Field:
    """The field of a scene key path."""
    return _BY_KEY[key]


def finite_number(value: Any, where: str, positive: bool) -> float:
    """`value` as a float if it is a finite number (and > 0 if `positive`); else ValueError naming `where`."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{where}: expected a finite number, got {value!r}")
    if positive and value <= 0:
        raise ValueError(f"{where}: must be > 0, got {value:g}")
    return float(value)


def parse(f: Field, value: Any, spelling: str, where: str | None = None) -> Any:
    """`value` of field `f` as written in `spelling` (None stays None where the default is None),
    checked: its type, choices, sign and the field's shared guard; ValueError naming `where` (the
    field's name in the spelling by default)."""
    from validation import guards

    where = where or f.name(spelling)
    if f.type == "choice":
        choices = f.choices_in(spelling)
        if value not in choices:
            raise ValueError(f"{where}: expected one of {', '.join(choices)}, got {value!r}")
        return value
    if f.type == "bool":
        if not isinstance(value, bool):
            raise ValueError(f"{where}: expected true or false, got {value!r}")
        return value
    if value is None and f.default_in(spelling) is None:
        return None
    if f.type == "numbers":
        values = value if isinstance(value, list) else [value]
        if not values:
            raise ValueError(f"{where}: expected at least one value (an empty list gives an empty table)")
        values = [finite_number(v, f"{where}[{i}]", f.positive) for i, v in enumerate(values)]
        if f.guard == "forces":
            guards.check_forces(values, where)
        return values
    if f.type == "number":
        number = finite_number(value, where, f.positive)
        if f.guard == "modulus":
            guards.check_modulus(number, where)
        elif f.guard == "forces":
            guards.check_forces(number, where)
        elif f.guard == "plate_travel":    # against h1 where the design is known: `check_plate_travel`
            guards.check_length(number, where, "u_mm")
        return number
    if f.type == "name":
        if not isinstance(value, str):
            raise ValueError(f"{where}: expected a surface preset name, got {value!r}")
        check_surface_preset(value, where)
        return value
    if not isinstance(value, str):                      # a file
        raise ValueError(f"{where}: expected a file name, got {value!r}")
    return value


def check_u_max(u_max_mm: float | None, geometry: Any, spelling: str) -> float | None:
    """The FEM curve's end `u_max_mm` (None: the default, 0.9 h1) against the design's height h1
    (`validation.guards.check_plate_travel`), named as the user wrote it; h1 itself when given
    one round-off above it."""
    if u_max_mm is None:
        return None
    from validation.guards import check_plate_travel
    return check_plate_travel(u_max_mm, 1e3 * geometry.h1_m, _BY_KEY["stiffness.u_max_mm"].name(spelling))


def check_surface_preset(name: Any, where: str) -> None:
    """A calibrated surface preset's name (read from the presets' data file: importing the
    roughness model would cost a scene that needs none of it 0.5 s)."""
    import json

    data = Path(__file__).resolve().parents[1] / "reduced" / "roughness" / "data" / "presets.json"
    if data.is_file():
        known = {d["name"] for d in json.loads(data.read_text(encoding="utf-8"))}
    else:                                  # an unusual install: ask the package
        from reduced.roughness.surfaces import load_presets
        known = set(load_presets())
    if name not in known:
        raise ValueError(f"{where}: unknown surface preset {name!r}; choose one of {', '.join(sorted(known))}")


# ------------------------------------------------------------------ the command line
def add_flags(group: argparse._ActionsContainer, keys: Iterable[str], helps: Mapping[str, str] | None = None,
              defaults: Mapping[str, Any] | None = None, **kwargs: Any) -> None:
    """The fields' flags on `group`, typed, with their choices and command-line defaults (or a
    command's own, `defaults` by key path); the help is `helps[key]` where given, else the field's
    meaning and default. kwargs: argparse extras per flag ({"--cup": {"type": cup_name}})."""
    helps, defaults = helps or {}, defaults or {}
    for key in keys:
        f = _BY_KEY[key]
        extra = dict(kwargs.get(f.flag, {}))
        default = defaults.get(key, f.default_in("cli"))
        if f.type == "bool":
            group.add_argument(f.flag, dest=f.dest, action="store_true", help=helps.get(key, f.meaning))
            continue
        if f.type == "choice" and "type" not in extra:
            extra["choices"] = f.choices_in("cli")
        elif f.type in ("number", "numbers"):
            extra.setdefault("type", float)
            extra.setdefault("metavar", f.unit.upper() or "X")
            if f.type == "numbers":
                extra.setdefault("nargs", "+")
        elif f.type in ("name", "file"):
            extra.setdefault("metavar", "NAME" if f.type == "name" else "FILE")
        shown = "%(default)s" if default is not None else "none"
        group.add_argument(f.flag, dest=f.dest, default=default,
                           help=helps.get(key, f"{f.meaning} (default: {shown})"), **extra)


def values_from_args(args: argparse.Namespace, keys: Iterable[str]) -> dict[str, Any]:
    """{key path: value} of the fields' flags in `args` (None: not given)."""
    return {key: getattr(args, _BY_KEY[key].dest) for key in keys}


# ------------------------------------------------------------------ the study
def study_from_values(values: Mapping[str, Any], *, contact_source: str = "default", **study: Any):
    """The `Study` of {key path: value} (a field not given: the Study's default); `study`: further
    Study attributes the spelling sets itself (outputs, sweep, refine, cup_laws, suction_table)."""
    from validation.bridge.study import Contact, CupDesign, Loads, Material, Study, Surface

    parts: dict[str, dict[str, Any]] = {"design": {}, "material": {}, "contact": {}, "surface": {}, "loads": {}}
    top: dict[str, Any] = {}
    for key, value in values.items():
        f = _BY_KEY[key]
        if not f.attr:                     # checked, not part of the study (allow_unusual_design)
            continue
        head, _, tail = f.attr.partition(".")
        value = tuple(value) if f.type == "numbers" else value
        (parts[head] if tail else top)[tail or head] = value
    return Study(design=CupDesign(**parts["design"]), material=Material(**parts["material"]),
                 contact=Contact(**parts["contact"], source=contact_source), surface=Surface(**parts["surface"]),
                 loads=Loads(**parts["loads"]), **top, **study)


def check_route(values: Mapping[str, Any], given: Iterable[str], spelling: str,
                swept: str | None = None) -> None:
    """The rules between the route and the other fields, in the names of `spelling`: the routes
    that need the FEM; the fem route's own fields (the press, the plate step) with it only, one
    press, and what it does not model (relaxation, kappa, Appendix A). `values`: {key
    path: value} with defaults; `given`: the key paths the user wrote; `swept`: a swept key path."""
    name = lambda key: _BY_KEY[key].name(spelling)                                   # noqa: E731
    route_is = lambda value: _BY_KEY["stiffness.route"].setting(spelling, value)    # noqa: E731
    route, given = values.get("stiffness.route", "paper"), set(given)
    source = values.get("stiffness.source", "fem")
    if values.get("stiffness.u_max_mm") is not None and source != "fem":
        raise ValueError(f"{name('stiffness.u_max_mm')}: ends the FEM stiffness curve; Appendix A's has no FEM path "
                         f"(drop it or set source = \"fem\")")
    if route == "profile" and source != "fem":
        raise ValueError(f"{name('stiffness.route')}: 'profile' needs source = \"fem\" (the FEM's contact-pressure "
                         f"profiles)")
    for key in ("loads.press_u_mm", "loads.press_force_N", "stiffness.du_mm"):
        if key in given and route != "fem":
            raise ValueError(f"{name(key)}: only for {route_is('fem')} (the cup pressed and sealed in the FEM)")
    if route == "coupled" and values.get("fluid.kind", "air") != "air":
        raise ValueError(f"{name('fluid.kind')}: {route_is('coupled')} models a gas-filled cavity only; drop "
                         f"{_BY_KEY['fluid.kind'].setting(spelling, values['fluid.kind'])}")
    if route != "fem":
        return
    press = [k for k in ("loads.r_start_mm", "loads.press_u_mm", "loads.press_force_N") if values.get(k) is not None]
    if len(press) > 1:
        raise ValueError(f"{name(press[1])}: the cup is pressed one way: give one of "
                         f"{', '.join(name(k) for k in press)}")
    if source != "fem":
        raise ValueError(f"{name('stiffness.route')}: 'fem' needs source = \"fem\" (the cup's whole life in the FEM)")
    for key, default, why in (("material.relaxation", "none", "'s wall is the FEM's elastic one"),
                              ("loads.kappa", 1.0, "'s stiffness is the FEM's own")):
        if values.get(key, default) != default:
            raise ValueError(f"{name(key)}: the fem route{why}; drop {_BY_KEY[key].setting(spelling, values[key])}")
    if swept == "loads.kappa":
        raise ValueError("sweep.key: the fem route's stiffness is the FEM's own; kappa cannot be swept")
    if swept == "loads.r_start_mm" and press and press[0] != "loads.r_start_mm":
        raise ValueError(f"sweep.key: loads.r_start_mm is swept, but {name(press[0])} presses the cup; drop one")
    for key in ("cup.l0_mm", "cup.l1_mm"):
        if values.get(key) is not None and spelling == "cli":
            raise ValueError(f"{name(key)}: the fem route's seal is its FEM states' contact; drop --l0-mm, --l1-mm")

