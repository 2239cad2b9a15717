"""Which cup a lifetime is computed for: the stiffness curve's recorded design, a geometry file or a
Table 1 preset, turned into the reduced model's `CupParameters` (eqs 3-6).

An FEM stiffness curve records the design it was computed for, which it reads back as a typed
`reduced.design.CupShape` (`StiffnessCurve.design`: r0, r1, alpha, h1, the thickness at both
ends). A lifetime takes the cup from there; an explicit ``--cup`` or ``--geometry FILE`` must
describe the same cup, or the run is refused with both named. A curve that names no design (a
measured CSV, a user's mesh) takes the explicit cup, else cup A with a note saying so. The curve also records its interface with the plane (`StiffnessCurve.contact`,
a `reduced.design.ContactRecord`); a ``--geometry FILE`` whose ``[contact]`` table names another
law or mu is refused the same way. Every decision compares these typed values; an FEM design
becomes one through its own record (`shape_of`), the form the curve's sidecar keeps.

For a Table 1 cup (A, B) the reduced model keeps the paper's r_start = 12 mm, l0, l1 and
beta = 0.8. Any other design keeps beta = 0.8 (Table 1's value for both cups), starts at the middle
of the wall, r_start = (r0 + r1) / 2 (where 12 mm lies for A and B), and takes eq (5)'s strip
widths l0, l1 from a least-squares line through the curve's l(r_c) samples, unless given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from reduced.cup import CUPS, CupParameters
from reduced.design import ContactRecord, CupShape
from reduced.stiffness_curve import StiffnessCurve

if TYPE_CHECKING:
    from fem.geometry import CupGeometry
    from fem.interface import ContactLaw

__all__ = ["CupChoice", "resolve_cup", "explicit_design", "preset_design", "shape_of"]

_MM = 1e-3


@dataclass(frozen=True)
class CupChoice:
    """The cup a lifetime uses, where it came from, and what was assumed on the way."""

    cup: CupParameters
    design: CupShape
    label: str                 # e.g. "cup A (Table 1)", "my_cup.toml: r0 5, r1 25 mm, alpha 40 deg"
    source: str                # "stiffness curve", "geometry file", "preset" or "default preset"
    l_source: str              # where eq (5)'s l0, l1 come from
    notes: tuple[str, ...] = ()
    contact: ContactRecord | None = None    # the curve's interface (`StiffnessCurve.contact`)

    def describe(self) -> dict[str, Any]:
        """JSON-ready description (mm, degrees) for every lifetime output."""
        c = self.cup
        return {"label": self.label, "name": c.name, "source": self.source,
                "r0_mm": c.r0_m / _MM, "r1_mm": c.r1_m / _MM, "alpha_deg": c.alpha_deg,
                "h1_mm": c.h1_m / _MM, "r_start_mm": c.r_start_m / _MM, "l0_mm": c.l0_m / _MM,
                "l1_mm": c.l1_m / _MM, "beta": c.beta, "l_source": self.l_source,
                "contact": None if self.contact is None else self.contact.describe()}


def shape_of(geometry: CupGeometry) -> CupShape:
    """The `CupShape` of an FEM design, through its record (`CupGeometry.describe`, mm and degrees):
    the form a curve's sidecar keeps, so that a design and a curve's read-back compare alike."""
    return CupShape.from_record(geometry.describe())


@cache
def preset_design(name: str) -> CupShape:
    """The shape of Table 1 cup `name` as the FEM builds it (`fem.geometry.cup_geometry`)."""
    from fem.geometry import cup_geometry          # numpy only: no FEM machinery is imported
    return shape_of(cup_geometry(name))


def resolve_cup(curve: StiffnessCurve | None, *, cup: str | None = None,
                geometry_file: str | Path | None = None, r_start_mm: float | None = None,
                l0_mm: float | None = None, l1_mm: float | None = None,
                curve_label: str = "the stiffness curve", laws: str = "cone") -> CupChoice:
    """The cup for a lifetime: the curve's design, checked against an explicit cup or file.

    laws: 'cone' (eq 5's l0, l1 are needed) or 'curve' (r, V, l come from the curve: a custom
    design's l0, l1 are then not used and never refuse the run)."""
    explicit, file_contact = _explicit(cup, geometry_file) if (cup or geometry_file) else (None, None)
    explicit_label = f"--geometry {geometry_file}" if geometry_file is not None else f"--cup {cup}"
    recorded = curve.design if curve is not None else None
    notes: list[str] = []
    if recorded is not None and explicit is not None and not recorded.same_cup(explicit):
        raise ValueError(f"cup: {curve_label} was computed for {_label(recorded)}, but "
                         f"{explicit_label} is {_label(explicit)}; drop the option or use that "
                         f"cup's curve")
    _check_contact(curve, file_contact, curve_label, explicit_label)
    if recorded is not None:
        design, source = recorded, "stiffness curve"
    elif explicit is not None:
        design, source = explicit, ("geometry file" if geometry_file is not None else "preset")
    else:
        design, source = preset_design("A"), "default preset"
        if curve is not None:
            notes.append(f"{curve_label} names no cup design: cup A of Table 1 assumed "
                         f"(give --cup or --geometry)")
    if curve is not None:
        _check_height(design, curve, curve_label)
    params, l_source = _parameters(design, curve, r_start_mm, l0_mm, l1_mm, laws)
    return CupChoice(cup=params, design=design, label=_label(design), source=source, l_source=l_source,
                     notes=tuple(notes), contact=getattr(curve, "contact", None))


def explicit_design(cup: str | None, geometry_file: str | Path | None) -> CupShape:
    """The shape of a geometry file (starting from preset `cup`) or of preset `cup` (cup A when
    neither is given)."""
    return _explicit(cup, geometry_file)[0]


def _explicit(cup: str | None, geometry_file: str | Path | None) -> tuple[CupShape, ContactRecord | None]:
    """(the shape, the file's [contact] law or None) of `explicit_design`."""
    if geometry_file is not None:
        from validation.guards import load_design
        design = load_design(geometry_file, cup=cup or "A", allow_unusual=True)   # the caller checks the rest
        return shape_of(design.geometry), None if design.contact is None else _contact_record(design.contact)
    return preset_design(cup or "A"), None


def _contact_record(law: ContactLaw) -> ContactRecord:
    """A design file's law as the record a curve keeps (who chose it is the curve's to say)."""
    return ContactRecord(law.law, law.friction)


def _check_contact(curve: StiffnessCurve | None, file_contact: ContactRecord | None,
                   curve_label: str, explicit_label: str) -> None:
    """Refuse a design file whose [contact] law or mu differs from the one the curve was computed with."""
    recorded = getattr(curve, "contact", None)   # a curve-like record without it (the suction table's) names none
    if recorded is None or file_contact is None:
        return
    if not recorded.same_law(file_contact):
        raise ValueError(f"contact: {curve_label} was computed with {recorded.label()} contact, but "
                         f"{explicit_label} says {file_contact.label()}; drop the option or use "
                         f"that design's curve")


def _preset_of(design: CupShape) -> str | None:
    return next((name for name in CUPS if design.same_cup(preset_design(name))), None)


def _label(design: CupShape) -> str:
    preset = _preset_of(design)
    if preset is not None:
        return f"cup {preset} (Table 1)"
    name = "a custom design" if design.name is None else design.name
    return (f"{name} (r0 {design.r0_m / _MM:.4g} mm, r1 {design.r1_m / _MM:.4g} mm, alpha "
            f"{design.alpha_deg:.4g} deg)")


def _check_height(design: CupShape, curve: StiffnessCurve, curve_label: str) -> None:
    h1 = design.cone_height_m
    if not math.isclose(h1, curve.h1_m, rel_tol=1e-4):
        raise ValueError(f"cup: {curve_label} has h1 = {1e3 * curve.h1_m:.6g} mm but {_label(design)} "
                         f"has h1 = (r1 - r0) tan(alpha) = {h1 / _MM:.6g} mm: not the same cup")


def _parameters(design: CupShape, curve: StiffnessCurve | None, r_start_mm: float | None,
                l0_mm: float | None, l1_mm: float | None, laws: str = "cone") -> tuple[CupParameters, str]:
    """Table 1's parameters for a preset; the design's own otherwise (module docstring)."""
    preset = _preset_of(design)
    r0, r1 = design.r0_m, design.r1_m
    if r_start_mm is not None and not (math.isfinite(r_start_mm) and r0 < r_start_mm * _MM < r1):
        raise ValueError(f"r_start_mm: start radius must be in (r0, r1) = ({r0 / _MM:g}, "
                         f"{r1 / _MM:g}) mm, got {r_start_mm:g}")
    if (l0_mm is None) != (l1_mm is None):
        raise ValueError("l0_mm, l1_mm: give both strip widths of eq (5) or neither")
    for name, value in (("l0_mm", l0_mm), ("l1_mm", l1_mm)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name}: contact-strip width must be > 0 mm, got {value:g}")
    r_start = None if r_start_mm is None else r_start_mm * _MM
    if preset is not None:
        base = CUPS[preset]
        if l0_mm is not None:
            base = replace(base, l0_m=l0_mm * _MM, l1_m=l1_mm * _MM)
        return (replace(base, r_start_m=r_start or base.r_start_m),
                "given" if l0_mm is not None else "Table 1")
    if l0_mm is not None:
        l0, l1, l_source = l0_mm * _MM, l1_mm * _MM, "given"
    else:
        try:
            l0, l1, l_source = _fitted_strip_widths(curve, r0, r1, design)
        except ValueError:
            if laws == "cone":
                raise
            l0, l1, l_source = 0.1 * (r1 - r0), 0.1 * (r1 - r0), "not used: r, V, l from the curve"
    cup = CupParameters(r0_m=r0, r1_m=r1, alpha_deg=design.alpha_deg,
                        r_start_m=r_start or 0.5 * (r0 + r1), l0_m=l0, l1_m=l1, beta=0.8,
                        name="custom" if design.name is None else design.name)
    return cup, l_source


def _fitted_strip_widths(curve: StiffnessCurve | None, r0: float, r1: float,
                         design: CupShape) -> tuple[float, float, str]:
    """l0, l1 of eq (5) from a least-squares line through the curve's (r_c, l > 0) samples."""
    refuse = (f"l0_mm, l1_mm: {_label(design)} is not a Table 1 cup, so eq (5)'s strip widths "
              f"are unknown")
    if curve is None or not (curve.has("r_c_m") and curve.has("l_m")):
        raise ValueError(f"{refuse}: give --l0-mm and --l1-mm, or an FEM stiffness curve "
                         f"(it carries l and r_c)")
    ok = curve.l_m > 0
    r, l = curve.r_c_m[ok], curve.l_m[ok]
    if r.size < 2 or np.ptp(r) <= 1e-3 * (r1 - r0):
        raise ValueError(f"{refuse} and the curve resolves a strip at {r.size} radii only: give "
                         f"--l0-mm and --l1-mm")
    slope, intercept = np.polyfit(r, l, 1)
    l0, l1 = intercept + slope * r0, intercept + slope * r1
    if not (l0 > 0 and l1 > 0):
        raise ValueError(f"{refuse} and the line through the curve's l(r_c) gives l0 = "
                         f"{l0 / _MM:.3g} mm, l1 = {l1 / _MM:.3g} mm: give --l0-mm and --l1-mm")
    return float(l0), float(l1), (f"eq (5) fitted to the curve's l(r_c) at {r.size} samples: "
                                  f"l0 = {l0 / _MM:.3g} mm, l1 = {l1 / _MM:.3g} mm")
