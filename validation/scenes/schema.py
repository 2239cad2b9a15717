"""The scene file: what to model and what to show, validated before any work.

    [cup] [material] [contact] [surface] [fluid] [loads] [stiffness]    what to model
    [sweep]                                                               one parameter varied
    [[outputs]]     kind = curve | lifetimes | trajectories | figure | render | footprint | squeeze

The study's keys (cup, material, contact, surface, fluid, loads, stiffness) are the fields of
`validation.study_schema.FIELDS`, defined once for scenes, sweeps and the command line; `_TABLES`,
`_CHOICES` and `MEANING` are derived from them, beside the scene's own `OUTPUT_KEYS` and sweep
keys; docs/scenes.md is generated from them
(``python scripts/keys_docs.py``). Every table and key is optional but `outputs`. Unknown keys,
wrong types, implausible values (the shared guards of `validation.guards`, named by key path) and
contradictions are ValueErrors naming the key path (``outputs[2].kind: expected one of ...``):
one line and exit status 2 on the command line, before anything is computed or written. Paths in
the scene are relative to the scene file. The contact law and mu are checked by `fem.interface`
(imported only for a scene that names mu, coulomb or a design file: a scene of the reduced model
alone imports no fem); `Scene.contact_source` says where the law came from.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from validation.bridge.study import Study, Sweep
from validation.study_schema import FIELDS as STUDY_FIELDS
from validation.study_schema import (check_route, check_surface_preset, check_u_max, field_of, finite_number,
                                     parse, study_from_values)

__all__ = ["Scene", "load_scene", "scene_from_mapping", "OUTPUT_KINDS", "FIGURES", "key_rows"]

OUTPUT_KINDS = ("curve", "lifetimes", "trajectories", "figure", "render", "footprint", "squeeze")
#: the output kinds drawn from FEM states at given plate displacements (they need u_mm)
STATE_KINDS = ("render", "footprint", "squeeze")
FIELDS = ("contact_pressure", "von_mises", "min_stretch")
MAX_FRAMES = 60
FIGURES = ("lifetime_vs_force", "uc_vs_pressure", "F0_vs_u", "lifetime_vs_parameter", "r_pb_vs_time",
           "p_Ndot_vs_time")
SWEEP_KEYS = ("loads.kappa", "loads.r_start_mm", "surface.preset", "cup.preset", "contact.friction")
#: the study's tables and keys with their defaults, as `validation.study_schema.FIELDS` defines them
_TABLES: dict[str, dict[str, Any]] = {}
for _f in STUDY_FIELDS:
    if _f.scene:
        _TABLES.setdefault(_f.key.split(".")[0], {})[_f.key.split(".")[1]] = _f.default
_CHOICES = {tuple(f.key.split(".")): f.choices for f in STUDY_FIELDS if f.scene and f.type == "choice"}


#: what each key means (docs/scenes.md is generated from this, `_TABLES` and `_CHOICES`:
#: ``python scripts/keys_docs.py``)
MEANING: dict[str, str] = {
    **{f.key: f.meaning for f in STUDY_FIELDS if f.scene},
    "sweep.key": "the one parameter varied (contact.friction with law = \"coulomb\")",
    "sweep.values": "its values, each once: one lifetime table row per value and force",
    "outputs[].kind": "what to write: a stiffness curve, lifetimes, trajectories, a figure, or a 3D view "
                      "(render, footprint, squeeze: drawn from FEM states at u_mm)",
    "outputs[].name": "file stem (default: the figure's name, else the kind)",
    "outputs[].figure": "with kind = \"figure\": which figure (lifetime_vs_parameter needs [sweep]; "
                        "uc_vs_pressure and F0_vs_u draw one line per swept surface or cup); written as "
                        "PNG and SVG, and what it draws, point by point, as <name>_data.csv",
    "outputs[].u_mm": "with render, footprint, squeeze (and only them): the plate displacement shown [mm]",
    "outputs[].field": "with render, squeeze: the colouring",
    "outputs[].frames": "with squeeze: the number of frames from u = 0 to u_mm",
}
#: the [[outputs]] keys: (default, allowed) as the parser applies them
OUTPUT_KEYS: dict[str, tuple[Any, str]] = {
    "kind": (None, ", ".join(OUTPUT_KINDS)), "name": (None, "a plain file stem"),
    "figure": (None, ", ".join(FIGURES)), "u_mm": (None, "> 0"),
    "field": ("contact_pressure", ", ".join(FIELDS)), "frames": (8, f"2 .. {MAX_FRAMES}"),
}


def key_rows() -> list[tuple[str, Any, str, str, str]]:
    """(key path, default, allowed values, meaning, the same field's sweep key and flag) of every
    scene key, from the parser's own tables."""
    rows = []
    for table, keys in _TABLES.items():
        for key, default in keys.items():
            allowed = ", ".join(_CHOICES[(table, key)]) if (table, key) in _CHOICES else ""
            f = field_of(f"{table}.{key}")
            spelled = ", ".join(f"`{n}`" for n in (f.sweep and f"base.{f.sweep}", f.flag) if n)
            rows.append((f"{table}.{key}", default, allowed, MEANING[f"{table}.{key}"], spelled))
    rows.append(("sweep.key", None, ", ".join(SWEEP_KEYS), MEANING["sweep.key"]))
    rows.append(("sweep.values", None, "a non-empty list", MEANING["sweep.values"]))
    for key, (default, allowed) in OUTPUT_KEYS.items():
        rows.append((f"outputs[].{key}", default, allowed, MEANING[f"outputs[].{key}"]))
    return rows


@dataclass(frozen=True)
class Scene:
    """A validated scene: every table resolved with its defaults, paths made absolute."""

    tables: dict[str, dict[str, Any]]
    outputs: tuple[dict[str, Any], ...]
    source: str = "scene"
    sweep: dict[str, Any] | None = None
    contact_source: str = "default"     # who chose the contact law: the scene, the design file, default

    def study(self) -> Study:
        """The scene as a `validation.bridge.study.Study` (its sweep, if any, included)."""
        return study_from_values(_values(self.tables), contact_source=self.contact_source, outputs=self.outputs,
                                 sweep=None if self.sweep is None else Sweep(self.sweep["key"],
                                                                             tuple(self.sweep["values"])))

    def __getitem__(self, table: str) -> dict[str, Any]:
        return self.tables[table]

    def resolved(self) -> dict[str, Any]:
        """Plain data for the manifest: every table with its defaults, and the outputs."""
        tables = {k: dict(v) for k, v in self.tables.items()}
        tables["contact"]["source"] = self.contact_source
        return {**tables, "sweep": self.sweep, "outputs": [dict(o) for o in self.outputs]}

    def needs_fem(self) -> bool:
        """Whether any requested output needs the FEM (a stiffness curve from it)."""
        if self["stiffness"]["source"] != "fem":
            return False
        return any(o["kind"] != "figure" or o["figure"] != "uc_vs_pressure" for o in self.outputs)


def load_scene(path: str | Path) -> Scene:
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"scene: no such file '{path}'")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"scene: cannot parse '{path}': {exc}".replace("\n", " ")) from None
    return scene_from_mapping(data, base=path.parent, source=path.name)


