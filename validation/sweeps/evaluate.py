"""One design of a sweep, end to end: geometry -> FEM stiffness curve -> the quantities that matter.

`evaluate_design` is the unit of work a dask worker runs. It never raises for the design's own
sake: an invalid geometry or a solver failure becomes rows whose `failure` names the stage and the
cause, so one bad design never stops a sweep. Quantities (units in the names):

* ``F0_at_<u>mm_N``: the FEM's F0 at the requested plate displacements;
* ``small_u_stiffness_N_per_mm``: the secant F0(1 mm) / 1 mm; ``appendix_a_ratio``: that over
  Appendix A's secant for the design's own alpha, r0, r1, E and root thickness d0 (d1 = 0);
* ``r_c_start_mm``, ``l_start_mm``: the FEM's inner contact radius and strip width at the start
  state (eq 3's height at r_start); ``largest_force_N``: the largest F1 the fresh cup holds;
* ``lifetime_s``, ``reason`` per pull force (by default the paper's route, eqs 3-7 with the cone
  laws and eq (5)'s strip widths l0, l1 as given, by default Table 1's for the base cup, the only
  measured ones; or base.route's; no relaxation, u_c(p/E) of the surface);
* ``volume_mm3``: the wall's material volume (a cost for the Pareto front);
* cost: ``wall_time_s``, ``dofs``, ``newton_iterations``.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any

from validation.sweeps.spec import design_hash

if TYPE_CHECKING:
    from validation.bridge.study import Study

__all__ = ["evaluate_design", "study_of", "geometry_of", "material_volume_mm3"]

_MM = 1e-3


def geometry_of(design: dict[str, Any]):
    """The `fem.geometry.CupGeometry` of a design (the preset with its overrides)."""
    from fem.geometry import LinearThickness, cup_geometry

    base = cup_geometry(design["cup"])
    r0 = design["r0_mm"] * _MM if design.get("r0_mm") is not None else base.r0_m
    r1 = design["r1_mm"] * _MM if design.get("r1_mm") is not None else base.r1_m
    d0 = design["d0_mm"] * _MM if design.get("d0_mm") is not None else float(base.thickness(base.r0_m))
    d1 = design["d1_mm"] * _MM if design.get("d1_mm") is not None else float(base.thickness(base.r1_m))
    alpha = design["alpha_deg"] if design.get("alpha_deg") is not None else base.alpha_deg
    return cup_geometry(design["cup"], r0_m=r0, r1_m=r1, alpha_deg=alpha,
                        thickness=LinearThickness(r0, d0, r1, d1), name=f"design {design_hash(design)}")


def material_volume_mm3(geometry) -> float:
    """The wall's volume of revolution, pi oint r^2 dz around the cross-section [mm^3]."""
    poly = geometry.boundary_polygon(401)
    r, z = poly[:, 0], poly[:, 1]
    r2, z2 = r[[*range(1, len(r)), 0]], z[[*range(1, len(z)), 0]]
    # a counter-clockwise outline in (r, z): V = -pi/3 sum (z2 - z1)(r1^2 + r1 r2 + r2^2)
    return float(abs(math.pi / 3.0 * sum((b - a) * (p * p + p * q + q * q)
                                         for a, b, p, q in zip(z, z2, r, r2)))) / _MM ** 3


def study_of(design: dict[str, Any], geometry) -> Study:
    """The `validation.bridge.study.Study` of one design of a sweep: its base keys as the study's
    fields (`validation.study_schema`), its geometry, its route (the paper's with the cone laws
    and eq (5)'s l0, l1, Table 1's unless given; or profile, fem) on its surface, at its pull forces."""
    from dataclasses import replace

    from reduced.cup import CUPS
    from validation.study_schema import FIELDS, study_from_values

    table1 = CUPS[design["cup"]]
    values = {f.key: design[f.sweep] for f in FIELDS if f.sweep and f.sweep in design}
    values["cup.l0_mm"] = design["l0_mm"] if design.get("l0_mm") is not None else table1.l0_m / _MM
    values["cup.l1_mm"] = design["l1_mm"] if design.get("l1_mm") is not None else table1.l1_m / _MM
    values["contact.friction"] = design.get("friction", 0.0) if design["contact"] == "coulomb" else None
    route = design.get("route", "paper")
    study = study_from_values(values, contact_source="sweep file", stiffness="fem",
                              cup_laws="cone" if route == "paper" else None, refine=1)
    return replace(study, design=replace(study.design, geometry=geometry))


def evaluate_design(design: dict[str, Any]) -> list[dict[str, Any]]:
    """Rows (one per pull force) of one design: its parameters, hash, quantities or failure."""
    start = time.perf_counter()
    common = {**{k: v for k, v in design.items() if k not in ("F1_N", "F0_at_u_mm", "allow_unusual_design")},
              "design_hash": design_hash(design)}
    stage = "geometry"
    try:
        from validation.guards import check_design
        from validation.bridge.products import Products

        geometry = geometry_of(design)
        check_design(geometry.describe(), design["allow_unusual_design"], source="design")
        common["volume_mm3"] = material_volume_mm3(geometry)
        stage = "fem"
        products = Products(study_of(design, geometry))
        response, curve = products.fem_path(None), products.curve()
        common.update(_fem_quantities(response, curve, geometry, design))
        stage = "lifetime"
        rows = _lifetimes(products, design, common)
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        reason = f"{stage}: {type(exc).__name__}: {' '.join(str(exc).split())[:300]}"
        rows = [{**common, "F1_N": F, "failure": reason} for F in design["F1_N"]]
    wall = time.perf_counter() - start
    for row in rows:
        row["wall_time_s"] = wall
    return rows


def _fem_quantities(response, curve, geometry, design) -> dict[str, Any]:
    from reduced.appendix_a import appendix_a_force

    out: dict[str, Any] = {"dofs": response.stats.dofs, "newton_iterations": response.stats.newton_iterations}
    u_hi = float(curve.u_m[-1])
    for u_mm in design["F0_at_u_mm"]:
        out[f"F0_at_{u_mm:g}mm_N"] = float(curve.force(curve.h1_m - u_mm * _MM)) if u_mm * _MM <= u_hi else None
    stiffness = float(curve.force(curve.h1_m - 1e-3)) / 1.0
    d0 = float(geometry.thickness(geometry.r0_m))
    app = float(appendix_a_force(1e-3, geometry.alpha_deg, design["E_MPa"] * 1e6, d0, geometry.r0_m,
                                 geometry.r1_m)) / 1.0
    out.update(small_u_stiffness_N_per_mm=stiffness, appendix_a_ratio=stiffness / app)
    return out


def _lifetimes(products, design, common) -> list[dict[str, Any]]:
    curve, cup = products.curve(), products.cup()
    h_start = cup.h_start_m
    common = {**common, "r_start_mm": cup.r_start_m / _MM, "l0_mm": products.study.design.l0_mm,
              "l1_mm": products.study.design.l1_mm,
              "r_c_start_mm": float(curve.contact_radius(h_start)) / _MM,
              "l_start_mm": float(curve.contact_width(h_start)) / _MM}
    results = products.lifetimes()
    common["largest_force_N"] = results.largest_force_N
    return [{**common, "F1_N": F, "lifetime_s": r.lifetime_s if math.isfinite(r.lifetime_s) else None,
             "reason": r.reason, "failure": None} for F, r in zip(design["F1_N"], results)]
