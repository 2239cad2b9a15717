"""`cupcheck example`'s inputs that come from files: a stiffness curve of `cupcheck stiffness`
(--stiffness, whose design, contact law, mesh level and material become the example's) and the
coupled route's suction table (--suction-table, which must be of the same design and law)."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fem.interface import ContactChoice

__all__ = ["curve_inputs", "check_suction_table"]


def curve_inputs(args: argparse.Namespace) -> tuple[Any, ContactChoice, dict[str, Any]]:
    """(the FEM geometry, the contact law, the Study's fields) of a --stiffness curve: the design,
    law, mesh level and material its sidecar records. An option that contradicts them, or a curve
    that names no FEM design or law, is refused (ValueError naming the option)."""
    from fem.design_file import geometry_from_mapping
    from fem.interface import ContactChoice, ContactLaw
    from reduced.stiffness_curve import StiffnessCurve
    from validation.bridge.design import preset_design, resolve_cup, shape_of
    from validation.bridge.study import CupDesign, Material

    path = Path(args.stiffness)
    if not path.is_file():
        raise ValueError(f"--stiffness: no such file '{path}'")
    curve = StiffnessCurve.from_csv(path)
    shape, law, prov = curve.design, curve.contact, curve.provenance
    if shape is None or law is None or not isinstance(prov.get("material"), dict):
        raise ValueError(f"--stiffness: '{path.name}' records no FEM design, contact law or material (a measured "
                         f"or Appendix A curve); give --cup or --geometry and the example computes the FEM curve")
    label = f"the stiffness curve '{path.name}'"
    resolve_cup(curve, cup=args.cup, geometry_file=args.geometry, curve_label=label, laws="curve")
    was = law.law + (f" mu = {law.friction:g}" if law.law == "coulomb" else "")
    if args.contact is not None and args.contact != law.law:
        raise ValueError(f"--contact: {label} was computed with {was} contact; drop --contact {args.contact} "
                         f"(the curve's law is used) or derive a {args.contact} curve")
    if args.friction is not None and (law.law != "coulomb" or args.friction != law.friction):
        raise ValueError(f"--friction: {label} was computed with {was} contact; drop --friction")
    fidelity = prov.get("fidelity")
    if args.u_max_mm is not None:
        raise ValueError(f"--u-max-mm: {label} ends where its FEM run ended; drop --u-max-mm or derive a curve "
                         f"with `cupcheck stiffness --u-max-mm`")
    if args.fidelity is not None and fidelity is not None and args.fidelity != fidelity:
        raise ValueError(f"--fidelity: {label} was computed at the {fidelity} level; drop --fidelity "
                         f"{args.fidelity} or derive a curve at that level")
    args.fidelity = args.fidelity or fidelity
    preset = next((name for name in ("A", "B") if shape.same_cup(preset_design(name))), None)
    record = prov["geometry"]                           # the wall as written, its thickness profile included
    data = {k: record[k] for k in ("name", "r0_mm", "r1_mm", "alpha_deg", "thickness_convention") if k in record}
    thickness = record.get("thickness_profile", {})
    if thickness.get("kind") in ("linear", "table"):
        data["thickness"] = {"r_mm": thickness["r_mm"], "d_mm": thickness["d_mm"]}
    geometry = geometry_from_mapping(data, source=path.name)
    if not shape_of(geometry).same_cup(shape):
        raise ValueError(f"--stiffness: {label} records a wall this example cannot rebuild; give --geometry")
    contact = ContactChoice(ContactLaw(law.law, law.friction),
                            f"stiffness curve {path.name}" + (f", from its {law.source}" if law.source else ""))
    material = Material(E_MPa=prov["material"]["E_Pa"] / 1e6, nu=prov["material"]["nu"])
    design = CupDesign(preset=preset) if preset else CupDesign(preset=args.cup or "A", geometry=geometry)
    return geometry, contact, {"design": replace(design, l0_mm=args.l0_mm, l1_mm=args.l1_mm),
                               "material": material, "stiffness_file": str(path)}


def check_suction_table(args: argparse.Namespace, geometry, contact: ContactChoice) -> None:
    """--suction-table: only with the coupled route, an existing table of this very design."""
    if args.suction_table is None:
        return
    if args.route != "coupled":
        raise ValueError("--suction-table: applies to --route coupled only")
    from reduced.suction_table import SuctionTable
    if not Path(args.suction_table).is_file():
        raise ValueError(f"--suction-table: no such file '{args.suction_table}'")
    prov = SuctionTable.from_json(args.suction_table).provenance
    if prov.get("geometry") != geometry.describe():
        raise ValueError(f"--suction-table: '{args.suction_table}' was built for another design than "
                         f"{geometry.name}; build it with `cupcheck suction` on the same --cup/--geometry")
    law = contact.contact
    built = (prov.get("contact"), float(prov.get("friction", 0.0)))
    if built != (law.law, law.friction):
        raise ValueError(f"--suction-table: '{args.suction_table}' was built with {built[0]} contact"
                         f"{f' mu = {built[1]:g}' if built[0] == 'coulomb' else ''}, the example runs "
                         f"{law.label()}; give the same --contact (and --friction)")
