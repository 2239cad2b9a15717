"""The sweep file: a base design and the axes to vary, validated before any work.

    [base]                          # one cup design and its conditions (units in the key names)
    cup = "A"                       # the preset the geometry keys modify
    alpha_deg = 33
    d0_mm = 2.5                     # wall thickness at r0 and at r1 (a line between them)
    d1_mm = 0.447
    E_MPa = 4.0
    nu = 0.49
    contact = "sticking"            # frictionless (default, as everywhere) | sticking | coulomb
    # friction = 0.5                # Coulomb's mu in [0, 100]: with contact = "coulomb" only
    surface = "pmma-1.89"           # a calibrated preset (`cupcheck uc --list-surfaces`)
    fidelity = "coarse"             # FEM mesh level
    F1_N = [10, 40]                 # lifetimes at these pull forces: one table row per force
    F0_at_u_mm = [1, 3]             # F0 reported at these plate displacements
    allow_unusual_design = false    # true: steep or slender walls are run, not refused (`validation.guards`)
    # l0_mm, l1_mm: eq (5)'s strip widths (default: Table 1's for the base cup, as measured for it)

    [sampling]                      # grid (every combination of the axes' values) | lhs | sobol
    method = "grid"                 # lhs and sobol draw `n` designs in the axes' [low, high]
    n = 16
    seed = 1

    [[axes]]                        # grid: values; lhs/sobol: low and high (numeric axes)
    name = "alpha_deg"
    values = [25, 33, 40]

Instead of (or under) ``[base]``, ``scene = "my_scene.toml"`` takes the base design from a scene
file (`validation.scenes.schema`: its cup, material, contact, surface, loads and FEM fidelity);
keys in ``[base]`` then override the scene's. Axis names are the numeric base keys (alpha_deg, r0_mm, r1_mm, d0_mm, d1_mm, E_MPa, nu, r_start_mm,
friction: with a coulomb base) and, on a grid, the categorical ones (contact, surface; a coulomb
value takes the base's friction). Errors name the key path
(``axes[1].name: expected one of ...``) and are ValueErrors (exit status 2 on the command line).

Semantics checked here, before any FEM work: the plausibility guards every entry point shares
(`validation.guards`: moduli, forces, radii and wall thicknesses, named by key path; a steep or
slender design stays a failed row of its own, so one odd corner does not stop a sweep); a value
given twice on one axis is refused (it would be one design twice, and a duplicate usually is a
typo for another value); an empty force list and an unknown surface preset are refused; and a
sweep of more than `MAX_DESIGNS` designs is refused (each design is an FEM path: a larger sweep is
several sweeps). `lock_store` holds a sweep's store for one run at a time.
"""

from __future__ import annotations

import hashlib
import json
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from validation.study_schema import FIELDS, check_route, parse

__all__ = ["SweepSpec", "load_sweep", "sweep_from_mapping", "NUMERIC_AXES", "design_hash", "MAX_DESIGNS",
           "lock_store", "key_rows"]

#: the largest sweep one run takes (a grid's product of axis lengths, or lhs/sobol's n)
MAX_DESIGNS = 100_000
#: which plausibility guard a numeric key's values pass (`validation.guards`)
_LENGTHS = {"r0_mm": "r_mm", "r1_mm": "r_mm", "d0_mm": "d_mm", "d1_mm": "d_mm"}

NUMERIC_AXES = ("alpha_deg", "r0_mm", "r1_mm", "d0_mm", "d1_mm", "E_MPa", "nu", "r_start_mm", "l0_mm", "l1_mm",
                "friction")
