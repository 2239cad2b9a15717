"""Design files: a cup's wall and, optionally, its interface with the plane, in TOML or JSON.

A file's keys are in mm and degrees; it starts from a Table 1 preset (`fem.geometry.cup_geometry`)
and overrides what it names. A ``[contact]`` table, optional, names the interface with the plane
(`fem.interface.ContactLaw`): a `Design` holds the shape and the interface apart, and
`load_geometry` returns the wall alone. Every error is one line naming the file and the key.
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .geometry import CupGeometry, LinearThickness, TabulatedThickness, ThicknessProfile, cup_geometry
from .interface import ContactLaw, contact_from_mapping

__all__ = ["Design", "load_design", "design_from_mapping", "load_geometry", "geometry_from_mapping"]

_MM = 1e-3

_FILE_KEYS = ("cup", "name", "r0_mm", "r1_mm", "alpha_deg", "thickness_convention", "thickness", "contact")


@dataclass(frozen=True)
class Design:
    """What a design file holds: the wall's shape and, if the file says, its interface with the
    plane (the ``[contact]`` table, `fem.interface`); the two stay apart."""

    geometry: CupGeometry
    contact: ContactLaw | None = None      # None: the file names no contact law

    def describe(self) -> dict[str, Any]:
        """Plain data: the geometry's record and the contact table (None without one)."""
        return {"geometry": self.geometry.describe(),
                "contact": None if self.contact is None else self.contact.describe()}


def design_from_mapping(data: Mapping[str, Any], source: str = "geometry", cup: str = "A") -> Design:
    """A `Design` from plain data (the parsed design file; keys in mm and degrees).

    Geometry keys as in `geometry_from_mapping`; ``contact``, optional, a table ``{law = ...,
    friction = MU}`` (`fem.interface.contact_from_mapping`: law frictionless, sticking or coulomb;
    friction, Coulomb's mu in [0, 100], with coulomb only, which needs it).
    """
    shape = {k: v for k, v in data.items() if k != "contact"}
    geometry = geometry_from_mapping(shape, source=source, cup=cup)
    contact = contact_from_mapping(data["contact"], source) if "contact" in data else None
    return Design(geometry, contact)


def geometry_from_mapping(data: Mapping[str, Any], source: str = "geometry",
                          cup: str = "A") -> CupGeometry:
    """A `CupGeometry` from plain data (the parsed geometry file; keys in mm and degrees).

    Keys (all optional): ``cup`` ("A" or "B": start from that preset; default the argument
    `cup`), ``name``, ``r0_mm``, ``r1_mm``, ``alpha_deg``, ``thickness_convention``
    ("normal"|"vertical") and ``thickness``, a table ``{"r_mm": [...], "d_mm": [...]}`` (two
    points: the line through them, extrapolated; more: piecewise-linear, covering [r0, r1]).
    A ``contact`` table is checked (`design_from_mapping`) and not part of the shape.
    """
    if "contact" in data:
        return design_from_mapping(data, source=source, cup=cup).geometry
    unknown = set(data) - set(_FILE_KEYS)
    if unknown:
        raise ValueError(f"{source}: unknown key(s) {sorted(unknown)}; allowed: {', '.join(_FILE_KEYS)}")
    overrides: dict[str, Any] = {}
    for key in ("r0_mm", "r1_mm"):
        if key in data:
            overrides[key.replace("_mm", "_m")] = _number(data[key], key, source) * _MM
    if "alpha_deg" in data:
        overrides["alpha_deg"] = _number(data["alpha_deg"], "alpha_deg", source)
    if "thickness_convention" in data:
        overrides["thickness_convention"] = str(data["thickness_convention"])
    if "thickness" in data:
        overrides["thickness"] = _profile_from_mapping(data["thickness"], source)
    overrides["name"] = str(data.get("name", f"{source}"))
    return cup_geometry(str(data.get("cup", cup)), **overrides)


def load_geometry(path: str | Path, cup: str = "A") -> CupGeometry:
    """The wall of a design file (`load_design`; its ``[contact]`` table is checked, not returned)."""
    return load_design(path, cup=cup).geometry


def load_design(path: str | Path, cup: str = "A") -> Design:
    """Read a design file (``.json`` or ``.toml``; keys as in `design_from_mapping`).

    Example (TOML)::

        cup = "A"                      # preset the other keys modify
        alpha_deg = 30
        thickness_convention = "normal"
        [thickness]                    # 2 points: a line (extrapolated); more: a table
        r_mm = [5, 12, 19]
        d_mm = [2.5, 1.2, 0.45]
        [contact]                      # optional: the interface with the plane
        law = "coulomb"                # frictionless | sticking | coulomb
        friction = 0.5                 # Coulomb's mu in [0, 100], with coulomb only
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"geometry: no such file '{path}'")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ValueError(f"geometry: '{path}' is not a UTF-8 text file") from None
    try:
        if path.suffix.lower() == ".toml":
            data = tomllib.loads(text)
        elif path.suffix.lower() == ".json":
            data = json.loads(text)
        else:
            raise ValueError(f"geometry: '{path}' must end in .json or .toml")
    except (json.JSONDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ValueError(f"geometry: cannot parse '{path}': {exc}".replace("\n", " ")) from None
    if not isinstance(data, Mapping):
        raise ValueError(f"geometry: '{path}' must hold a table of keys")
    return design_from_mapping(data, source=path.name, cup=cup)


def _profile_from_mapping(value: Any, source: str) -> ThicknessProfile:
    if not isinstance(value, Mapping) or set(value) != {"r_mm", "d_mm"}:
        raise ValueError(f"{source}: thickness must be a table with exactly the keys r_mm and d_mm")
    try:
        r = [float(x) * _MM for x in value["r_mm"]]
        d = [float(x) * _MM for x in value["d_mm"]]
    except (TypeError, ValueError):
        raise ValueError(f"{source}: thickness r_mm and d_mm must be lists of numbers") from None
    if len(r) == 2 and len(d) == 2:
        return LinearThickness(r[0], d[0], r[1], d[1])
    return TabulatedThickness(tuple(r), tuple(d))


def _number(value: Any, key: str, source: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{source}: {key} must be a number, got {value!r}")
    return float(value)
