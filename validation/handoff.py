"""From the FEM's `CupResponse` to the reduced model's `StiffnessCurve`, and the run's JSON sidecar.

The CSV carries only the hand-off columns (``u_mm,h_mm,F0_N,r_c_mm,l_mm,V_mm3``; l is the
force-quartile width of the sealing strip, `fem.cup`), so that `cupcheck lifetime --stiffness`
reads it as it reads a measured curve. Everything else a run knows goes to the sidecar
``<out>.json``: the provenance, the solver statistics, and per step the plate reaction and the
integrated contact force, the median-force, pressure-weighted and half-maximum strip widths, the
largest penetration, the stored energy and the Newton iterations.
"""

from __future__ import annotations

import json
import platform
from collections.abc import Mapping
from dataclasses import asdict
from importlib import metadata
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from fem.cup import CupResponse
from reduced.stiffness_curve import StiffnessCurve

__all__ = ["stiffness_curve", "provenance", "sidecar", "write_sidecar", "software_versions"]

_PACKAGES = ("cupcheck", "numpy", "scipy", "scikit-fem", "meshio")


def software_versions() -> dict[str, str]:
    """Versions of Python and of the packages the FEM result depends on."""
    versions = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return versions


def provenance(response: CupResponse, *, geometry: Mapping[str, Any], mesh: Mapping[str, Any],
               fidelity: str | None) -> dict[str, Any]:
    """Where an FEM stiffness curve comes from: geometry, material, contact, mesh, versions."""
    m = response.material
    return {
        "source": "fem",
        "geometry": dict(geometry),
        "material": {"law": "compressible neo-Hookean", "E_Pa": m.E_Pa, "nu": m.nu,
                     "formulation": m.formulation},
        "contact": response.contact,
        "fidelity": fidelity,
        "mesh": dict(mesh),
        "l_definition": "force-quartile width 2 (r_75 - r_25) of the radial line force int p dr "
                        "over the innermost contact zone (0: no strip the mesh resolves)",
        "versions": software_versions(),
    }


class CurveArrays(Protocol):
    """What the hand-off reads: a `CupResponse`, or a cached result with the same arrays."""

    h1_m: float
    u_m: np.ndarray
    F0_N: np.ndarray
    r_c_m: np.ndarray
    l_m: np.ndarray
    V_m3: np.ndarray


def stiffness_curve(response: CurveArrays, provenance: Mapping[str, Any]) -> StiffnessCurve:
    """The hand-off curve: u, F0 (the plate reaction), r_c, l (force-quartile width) and V per step."""
    return StiffnessCurve(u_m=response.u_m, F0_N=response.F0_N + 0.0, h1_m=response.h1_m,
                          r_c_m=response.r_c_m, l_m=response.l_m, V_m3=response.V_m3,
                          provenance=provenance)


def sidecar(response: CupResponse, provenance: Mapping[str, Any]) -> dict[str, Any]:
    """The JSON sidecar: provenance, solver statistics and the per-step extras (units in keys)."""
    stats = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in asdict(response.stats).items()}
    stats["largest_penetration_m"] = float(np.max(np.abs(response.penetration_m), initial=0.0))
    stats["largest_F0_mismatch_N"] = float(np.max(np.abs(response.F0_N - response.F0_contact_N),
                                                  initial=0.0))
    folding = response.folding_u_m
    stats["folding_u_mm"] = None if folding is None else folding * 1e3
    steps = {
        "u_mm": response.u_m * 1e3,
        "F0_N": response.F0_N,
        "F0_contact_N": response.F0_contact_N,
        "l_median_mm": response.l_median_m * 1e3,
        "l_weighted_mm": response.l_weighted_m * 1e3,
        "l_half_max_mm": response.l_half_max_m * 1e3,
        "penetration_mm": response.penetration_m * 1e3,
        "energy_J": response.energy_J,
        "newton_iterations": response.newton_iterations,
        "min_stretch": response.min_stretch,
    }
    return {"provenance": dict(provenance), "h1_mm": response.h1_m * 1e3, "solver": stats,
            "steps": {k: np.asarray(v).tolist() for k, v in steps.items()}}


def write_sidecar(data: Mapping[str, Any], path: str | Path) -> Path:
    """Write the sidecar as indented JSON (to a path the caller makes atomic)."""
    path = Path(path)
    path.write_text(json.dumps(data, indent=1, sort_keys=True, default=_plain) + "\n")
    return path


def _plain(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)
