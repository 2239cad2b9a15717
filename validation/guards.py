"""Plausibility guards on physical inputs: refuse a value no suction cup has, and name the likely slip.

Each guard raises `ImplausibleInput` (a ValueError: the command line prints it as one line and
exits 2) naming the field as the user wrote it (``--E-MPa``, ``material.E_MPa``,
``axes[0].values[2]``, ``g.toml: thickness.d_mm[0]``), the value, the plausible range and the
unit slip that would explain it ("E_MPa = 4e+06: did you give Pa?"). The ranges are wide: they
catch factors of 1e3-1e9, not unusual designs. Only the design guards that a real cup could
exceed (a steep cone, a slender wall) can be overridden, by ``allow_unusual=True``
(``--allow-unusual-design``, a scene's ``cup.allow_unusual_design``, a sweep's
``base.allow_unusual_design``).

The command line, scene files, sweep files and design files call the same guards, before any FEM
work: `check_modulus`, `check_forces`, `load_design` (the guarded reader of a design file: its raw
lengths, then the built wall), `check_design`, `check_stiffness_curve` (a curve's displacements
against the cup's height, its recorded modulus against the one given), `check_plate_travel` (an
FEM path's end within the cup's height) and `check_uc_table`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

__all__ = ["ImplausibleInput", "PLAUSIBLE", "check_modulus", "check_forces", "check_start_radius", "check_length",
           "check_design_data", "load_design", "check_design", "check_stiffness_curve", "check_uc_table",
           "check_uc_file", "check_spectrum", "check_plate_travel"]

#: (low, high) plausible range of each guarded quantity, in the unit its field name says
PLAUSIBLE: dict[str, tuple[float, float]] = {
    "E_MPa": (0.01, 1e3),            # soft gels to stiff elastomers
    "r_mm": (0.5, 500.0),            # top-plate and rim radii
    "d_mm": (0.01, 50.0),            # wall thickness
    "u_mm": (0.01, 500.0),           # an FEM path's plate displacement, before its cup is known (<= h1)
    "F_N": (1e-6, 1e5),              # pull force: below a micronewton p/E underflows, above 10 kN no cup holds
    "alpha_deg": (5.0, 80.0),        # cone angle: flatter is a disc, steeper a tube
    "slenderness": (0.0, 400.0),     # wall length / thinnest wall: beyond it the meshes cannot resolve the wall
    "u_c_m": (0.0, 1e-3),            # critical gap: no seal leaves 1 mm (tables reach ~0.2 mm at p/E = 1e-4)
    "h_rms_m": (1e-10, 1e-3),        # surface roughness: atomically flat to sandpaper
}

#: unit slips: (name, factor from the intended unit to the field's unit)
_SLIPS = {
    "E_MPa": (("Pa", 1e-6), ("kPa", 1e-3), ("GPa", 1e3)),
    "r_mm": (("um", 1e-3), ("m", 1e3)),
    "d_mm": (("um", 1e-3), ("m", 1e3)),
    "u_mm": (("um", 1e-3), ("m", 1e3)),
    "F_N": (("mN", 1e-3), ("kN", 1e3)),
    "u_c_m": (("um", 1e-6), ("nm", 1e-9)),
    "h_rms_m": (("um (C in um^4, q in 1/um)", 1e-6), ("nm", 1e-9)),
}


class ImplausibleInput(ValueError):
    """A physical input outside the range any suction cup has (the message names the likely slip)."""


def _refuse(field: str, value: float, kind: str, extra: str = "") -> None:
    lo, hi = PLAUSIBLE[kind]
    slips = [name for name, factor in _SLIPS.get(kind, ()) if lo <= value * factor <= hi]
    hint = f": did you give {' or '.join(slips)}?" if slips else ""
    raise ImplausibleInput(f"{field} = {value:.4g}{hint} (plausible: {lo:g} .. {hi:g}{extra})")


def check_modulus(E_MPa: float, field: str = "E_MPa") -> float:
    """A Young's modulus in MPa in the plausible range of cup materials."""
    if not (math.isfinite(E_MPa) and E_MPa > 0):
        raise ValueError(f"{field}: Young's modulus must be > 0 MPa, got {E_MPa:g}")
    lo, hi = PLAUSIBLE["E_MPa"]
    if not lo <= E_MPa <= hi:
        _refuse(field, E_MPa, "E_MPa", " MPa")
    return E_MPa


def check_forces(forces_N: Any, field: str = "F1_N") -> list[float]:
    """Pull forces in N, each finite and in the plausible range (a force too small to give a
    contact pressure is named here, not by the reduced model's internal p/E)."""
    values = list(forces_N) if isinstance(forces_N, (list, tuple)) else [forces_N]
    for i, F in enumerate(values):
        where = field if len(values) == 1 else f"{field}[{i}]"
        if not (math.isfinite(F) and F > 0):
            raise ValueError(f"{where}: pull force must be > 0 N, got {F:g}")
        lo, hi = PLAUSIBLE["F_N"]
        if not lo <= F <= hi:
            _refuse(where, F, "F_N", " N")
    return [float(F) for F in values]