CATEGORICAL_AXES = ("contact", "surface")
#: the study's fields a sweep file spells in [base] (`validation.study_schema.FIELDS`), by base key
_STUDY = {f.sweep: f for f in FIELDS if f.sweep}
#: optional base keys, absent unless given (a design's hash is that of its given keys)
_OPTIONAL = ("friction", "route", "u_max_mm")
#: the sweep's own base keys (the design's geometry, what it reports) and their meaning
_OWN: dict[str, tuple[Any, str]] = {
    "alpha_deg": (None, "cone angle [deg] (default: the cup's)"),
    "r0_mm": (None, "top-plate radius [mm] (default: the cup's)"), "r1_mm": (None, "rim radius [mm] (default: the cup's)"),
    "d0_mm": (None, "wall thickness at r0 [mm] (a line to d1 at r1; default: the cup's)"),
    "d1_mm": (None, "wall thickness at r1 [mm] (default: the cup's)"),
    "F0_at_u_mm": ([1.0], "plate displacements [mm] at which F0 is reported, each once"),
}
_BASE_DEFAULTS: dict[str, Any] = {**{k: f.default_in("sweep") for k, f in _STUDY.items() if k not in _OPTIONAL},
                                  **{k: d for k, (d, _) in _OWN.items()}}
_CHOICES = {k: f.choices_in("sweep") for k, f in _STUDY.items() if f.type == "choice"}
_METHODS = ("grid", "lhs", "sobol")


#: what each key means (docs/sweeps.md is generated from this and the parser's tables:
#: ``python scripts/keys_docs.py``)
MEANING: dict[str, str] = {
    **{f"base.{k}": f.meaning for k, f in _STUDY.items()},
    **{f"base.{k}": meaning for k, (_, meaning) in _OWN.items()},
    "scene": "a scene file whose cup, material, contact, surface, loads and fidelity are the base ([base] "
             "keys then override them)",
    "sampling.method": "grid: every combination of the axes' values; lhs, sobol: n designs in [low, high]",
    "sampling.n": f"lhs, sobol: the number of designs, 1 .. {MAX_DESIGNS}",
    "sampling.seed": "lhs, sobol: the random seed (reproducible designs)",
    "axes[].name": "the base key varied (categorical ones on a grid only; friction with a coulomb base)",
    "axes[].values": f"grid: the values, each once (at most {MAX_DESIGNS} designs in all)",
    "axes[].low": "lhs, sobol: the lower bound", "axes[].high": "lhs, sobol: the upper bound (> low)",
}


def key_rows() -> list[tuple[str, Any, str, str]]:
    """(key path, default, allowed values, meaning) of every sweep key, from the parser's own tables."""
    rows = [("scene", None, "a scene file name", MEANING["scene"])]
    for key, default in {**_BASE_DEFAULTS, **{k: None for k in _OPTIONAL}}.items():
        allowed = ", ".join(_CHOICES[key]) if key in _CHOICES else ""
        rows.append((f"base.{key}", default, allowed, MEANING[f"base.{key}"]))
    rows += [("sampling.method", "grid", ", ".join(_METHODS), MEANING["sampling.method"]),
             ("sampling.n", None, f"1 .. {MAX_DESIGNS}", MEANING["sampling.n"]),
             ("sampling.seed", 0, "an integer", MEANING["sampling.seed"]),
             ("axes[].name", None, ", ".join(NUMERIC_AXES + CATEGORICAL_AXES), MEANING["axes[].name"])]
    rows += [(f"axes[].{k}", None, "", MEANING[f"axes[].{k}"]) for k in ("values", "low", "high")]
    return rows


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep: the base design, the axes and how to sample them."""

    base: dict[str, Any]
    axes: tuple[dict[str, Any], ...]
    method: str = "grid"
    n: int = 0
    seed: int = 0

    def designs(self) -> list[dict[str, Any]]:
        """Every design of the sweep: the base with the axes' values, in a reproducible order."""
        names = [a["name"] for a in self.axes]
        if self.method == "grid":
            grids = np.meshgrid(*[np.arange(len(a["values"])) for a in self.axes], indexing="ij")
            points = [[a["values"][int(g.flat[i])] for a, g in zip(self.axes, grids)]
                      for i in range(grids[0].size)] if self.axes else [[]]
        else:
            from scipy.stats import qmc
            engine = (qmc.LatinHypercube(d=len(self.axes), seed=self.seed) if self.method == "lhs"
                      else qmc.Sobol(d=len(self.axes), scramble=True, seed=self.seed))
            unit = engine.random(self.n)
            lo = np.array([a["low"] for a in self.axes])
            hi = np.array([a["high"] for a in self.axes])
            points = qmc.scale(unit, lo, hi).tolist()
        return [{**self.base, **dict(zip(names, p))} for p in points]