def scene_from_mapping(data: Mapping[str, Any], base: str | Path = ".", source: str = "scene") -> Scene:
    """A `Scene` from plain data (parsed TOML); ValueError naming the key path."""
    unknown = sorted(set(data) - set(_TABLES) - {"outputs", "sweep"})
    if unknown:
        raise ValueError(f"{unknown[0]}: unknown table; allowed: {', '.join([*_TABLES, 'sweep', 'outputs'])}")
    tables = {name: _table(name, data.get(name, {}), defaults) for name, defaults in _TABLES.items()}
    _paths(tables, Path(base))
    _guards(tables, data.get("sweep"))
    contact_source = _design_contact(tables, data.get("contact", {}), source)
    _cross_checks(tables, data.get("sweep"))
    sweep_key = data["sweep"].get("key") if isinstance(data.get("sweep"), Mapping) else None
    check_route(_values(tables), {f"{t}.{k}" for t in _TABLES for k in data.get(t, {})}, "scene", sweep_key)
    outputs = data.get("outputs")
    if not isinstance(outputs, list) or not outputs:
        raise ValueError("outputs: a scene needs a non-empty list of [[outputs]]")
    parsed = tuple(_output(o, i) for i, o in enumerate(outputs))
    files = [(o["name"], o["kind"] in ("figure", *STATE_KINDS)) for o in parsed]   # tables .csv, images .png
    if len(set(files)) != len(files):
        twice = next(n for n, f in files if files.count((n, f)) > 1)
        raise ValueError(f"outputs: two outputs would write the same file '{twice}'; give one a name")
    sweep = _sweep(data["sweep"], tables) if "sweep" in data else None
    if sweep is None and any(o["figure"] == "lifetime_vs_parameter" for o in parsed):
        raise ValueError("outputs: the figure lifetime_vs_parameter needs a [sweep] table")
    if sweep is not None and any(o["kind"] in ("curve", "trajectories", *STATE_KINDS)
                                 or o["figure"] in ("r_pb_vs_time", "p_Ndot_vs_time") for o in parsed):
        raise ValueError("sweep: a swept scene writes lifetimes and figures; drop the curve, trajectories and 3D outputs")
    if tables["stiffness"]["route"] == "fem":
        for i, o in enumerate(parsed):
            if o["figure"] in ("r_pb_vs_time", "p_Ndot_vs_time"):
                raise ValueError(f"outputs[{i}].figure: {o['figure']} draws the cone's r(t) or the strip's p(t), "
                                 f"which the fem route has not; write kind = \"trajectories\" (its FEM states)")
    return Scene(tables=tables, outputs=parsed, source=source, sweep=sweep, contact_source=contact_source)