def check_start_radius(r_start_mm: float | None, radii_mm: tuple[float, float], field: str) -> None:
    """The reduced model's start radius inside the wall, r0 < r_start < r1 (None: the default)."""
    if r_start_mm is None:
        return
    r0, r1 = radii_mm
    if isinstance(r_start_mm, bool) or not isinstance(r_start_mm, (int, float)):
        return                                 # not a number: the reader that types it says so
    if not (math.isfinite(r_start_mm) and r0 < r_start_mm < r1):
        slips = [name for name, factor in _SLIPS["r_mm"] if r0 < r_start_mm * factor < r1]
        hint = f": did you give {' or '.join(slips)}?" if slips else ""
        raise ImplausibleInput(f"{field} = {r_start_mm:.4g}{hint} (the start radius must lie in (r0, r1) = "
                               f"({r0:.4g}, {r1:.4g}) mm)")


def check_length(value: Any, field: str, kind: str = "r_mm") -> None:
    """A radius (kind "r_mm"), wall thickness ("d_mm") or plate displacement ("u_mm") in mm; a value that is not a number is
    left to the reader that types it."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        return
    lo, hi = PLAUSIBLE[kind]
    if not lo <= value <= hi:
        _refuse(field, float(value), kind, " mm")


def check_design_data(data: Mapping[str, Any], source: str = "design") -> None:
    """The raw lengths of a design file's table (before the wall is built, so that a slip is named
    as the slip, not as the odd wall it makes): r0_mm, r1_mm and the thickness table."""
    for key in ("r0_mm", "r1_mm"):
        check_length(data.get(key), f"{source}: {key}")
    table = data.get("thickness")
    if isinstance(table, Mapping):
        for key, kind in (("r_mm", "r_mm"), ("d_mm", "d_mm")):
            values = table.get(key)
            if isinstance(values, list):
                for i, value in enumerate(values):
                    check_length(value, f"{source}: thickness.{key}[{i}]", kind)


def load_design(path: str | Path, cup: str = "A", field: str | None = None, allow_unusual: bool = False,
                override: str = "pass --allow-unusual-design"):
    """A design file read and guarded: its raw lengths (`check_design_data`), then the file as
    `fem.design_file.load_design` reads it (its own structural checks), then the built wall
    (`check_design`). `field` names where the user gave the file (``cup.geometry``, ``--geometry``)."""
    from fem.design_file import load_design as read_design

    path = Path(path)
    source = f"{field} ({path.name})" if field else path.name
    data = _raw_table(path)
    if data is not None:
        check_design_data(data, source)
    design = read_design(path, cup=cup)
    check_design(design.geometry.describe(), allow_unusual, source=source, override=override)
    return design


def _raw_table(path: Path) -> Mapping[str, Any] | None:
    """The parsed table of a design file, or None where the file's own reader will say what is wrong."""
    import json
    import tomllib

    try:
        text = path.read_text(encoding="utf-8")
        data = tomllib.loads(text) if path.suffix.lower() == ".toml" else json.loads(text)
    except (OSError, ValueError):
        return None
    return data if isinstance(data, Mapping) else None


def check_design(design: Mapping[str, Any], allow_unusual: bool = False, source: str = "geometry",
                 override: str = "pass --allow-unusual-design") -> None:
    """Radii, wall thickness, cone angle and wall slenderness of a design record
    (`CupGeometry.describe`); `override` says how the user accepts an unusual design."""
    for key in ("r0_mm", "r1_mm"):
        value = float(design[key])
        lo, hi = PLAUSIBLE["r_mm"]
        if not lo <= value <= hi:
            _refuse(f"{source}: {key}", value, "r_mm", " mm")
    for key in ("d_at_r0_mm", "d_at_r1_mm"):
        if key in design:
            value = float(design[key])
            lo, hi = PLAUSIBLE["d_mm"]
            if not lo <= value <= hi:
                _refuse(f"{source}: wall thickness {key}", value, "d_mm", " mm")
    if allow_unusual:
        return
    override = f"; {override} if the design is meant"
    alpha = float(design["alpha_deg"])
    lo, hi = PLAUSIBLE["alpha_deg"]
    if not lo <= alpha <= hi:
        raise ImplausibleInput(f"{source}: alpha_deg = {alpha:g} is outside {lo:g} .. {hi:g} deg (a "
                               f"{'disc' if alpha < lo else 'tube'}, h1 = {design['h1_mm']:.4g} mm, "
                               f"not a cup){override}")
    length = (float(design["r1_mm"]) - float(design["r0_mm"])) / math.cos(math.radians(alpha))
    thinnest = min(float(design["d_at_r0_mm"]), float(design["d_at_r1_mm"]))
    ratio = length / thinnest
    if ratio > PLAUSIBLE["slenderness"][1]:
        raise ImplausibleInput(f"{source}: the wall is {length:.4g} mm long and {thinnest:.3g} mm thin "
                               f"(slenderness {ratio:.0f}, plausible <= {PLAUSIBLE['slenderness'][1]:g}): "
                               f"the FEM meshes cannot resolve it{override}")