def design_hash(design: Mapping[str, Any]) -> str:
    """Content hash of a design's parameters (its identity in the result store)."""
    text = json.dumps({k: design[k] for k in sorted(design)}, sort_keys=True, default=float)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def load_sweep(path: str | Path) -> SweepSpec:
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"sweep: no such file '{path}'")
    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"sweep: cannot parse '{path}': {exc}".replace("\n", " ")) from None
    return sweep_from_mapping(data, root=path.parent)


def sweep_from_mapping(data: Mapping[str, Any], root: str | Path = ".") -> SweepSpec:
    """A `SweepSpec` from parsed TOML (module docstring); ValueError naming the key path."""
    _keys(data, ("scene", "base", "sampling", "axes"), "")
    base = _base({**_scene_base(data["scene"], root), **data.get("base", {})} if "scene" in data
                 else data.get("base", {}))
    sampling = data.get("sampling", {})
    _keys(sampling, ("method", "n", "seed"), "sampling")
    method = sampling.get("method", "grid")
    if method not in _METHODS:
        raise ValueError(f"sampling.method: expected one of {', '.join(_METHODS)}, got {method!r}")
    n, seed = sampling.get("n", 0), sampling.get("seed", 0)
    if method != "grid" and not (isinstance(n, int) and not isinstance(n, bool) and 1 <= n <= MAX_DESIGNS):
        raise ValueError(f"sampling.n: {method} needs a number of designs in [1, {MAX_DESIGNS}], got {n!r}")
    if not isinstance(seed, int):
        raise ValueError(f"sampling.seed: expected an integer, got {seed!r}")
    axes = data.get("axes", [])
    if not isinstance(axes, list):
        raise ValueError("axes: expected a list of tables ([[axes]])")
    parsed = tuple(_axis(a, i, method) for i, a in enumerate(axes))
    names = [a["name"] for a in parsed]
    if len(set(names)) != len(names):
        raise ValueError(f"axes: an axis appears twice ({', '.join(names)})")
    if method != "grid" and not parsed:
        raise ValueError(f"axes: {method} sampling needs at least one axis")
    if method == "grid":
        size = math.prod(len(a["values"]) for a in parsed)
        if size > MAX_DESIGNS:
            lengths = " x ".join(str(len(a["values"])) for a in parsed)
            raise ValueError(f"axes: the grid has {lengths} = {size:.3g} designs, more than {MAX_DESIGNS} "
                             f"(each is an FEM path); use fewer values, or lhs/sobol sampling with n designs")
    _check_surfaces(base, parsed)
    _check_start_radius(base, parsed)
    _check_contact_axes(base, parsed)
    return SweepSpec(base=base, axes=parsed, method=method, n=n if method != "grid" else 0, seed=seed)


def _check_contact_axes(base: dict[str, Any], axes: tuple[dict[str, Any], ...]) -> None:
    """Every design's contact law is whole (`fem.interface.contact_law` checks it): a friction axis
    varies a coulomb base's mu; a contact axis's coulomb value takes base.friction."""
    from fem.interface import Spelling, contact_law

    names = [a["name"] for a in axes]
    spelling = Spelling("base.contact", "base.friction", 'base.contact = "{}"', "base.friction = MU")
    laws = axes[names.index("contact")]["values"] if "contact" in names else [base["contact"]]
    if "friction" in names:
        i = names.index("friction")
        if base["contact"] != "coulomb" or "contact" in names:
            raise ValueError(f'axes[{i}].name: a friction axis varies Coulomb\'s mu: it needs '
                             f'base.contact = "coulomb" and no contact axis')
        axis = axes[i]
        for mu in axis.get("values", [axis.get("low"), axis.get("high")]):
            contact_law("coulomb", mu, Spelling("base.contact", f"axes[{i}]", 'base.contact = "{}"', "MU"))
        return
    mu = base.get("friction")
    for law in dict.fromkeys(laws):
        contact_law(law, mu if law == "coulomb" else None, spelling)
    if mu is not None and "coulomb" not in laws:
        contact_law(laws[0], mu, spelling)          # a mu without a coulomb law: refused


