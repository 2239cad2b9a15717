"""Plausibility guards on physical inputs: refuse a value no suction cup has, and name the likely slip.

Each guard raises `ImplausibleInput` (a ValueError: the command line prints it as one line and
exits 2) naming the field, the value, the plausible range and the unit slip that would explain it
("E_MPa = 4e+06: did you give Pa?"). The ranges are wide: they catch factors of 1e3-1e9, not
unusual designs. Only the design guards that a real cup could exceed (a steep cone, a slender
wall) can be overridden, by ``allow_unusual=True`` (``--allow-unusual-design``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["ImplausibleInput", "PLAUSIBLE", "check_modulus", "check_design", "check_uc_table",
           "check_spectrum"]

#: (low, high) plausible range of each guarded quantity, in the unit its field name says
PLAUSIBLE: dict[str, tuple[float, float]] = {
    "E_MPa": (0.01, 1e3),            # soft gels to stiff elastomers
    "r_mm": (0.5, 500.0),            # top-plate and rim radii
    "alpha_deg": (5.0, 80.0),        # cone angle: flatter is a disc, steeper a tube
    "slenderness": (0.0, 400.0),     # wall length / thinnest wall: beyond it the meshes cannot resolve the wall
    "u_c_m": (0.0, 1e-3),            # critical gap: no seal leaves 1 mm (tables reach ~0.2 mm at p/E = 1e-4)
    "h_rms_m": (1e-10, 1e-3),        # surface roughness: atomically flat to sandpaper
}

#: unit slips: (name, factor from the intended unit to the field's unit)
_SLIPS = {
    "E_MPa": (("Pa", 1e-6), ("kPa", 1e-3), ("GPa", 1e3)),
    "r_mm": (("um", 1e-3), ("m", 1e3)),
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


def check_design(design: Mapping[str, Any], allow_unusual: bool = False, source: str = "geometry") -> None:
    """Radii, cone angle and wall slenderness of a design record (`CupGeometry.describe`)."""
    for key in ("r0_mm", "r1_mm"):
        value = float(design[key])
        lo, hi = PLAUSIBLE["r_mm"]
        if not lo <= value <= hi:
            _refuse(f"{source}: {key}", value, "r_mm", " mm")
    if allow_unusual:
        return
    override = "; pass --allow-unusual-design if the design is meant"
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


def check_uc_table(p_over_E: np.ndarray, u_c_m: np.ndarray, field: str = "u_c_m") -> None:
    """Critical gaps in metres (a table in um or nm is the usual slip)."""
    u = np.asarray(u_c_m, dtype=float)
    worst = float(np.max(u, initial=0.0))
    if worst > PLAUSIBLE["u_c_m"][1]:
        i = int(np.argmax(u))
        _refuse(f"{field} at p_over_E = {float(np.asarray(p_over_E)[i]):.4g}", worst, "u_c_m", " m")


def check_spectrum(h_rms_m: float, field: str = "surface") -> None:
    """The rms roughness a power spectrum implies, in metres."""
    lo, hi = PLAUSIBLE["h_rms_m"]
    if not (math.isfinite(h_rms_m) and lo <= h_rms_m <= hi):
        _refuse(f"{field}: rms roughness h_rms_m", h_rms_m, "h_rms_m", " m")