def check_plate_travel(u_mm: float, h1_mm: float, field: str) -> float:
    """An FEM path's end, the plate displacement u [mm], in (h1 / 100, h1]: beyond the cup's height
    h1 the plate would pass through the plane (a value in um runs far beyond it), and a path
    shorter than 1 % of h1 reaches no state a lifetime reads (a value in m is that short)."""
    if not (math.isfinite(u_mm) and u_mm > 0):
        raise ValueError(f"{field}: plate displacement must be > 0 mm, got {u_mm:g}")
    if u_mm > h1_mm * (1 + 1e-9):          # beyond the round-off of an mm -> m conversion
        hint = ": did you give um?" if h1_mm / 100 <= u_mm * 1e-3 <= h1_mm else ""
        raise ImplausibleInput(f"{field} = {u_mm:.9g}{hint} (the plate displacement must lie in (0, h1] = "
                               f"(0, {h1_mm:.9g}] mm: at h1 the plate edge reaches the plane)")
    if u_mm < h1_mm / 100:
        hint = ": did you give m?" if h1_mm / 100 <= u_mm * 1e3 <= h1_mm else ""
        raise ImplausibleInput(f"{field} = {u_mm:.4g}{hint} (plausible: {h1_mm / 100:.4g} .. {h1_mm:.9g} mm, "
                               f"1 % of the cup's height h1 to h1)")
    return min(float(u_mm), h1_mm)


def check_stiffness_curve(curve: Any | None, h1_mm: float, field: str, E_MPa: float | None = None,
                          E_field: str = "--E-MPa") -> None:
    """A stiffness curve against the cup it is used for: its displacements within the cup's
    height h1 (a u column in um runs far beyond it), and the modulus its sidecar records equal to
    the modulus given (`E_MPa`, named `E_field`), since F0 scales with E. None (no curve: Appendix A)
    passes."""
    if curve is None:
        return
    u_max_mm = 1e3 * float(curve.u_m[-1])
    if u_max_mm > h1_mm * (1 + 1e-6):
        hint = ": did you give um?" if u_max_mm * 1e-3 <= h1_mm else ""
        raise ImplausibleInput(f"{field}: u_mm runs to {u_max_mm:.4g} mm, beyond the cup's height h1 = "
                               f"{h1_mm:.4g} mm (the plate stops at u = h1){hint}")
    material = curve.provenance.get("material") if isinstance(curve.provenance, Mapping) else None
    recorded = material.get("E_Pa") if isinstance(material, Mapping) else None
    if E_MPa is None or isinstance(recorded, bool) or not isinstance(recorded, (int, float)):
        return
    if not math.isclose(1e-6 * recorded, E_MPa, rel_tol=1e-6):
        raise ImplausibleInput(f"{E_field} = {E_MPa:g} MPa, but {field} was computed with E = "
                               f"{1e-6 * recorded:g} MPa (its sidecar); F0 scales with E: give {E_field} "
                               f"{1e-6 * recorded:g} or a curve computed at {E_MPa:g} MPa")


def check_uc_table(p_over_E: np.ndarray, u_c_m: np.ndarray, field: str = "u_c_m") -> None:
    """Critical gaps in metres (a table in um or nm is the usual slip)."""
    import numpy as np          # a scene's checks import numpy only for a u_c table

    u = np.asarray(u_c_m, dtype=float)
    worst = float(np.max(u, initial=0.0))
    if worst > PLAUSIBLE["u_c_m"][1]:
        i = int(np.argmax(u))
        _refuse(f"{field} at p_over_E = {float(np.asarray(p_over_E)[i]):.4g}", worst, "u_c_m", " m")


def check_uc_file(path: str | Path, field: str) -> None:
    """A u_c table file (columns p_over_E,u_c_m) read and guarded, `field` naming where it was given."""
    from reduced.critical_gap import UcTable

    try:
        table = UcTable.from_csv(path)
    except ValueError as exc:
        raise ValueError(f"{field}: {exc}") from None
    check_uc_table(table.p_over_E, table.u_c_m, f"{field}: u_c_m")


def check_spectrum(h_rms_m: float, field: str = "surface") -> None:
    """The rms roughness a power spectrum implies, in metres."""
    lo, hi = PLAUSIBLE["h_rms_m"]
    if not (math.isfinite(h_rms_m) and lo <= h_rms_m <= hi):
        _refuse(f"{field}: rms roughness h_rms_m", h_rms_m, "h_rms_m", " m")
