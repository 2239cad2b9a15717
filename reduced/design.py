"""The cup and interface a stiffness curve was computed for, as typed values read from its record.

A curve's provenance is its written record (the JSON sidecar: ``geometry`` in mm and degrees;
``contact``, ``friction``, ``contact_source``). The decisions taken with a curve -- is it the cup
named on the command line? was it computed with the contact law a design file names? -- compare
the values of this module, which read that record in one place (`recorded_design`,
`recorded_contact`). Neither knows the FEM: the bridge builds a `CupShape` from an FEM design's
record (`validation.bridge.design.shape_of`), so a design read back from a sidecar and one built
from a design file are the same kind of value.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["CupShape", "ContactRecord", "recorded_design", "recorded_contact", "DESIGN_KEYS"]

_MM = 1e-3
#: relative tolerance of two records naming the same cup (or the same Coulomb mu)
_SAME = 1e-6
#: the keys a recorded design must have for the reduced model to use it
DESIGN_KEYS = ("r0_mm", "r1_mm", "alpha_deg", "h1_mm")


@dataclass(frozen=True)
class CupShape:
    """What identifies a designed cup (SI; the cone angle in degrees).

    r0_m, r1_m: top-plate and rim radii; alpha_deg: cone angle with the plane; h1_m: the
    undeformed height the design records; d_at_r0_m, d_at_r1_m: wall thickness at both ends
    (None where the record does not say); thickness_convention: how the thickness is measured
    ("normal" or "vertical"); name: the design's label (None: unnamed).
    """

    r0_m: float
    r1_m: float
    alpha_deg: float
    h1_m: float
    d_at_r0_m: float | None = None
    d_at_r1_m: float | None = None
    thickness_convention: str = "normal"
    name: str | None = None

    @classmethod
    def from_record(cls, record: Mapping[str, Any]) -> CupShape:
        """The shape of a design record (mm and degrees: ``r0_mm``, ``r1_mm``, ``alpha_deg``,
        ``h1_mm``, optionally ``d_at_r0_mm``, ``d_at_r1_mm``, ``thickness_convention``, ``name``)."""
        missing = [k for k in DESIGN_KEYS if record.get(k) is None]
        if missing:
            raise ValueError(f"geometry.{missing[0]}: the design record lacks it")
        mm = {k: _number(record, k) for k in (*DESIGN_KEYS, "d_at_r0_mm", "d_at_r1_mm")}
        name = record.get("name")
        return cls(r0_m=mm["r0_mm"] * _MM, r1_m=mm["r1_mm"] * _MM, alpha_deg=mm["alpha_deg"],
                   h1_m=mm["h1_mm"] * _MM,
                   d_at_r0_m=None if mm["d_at_r0_mm"] is None else mm["d_at_r0_mm"] * _MM,
                   d_at_r1_m=None if mm["d_at_r1_mm"] is None else mm["d_at_r1_mm"] * _MM,
                   thickness_convention=str(record.get("thickness_convention") or "normal"),
                   name=None if name is None else str(name))

    def describe(self) -> dict[str, Any]:
        """The record's keys this shape holds (mm and degrees)."""
        out: dict[str, Any] = {"r0_mm": self.r0_m / _MM, "r1_mm": self.r1_m / _MM,
                               "alpha_deg": self.alpha_deg, "h1_mm": self.h1_m / _MM,
                               "thickness_convention": self.thickness_convention}
        for key, value in (("d_at_r0_mm", self.d_at_r0_m), ("d_at_r1_mm", self.d_at_r1_m)):
            if value is not None:
                out[key] = value / _MM
        return out if self.name is None else {"name": self.name, **out}

    @property
    def cone_height_m(self) -> float:
        """h1 = (r1 - r0) tan(alpha) of the cone the radii and angle span (eq 3 at r = r1) [m]."""
        return (self.r1_m - self.r0_m) * math.tan(math.radians(self.alpha_deg))

    def same_cup(self, other: CupShape) -> bool:
        """True if both name the same cup: radii, angle and the thickness at both ends (where both
        say) to a relative 1e-6, and the same thickness convention. The name does not count."""
        pairs = [(self.r0_m, other.r0_m, 1e-12), (self.r1_m, other.r1_m, 1e-12),
                 (self.alpha_deg, other.alpha_deg, 1e-9)]
        pairs += [(a, b, 1e-12) for a, b in ((self.d_at_r0_m, other.d_at_r0_m), (self.d_at_r1_m, other.d_at_r1_m))
                  if a is not None and b is not None]
        return (all(math.isclose(a, b, rel_tol=_SAME, abs_tol=tol) for a, b, tol in pairs)
                and self.thickness_convention == other.thickness_convention)


@dataclass(frozen=True)
class ContactRecord:
    """The interface a curve was computed with: ``law`` (frictionless, sticking, coulomb),
    ``friction`` (Coulomb's mu, 0 for the other laws) and ``source`` (who chose the law:
    "command line", "geometry file my_cup.toml", ...; None where the record does not say)."""

    law: str
    friction: float = 0.0
    source: str | None = None

    def same_law(self, other: ContactRecord) -> bool:
        """True if both name the same law and mu (to a relative 1e-6); who chose it does not count."""
        return self.law == other.law and math.isclose(self.friction, other.friction, rel_tol=_SAME, abs_tol=1e-12)

    def label(self) -> str:
        """Short text: "sticking", "coulomb (mu = 0.3)"."""
        return f"coulomb (mu = {self.friction:g})" if self.law == "coulomb" else self.law

    def describe(self) -> dict[str, Any]:
        """Plain data: law, friction, source."""
        return {"law": self.law, "friction": self.friction, "source": self.source}


def recorded_design(provenance: Mapping[str, Any]) -> CupShape | None:
    """The cup a provenance record names (its ``geometry`` table with r0_mm, r1_mm, alpha_deg,
    h1_mm), or None when it names none (a measured curve, a user's mesh)."""
    geometry = provenance.get("geometry")
    if isinstance(geometry, Mapping) and all(k in geometry for k in DESIGN_KEYS):
        return CupShape.from_record(geometry)
    return None


def recorded_contact(provenance: Mapping[str, Any]) -> ContactRecord | None:
    """The interface a provenance record names (``contact``, ``friction``, ``contact_source``), or
    None when it names no law (a measured curve, Appendix A)."""
    law = provenance.get("contact")
    if not isinstance(law, str):
        return None
    source = provenance.get("contact_source")
    return ContactRecord(law, float(provenance.get("friction", 0.0)), None if source is None else str(source))


def _number(record: Mapping[str, Any], key: str) -> float | None:
    value = record.get(key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"geometry.{key}: expected a number, got {value!r:.40}")
    return float(value)
