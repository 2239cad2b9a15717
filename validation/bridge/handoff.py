"""From the FEM's `CupResponse` to the reduced model's `StiffnessCurve`, and the run's JSON sidecar.

The CSV carries only the hand-off columns (``u_mm,h_mm,F0_N,r_c_mm,l_mm,V_mm3``; l is the
force-quartile width of the sealing strip, `fem.cup`), so that `cupcheck lifetime --stiffness`
reads it as it reads a measured curve. Everything else a run knows goes to the sidecar
``<out>.json`` (every key names its unit; lengths in mm like the CSV):

* ``provenance``: geometry, material, contact (``contact``, ``friction`` for coulomb, and
  ``contact_source``: where the law came from), fidelity, mesh, the definition of l, versions;
* ``h1_mm``; ``solver``: the path's `fem.solver.SolverStats` (steps, newton_iterations, cutbacks,
  wall_time_s, dofs, unstable_steps, dissipated_J), ``largest_penetration_mm``,
  ``largest_F0_mismatch_N`` (max |F0 - 2 pi int p r dr|) and ``folding_u_mm`` (or null);
* ``steps``: per converged step ``u_mm``, ``F0_N``, ``F0_contact_N``, the median-force,
  pressure-weighted and half-maximum strip widths ``l_median_mm``, ``l_weighted_mm``,
  ``l_half_max_mm``, ``penetration_mm``, ``energy_J``, ``newton_iterations``, ``unstable`` (the
  tangent lost definiteness in the step that ended there), ``min_stretch``, and the contact
  pressure profile p(r) as the lumped nodal pressures of the contact nodes sorted by deformed
  radius (`fem.contact.PressureProfile.r_m`, ``p_Pa``): ``pressure_r_mm[i]`` and
  ``pressure_kPa[i]``, one list per step (empty where nothing touches).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import asdict
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from fem.cup import CupResponse
from fem.interface import ContactLaw
from reduced.stiffness_curve import StiffnessCurve, profiles_from_lists
from validation.output import software_versions

__all__ = ["stiffness_curve", "provenance", "contact_provenance", "sidecar", "write_sidecar", "software_versions"]



def provenance(response: CupResponse, *, geometry: Mapping[str, Any], mesh: Mapping[str, Any],
               fidelity: str | None, contact_source: str | None = None) -> dict[str, Any]:
    """Where an FEM stiffness curve comes from: geometry, material, contact (the law, Coulomb's
    ``friction``, and ``contact_source``: who chose the law, e.g. "command line", "geometry file
    my_cup.toml", "default", "scene file s.toml"; omitted where the caller does not say), mesh,
    versions."""
    m = response.material
    return {
        "source": "fem",
        "geometry": dict(geometry),
        "material": {"law": "compressible neo-Hookean", "E_Pa": m.E_Pa, "nu": m.nu,
                     "formulation": m.formulation},
        **contact_provenance(response.contact_law, contact_source),
        "fidelity": fidelity,
        "mesh": dict(mesh),
        "l_definition": "force-quartile width 2 (r_75 - r_25) of the radial line force int p dr "
                        "over the innermost contact zone (0: no strip the mesh resolves)",
        "versions": software_versions(),
    }


def contact_provenance(law: ContactLaw, source: str | None = None) -> dict[str, Any]:
    """The provenance's contact keys (stiffness sidecar, suction table) of a
    `fem.interface.ContactLaw`: ``contact`` (the law), ``friction`` (Coulomb's mu, with coulomb
    only) and ``contact_source`` (if known)."""
    return {"contact": law.law, **({"friction": float(law.friction)} if law.law == "coulomb" else {}),
            **({"contact_source": source} if source is not None else {})}


class CurveArrays(Protocol):
    """What the hand-off reads: a `CupResponse`, or a cached result with the same arrays."""

    h1_m: float
    u_m: np.ndarray
    F0_N: np.ndarray
    r_c_m: np.ndarray
    l_m: np.ndarray
    V_m3: np.ndarray


def stiffness_curve(response: CurveArrays, provenance: Mapping[str, Any]) -> StiffnessCurve:
    """The hand-off curve: u, F0 (the plate reaction), r_c, l (force-quartile width) and V per step,
    and, where the response has them, the contact-pressure profiles (lumped nodal pressures)."""
    pressure = getattr(response, "pressure", None)
    profiles = None if not pressure else profiles_from_lists(
        [p.r_m * 1e3 for p in pressure], [p.p_Pa * 1e-3 for p in pressure])
    return StiffnessCurve(u_m=response.u_m, F0_N=response.F0_N + 0.0, h1_m=response.h1_m,
                          r_c_m=response.r_c_m, l_m=response.l_m, V_m3=response.V_m3,
                          provenance=provenance, profiles=profiles)


def sidecar(response: CupResponse, provenance: Mapping[str, Any]) -> dict[str, Any]:
    """The JSON sidecar: provenance, solver statistics and the per-step extras (units in keys)."""
    stats = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in asdict(response.stats).items()}
    stats["largest_penetration_mm"] = float(np.max(np.abs(response.penetration_m), initial=0.0)) * 1e3
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
        "unstable": response.unstable,
        "min_stretch": response.min_stretch,
    }
    steps = {k: np.asarray(v).tolist() for k, v in steps.items()}
    steps["pressure_r_mm"] = [(p.r_m * 1e3).tolist() for p in response.pressure]
    steps["pressure_kPa"] = [(p.p_Pa * 1e-3).tolist() for p in response.pressure]
    return {"provenance": dict(provenance), "h1_mm": response.h1_m * 1e3, "solver": stats,
            "steps": steps}


def write_sidecar(data: Mapping[str, Any], path: str | Path) -> Path:
    """Write the sidecar as indented JSON (to a path the caller makes atomic)."""
    path = Path(path)
    path.write_text(json.dumps(data, indent=1, sort_keys=True, default=_plain, allow_nan=False) + "\n")
    return path


def _plain(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)