def _sweep(table: Any, tables: dict[str, dict[str, Any]]) -> dict[str, Any]:
    if not isinstance(table, Mapping):
        raise ValueError("sweep: expected a table")
    unknown = sorted(set(table) - {"key", "values"})
    if unknown:
        raise ValueError(f"sweep.{unknown[0]}: unknown key; allowed: key, values")
    key, values = table.get("key"), table.get("values")
    if key not in SWEEP_KEYS:
        raise ValueError(f"sweep.key: expected one of {', '.join(SWEEP_KEYS)}, got {key!r}")
    if not isinstance(values, list) or not values:
        raise ValueError("sweep.values: expected a non-empty list")
    twice = [j for j, v in enumerate(values) if v in values[:j]]
    if twice:
        raise ValueError(f"sweep.values[{twice[0]}]: {values[twice[0]]!r} appears twice; give each value once")
    name, field = key.split(".")
    if (name, field) in _CHOICES:
        bad = [v for v in values if v not in _CHOICES[(name, field)]]
        if bad:
            raise ValueError(f"sweep.values: expected {', '.join(_CHOICES[(name, field)])}, got {bad[0]!r}")
    elif field == "preset":
        if not all(isinstance(v, str) for v in values):
            raise ValueError("sweep.values: expected surface preset names")
        for j, v in enumerate(values):
            check_surface_preset(v, f"sweep.values[{j}]")
    elif key != "contact.friction":
        values = [finite_number(v, f"sweep.values[{i}]", positive=True) for i, v in enumerate(values)]
    if key == "contact.friction":
        if tables["contact"]["law"] != "coulomb":
            raise ValueError("sweep.key: contact.friction needs contact.law = \"coulomb\"")
        values = [_friction(v, f"sweep.values[{i}]") for i, v in enumerate(values)]
    if key == "cup.preset" and tables["cup"]["geometry"]:
        raise ValueError("sweep.key: cup.preset cannot be swept with a design file (cup.geometry)")
    return {"key": key, "values": values}