def _check_surfaces(base: dict[str, Any], axes: tuple[dict[str, Any], ...]) -> None:
    """Every surface a design uses is a calibrated preset (the base's, or a surface axis's values)."""
    from validation.study_schema import check_surface_preset

    given = [("base.surface", base["surface"])]
    for i, axis in enumerate(axes):
        if axis["name"] == "surface":
            given = [(f"axes[{i}].values[{j}]", v) for j, v in enumerate(axis["values"])]
    for where, name in given:
        check_surface_preset(name, where)


def _check_start_radius(base: dict[str, Any], axes: tuple[dict[str, Any], ...]) -> None:
    """r_start inside the base cup's wall (when the radii are not swept: then each design's own
    check makes a failed row)."""
    from reduced.cup import CUPS
    from validation.guards import check_start_radius

    names = [a["name"] for a in axes]
    if "r0_mm" in names or "r1_mm" in names:
        return
    cup = CUPS[base["cup"]]
    radii = (base["r0_mm"] if base["r0_mm"] is not None else cup.r0_m * 1e3,
             base["r1_mm"] if base["r1_mm"] is not None else cup.r1_m * 1e3)
    check_start_radius(base["r_start_mm"], radii, "base.r_start_mm")
    if "r_start_mm" in names:
        i = names.index("r_start_mm")
        for key, value in ([(f"values[{j}]", v) for j, v in enumerate(axes[i]["values"])] if "values" in axes[i]
                           else [("low", axes[i]["low"]), ("high", axes[i]["high"])]):
            check_start_radius(value, radii, f"axes[{i}].{key}")