def _table(name: str, given: Any, defaults: dict[str, Any]) -> dict[str, Any]:
    if not isinstance(given, Mapping):
        raise ValueError(f"{name}: expected a table")
    unknown = sorted(set(given) - set(defaults))
    if unknown:
        raise ValueError(f"{name}.{unknown[0]}: unknown key; allowed: {', '.join(defaults)}")
    table = {**defaults, **given}
    for key, value in table.items():
        table[key] = parse(field_of(f"{name}.{key}"), value, "scene")
    return table


def _values(tables: Mapping[str, Mapping[str, Any]]) -> dict[str, Any]:
    """{key path: value} of the study's tables."""
    return {f"{t}.{k}": v for t, keys in tables.items() for k, v in keys.items()}


def _paths(tables: dict[str, dict[str, Any]], base: Path) -> None:
    for name, key in (("cup", "geometry"), ("surface", "uc_table")):
        value = tables[name][key]
        if value is None:
            continue
        if not isinstance(value, str):
            raise ValueError(f"{name}.{key}: expected a file name, got {value!r}")
        path = (base / value).resolve()
        if not path.is_file():
            raise ValueError(f"{name}.{key}: no such file '{path}'")
        tables[name][key] = str(path)


def _guards(tables: dict[str, dict[str, Any]], sweep: Any = None) -> None:
    """The plausibility guards every entry point shares (`validation.guards`), named by key path:
    the modulus, the pull forces, the design file's lengths and wall, the FEM curve's end within
    the height of each cup, the u_c table's gaps."""
    from validation import guards

    cup = tables["cup"]
    design = None
    if cup["geometry"]:
        design = guards.load_design(cup["geometry"], cup=cup["preset"], field="cup.geometry",
                                    allow_unusual=cup["allow_unusual_design"],
                                    override="set cup.allow_unusual_design = true").geometry
        radii = (design.r0_m * 1e3, design.r1_m * 1e3)
    else:
        from reduced.cup import CUPS
        radii = (CUPS[cup["preset"]].r0_m * 1e3, CUPS[cup["preset"]].r1_m * 1e3)
    u_max = tables["stiffness"]["u_max_mm"]
    if u_max is not None:                  # within the height of each cup the scene runs
        from fem.geometry import cup_geometry
        swept = isinstance(sweep, Mapping) and sweep.get("key") == "cup.preset" and isinstance(sweep.get("values"), list)
        presets = [v for v in sweep["values"] if v in ("A", "B")] if swept else [cup["preset"]]
        for geometry in [design] if design is not None else [cup_geometry(p) for p in presets]:
            check_u_max(u_max, geometry, "scene")
    guards.check_start_radius(tables["loads"]["r_start_mm"], radii, "loads.r_start_mm")
    if isinstance(sweep, Mapping) and sweep.get("key") == "loads.r_start_mm" and isinstance(sweep.get("values"), list):
        for j, value in enumerate(sweep["values"]):
            guards.check_start_radius(value, radii, f"sweep.values[{j}]")
    if tables["surface"]["uc_table"]:
        guards.check_uc_file(tables["surface"]["uc_table"], "surface.uc_table")


def _friction(value: Any, where: str) -> float:
    """Coulomb's mu, checked by `fem.interface` (the one check of every input's mu)."""
    from fem.interface import Spelling, contact_law
    return contact_law("coulomb", value, Spelling(friction=where)).friction


def _design_contact(tables: dict[str, dict[str, Any]], given: Any, source: str) -> str:
    """Without a contact.law in the scene, take the design file's [contact] law (and its mu, unless
    the scene gives contact.friction) into ``tables["contact"]``; return who chose the law."""
    scene = f"scene file {source}"
    if "law" in given:                     # `given` is a table: `_table` checked it
        return scene
    if not tables["cup"]["geometry"]:
        return "default"
    from fem.design_file import load_design
    from fem.interface import FILE, choose_contact

    path = Path(tables["cup"]["geometry"])
    design = load_design(path, cup=tables["cup"]["preset"]).contact
    if design is None:
        return "default"
    choice = choose_contact(None, given.get("friction"), scene, design, f"geometry file {path.name}", FILE)
    law = choice.contact
    tables["contact"].update(law=law.law, friction=law.friction if law.law == "coulomb" else None)
    return choice.source


def _cross_checks(tables: dict[str, dict[str, Any]], sweep: Any = None) -> None:
    contact = tables["contact"]
    swept = isinstance(sweep, Mapping) and sweep.get("key") == "contact.friction"
    if contact["friction"] is not None or (contact["law"] == "coulomb" and not swept):
        from fem.interface import FILE, contact_law       # only here: a reduced-model scene imports no fem
        contact["friction"] = contact_law(contact["law"], contact["friction"], FILE).friction
    if contact["law"] == "coulomb" and tables["stiffness"]["source"] != "fem":
        raise ValueError("contact.law: Coulomb friction is a FEM contact law; it needs stiffness.source = \"fem\"")
    if tables["cup"]["geometry"] is not None and tables["stiffness"]["source"] != "fem":
        raise ValueError("stiffness.source: a design file (cup.geometry) needs source = \"fem\"; Appendix A "
                         "is for the Table 1 presets")
    if tables["fluid"]["kind"] == "water" and tables["material"]["relaxation"] != "none":
        raise ValueError("material.relaxation: the water-filled cavity is implemented without relaxation only")
    if not 0.0 <= tables["material"]["nu"] < 0.5:
        raise ValueError(f"material.nu: Poisson's ratio must be in [0, 0.5), got {tables['material']['nu']:g}")


def _output(output: Any, i: int) -> dict[str, Any]:
    where = f"outputs[{i}]"
    if not isinstance(output, Mapping):
        raise ValueError(f"{where}: expected a table")
    allowed = ("kind", "name", "figure", "u_mm", "field", "frames")
    unknown = sorted(set(output) - set(allowed))
    if unknown:
        raise ValueError(f"{where}.{unknown[0]}: unknown key; allowed: {', '.join(allowed)}")
    kind = output.get("kind")
    if kind not in OUTPUT_KINDS:
        raise ValueError(f"{where}.kind: expected one of {', '.join(OUTPUT_KINDS)}, got {kind!r}")
    figure = output.get("figure")
    if kind == "figure" and figure not in FIGURES:
        raise ValueError(f"{where}.figure: expected one of {', '.join(FIGURES)}, got {figure!r}")
    if kind != "figure" and figure is not None:
        raise ValueError(f"{where}.figure: only for kind = \"figure\"")
    u_mm = output.get("u_mm")
    if (kind in STATE_KINDS) != (u_mm is not None):
        raise ValueError(f"{where}.u_mm: {', '.join(STATE_KINDS)} need u_mm (the plate displacement shown), "
                         "and only they")
    if u_mm is not None:
        u_mm = finite_number(u_mm, f"{where}.u_mm", positive=True)
    field = output.get("field")
    if field is not None and kind not in ("render", "squeeze"):
        raise ValueError(f"{where}.field: only for kind = \"render\" or \"squeeze\"")
    if kind in ("render", "squeeze"):
        field = "contact_pressure" if field is None else field
        if field not in FIELDS:
            raise ValueError(f"{where}.field: expected one of {', '.join(FIELDS)}, got {field!r}")
    frames = output.get("frames")
    if frames is not None and kind != "squeeze":
        raise ValueError(f"{where}.frames: only for kind = \"squeeze\"")
    if kind == "squeeze":
        frames = 8 if frames is None else frames
        if isinstance(frames, bool) or not isinstance(frames, int) or not 2 <= frames <= MAX_FRAMES:
            raise ValueError(f"{where}.frames: expected a whole number in [2, {MAX_FRAMES}], got {frames!r}")
    name = output.get("name", figure if kind == "figure" else kind)
    if not isinstance(name, str) or not name or "/" in name or name.startswith("."):
        raise ValueError(f"{where}.name: expected a plain file stem, got {name!r}")
    return {"kind": kind, "name": name, "figure": figure, "u_mm": u_mm, "field": field, "frames": frames}