def lock_store(out: str | Path):
    """Hold a sweep's store `out` for this run (an OS file lock on its resolved path, released when
    the returned lock is dropped or the process ends): a second sweep on the same store is refused
    at once instead of computing every design again beside the first."""
    from filelock import FileLock, Timeout

    real = Path(out).resolve()
    real.mkdir(parents=True, exist_ok=True)
    lock = FileLock(str(real / ".sweep.lock"), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        raise ValueError(f"--out: the sweep store '{out}' is being computed by another cupcheck sweep; "
                         f"wait for it (a rerun then computes only what is missing)") from None
    return lock


def _scene_base(scene: Any, root: str | Path) -> dict[str, Any]:
    """The sweep's base design from a scene file (the same format as `cupcheck run`)."""
    from validation.scenes.schema import load_scene

    if not isinstance(scene, str):
        raise ValueError(f"scene: expected a scene file name, got {scene!r}")
    sc = load_scene(Path(root) / scene)
    base = {"cup": sc["cup"]["preset"], "E_MPa": sc["material"]["E_MPa"], "nu": sc["material"]["nu"],
            "contact": sc["contact"]["law"], "fidelity": sc["stiffness"]["fidelity"], "F1_N": sc["loads"]["F1_N"]}
    if sc["contact"]["law"] == "coulomb":
        base["friction"] = sc["contact"]["friction"]
    if sc["surface"]["preset"] and not sc["surface"]["uc_table"]:
        base["surface"] = sc["surface"]["preset"]
    if sc["loads"]["r_start_mm"] is not None:
        base["r_start_mm"] = sc["loads"]["r_start_mm"]
    if sc["stiffness"]["route"] != "paper":
        base["route"] = sc["stiffness"]["route"]
    if sc["cup"]["geometry"]:
        from fem.design_file import load_geometry
        d = load_geometry(sc["cup"]["geometry"], cup=sc["cup"]["preset"]).describe()
        base.update(r0_mm=d["r0_mm"], r1_mm=d["r1_mm"], alpha_deg=d["alpha_deg"], d0_mm=d["d_at_r0_mm"],
                    d1_mm=d["d_at_r1_mm"])
    if sc["surface"]["uc_table"] or sc["stiffness"]["source"] != "fem" or sc["fluid"]["kind"] != "air":
        raise ValueError(f"scene: a sweep evaluates FEM designs in air on a preset surface; '{scene}' asks for "
                         f"another stiffness source, fluid or a u_c table")
    if sc["loads"]["press_u_mm"] is not None or sc["loads"]["press_force_N"] is not None:
        raise ValueError(f"scene: a sweep presses each design to its r_start; '{scene}' gives loads.press_u_mm "
                         f"or loads.press_force_N")
    return base


def _keys(table: Any, allowed: tuple[str, ...], where: str) -> None:
    if not isinstance(table, Mapping):
        raise ValueError(f"{where or 'sweep'}: expected a table")
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        prefix = f"{where}." if where else ""
        raise ValueError(f"{prefix}{unknown[0]}: unknown key; allowed: {', '.join(allowed)}")


def _base(table: Mapping[str, Any]) -> dict[str, Any]:
    _keys(table, tuple(_BASE_DEFAULTS) + _OPTIONAL, "base")
    base = {**_BASE_DEFAULTS, **table}
    for key in base:                       # the study's fields: one parser for every spelling
        if key in _STUDY:
            base[key] = parse(_STUDY[key], base[key], "sweep")
    for key in _OWN:
        if key != "F0_at_u_mm" and base.get(key) is not None:
            base[key] = _number(base[key], f"base.{key}")
            _plausible(key, base[key], f"base.{key}")
    check_route({_STUDY[k].key: v for k, v in base.items() if k in _STUDY},
                {_STUDY[k].key for k in table if k in _STUDY}, "sweep")
    for key in ("F1_N", "F0_at_u_mm"):
        values = base[key] if isinstance(base[key], list) else [base[key]]
        if not values:
            raise ValueError(f"base.{key}: expected at least one value (an empty list gives an empty table)")
        base[key] = [_number(v, f"base.{key}[{i}]", positive=True) for i, v in enumerate(values)]
        if len(set(base[key])) != len(base[key]):   # one table row per design and value
            twice = next(v for v in base[key] if base[key].count(v) > 1)
            raise ValueError(f"base.{key}: {twice:g} appears twice; give each value once")
    return base


def _plausible(key: str, value: float, where: str) -> None:
    """The shared plausibility guard of a numeric key's value (`validation.guards`)."""
    from validation import guards

    if key == "E_MPa":
        guards.check_modulus(value, where)
    elif key in _LENGTHS:
        guards.check_length(value, where, _LENGTHS[key])


def _axis(axis: Any, i: int, method: str) -> dict[str, Any]:
    where = f"axes[{i}]"
    _keys(axis, ("name", "values", "low", "high"), where)
    name = axis.get("name")
    allowed = NUMERIC_AXES + (CATEGORICAL_AXES if method == "grid" else ())
    if name not in allowed:
        raise ValueError(f"{where}.name: expected one of {', '.join(allowed)}, got {name!r}")
    if method == "grid":
        values = axis.get("values")
        if not isinstance(values, list) or not values or "low" in axis or "high" in axis:
            raise ValueError(f"{where}.values: a grid axis needs a non-empty list of values (no low/high)")
        if name in CATEGORICAL_AXES:
            choices = _CHOICES.get(name)
            bad = [v for v in values if not isinstance(v, str) or (choices and v not in choices)]
            if bad:
                raise ValueError(f"{where}.values: expected {' or '.join(choices) if choices else 'names'}, "
                                 f"got {bad[0]!r}")
        else:
            values = [_number(v, f"{where}.values[{j}]") for j, v in enumerate(values)]
            for j, v in enumerate(values):
                _plausible(name, v, f"{where}.values[{j}]")
        twice = [j for j, v in enumerate(values) if v in values[:j]]
        if twice:
            raise ValueError(f"{where}.values[{twice[0]}]: {values[twice[0]]!r} appears twice on the axis "
                             f"{name}; give each value once")
        return {"name": name, "values": values}
    if "values" in axis:
        raise ValueError(f"{where}.values: {method} sampling takes low and high, not values")
    lo, hi = (_number(axis.get(k), f"{where}.{k}") for k in ("low", "high"))
    _plausible(name, lo, f"{where}.low")
    _plausible(name, hi, f"{where}.high")
    if not lo < hi:
        raise ValueError(f"{where}.high: must exceed low = {lo:g}, got {hi:g}")
    return {"name": name, "low": lo, "high": hi}


def _number(value: Any, where: str, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{where}: expected a finite number, got {value!r}")
    if positive and value <= 0:
        raise ValueError(f"{where}: must be > 0, got {value:g}")
    return float(value)
