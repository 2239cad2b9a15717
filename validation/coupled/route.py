"""`cupcheck lifetime --route coupled`: the lifetimes from an FEM suction table (`cupcheck suction`)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: lifetime options that the coupled route replaces or does not model: (option, value, default)
_NOT_HERE = (("--stiffness", "stiffness", "appendix-a"), ("--fluid", "fluid", "air"),
             ("--cavitation-kPa", "cavitation_kPa", None), ("--cup-laws", "cup_laws", None),
             ("--d0-mm", "d0_mm", 2.0), ("--l0-mm", "l0_mm", None), ("--l1-mm", "l1_mm", None))


@dataclass(frozen=True)
class _TableDesign:
    """What `validation.design.resolve_cup` reads of a curve: the recorded design and h1."""

    design: dict[str, Any] | None
    h1_m: float


def coupled_model(args: argparse.Namespace):
    """(CoupledCavity, u_start [m], the `CupChoice`, the cup's description for the outputs) from
    the options; ValueError on bad input."""
    from reduced.coupled import CoupledCavity
    from reduced.gas import Gas
    from reduced.suction_table import SuctionTable
    from reduced.viscoelastic import measurement_contact_time
    from validation.commands.lifetime import build_uc, check_run_options
    from validation.design import resolve_cup

    if args.reference_mode:
        raise ValueError("--reference-mode: the reference conventions are the paper route's; "
                         "drop it with --route coupled")
    given = [opt for opt, name, default in _NOT_HERE if getattr(args, name) != default]
    if given:
        raise ValueError(f"--route: coupled takes F1, V, r and the contact profile from the suction "
                         f"table and does not model water; drop {', '.join(given)}")
    if args.suction_table is None:
        raise ValueError("--suction-table: --route coupled needs the FEM table of `cupcheck suction` (.json)")
    if not Path(args.suction_table).is_file():
        raise ValueError(f"--suction-table: no such file '{args.suction_table}'")
    check_run_options(args)
    relaxation = _relaxation(args)
    table = SuctionTable.from_json(args.suction_table)
    h1 = table.h1_m
    recorded = _TableDesign(table.provenance.get("geometry"), h1)
    choice = resolve_cup(recorded if recorded.design else None, cup=args.cup,
                         geometry_file=args.geometry, r_start_mm=args.r_start_mm,
                         curve_label=f"'{args.suction_table}'", laws="curve")
    cup = choice.cup
    u_start = (h1 if math.isfinite(h1) else cup.h1_m) - cup.h_start_m
    phi0 = None if relaxation is None else (
        args.phi0_s if args.phi0_s is not None else measurement_contact_time(cup))
    model = CoupledCavity(table, build_uc(args), Gas(T_K=args.T_K), args.p_a_Pa, kappa=args.kappa,
                          interface=args.interface, relaxation=relaxation, phi0_s=phi0)
    description = {**choice.describe(), "route": "coupled", "u_start_mm": 1e3 * u_start,
                   "interface": args.interface, "suction_table": str(args.suction_table),
                   **({} if relaxation is None else {"relaxation": relaxation.provenance, "phi0_s": phi0})}
    return model, u_start, choice, description


def _relaxation(args: argparse.Namespace):
    """The `RelaxationModulus` of --relaxation (none, default or a CSV), as the paper route reads
    it; --phi0-s checked here so that its error names the option."""
    from validation.commands.lifetime import relaxation_law

    if args.relaxation == "none":
        if args.phi0_s is not None:
            raise ValueError("--phi0-s: the measurement contact time applies with --relaxation only")
        return None
    if args.phi0_s is not None and not (math.isfinite(args.phi0_s) and args.phi0_s > 0):
        raise ValueError(f"--phi0-s: measurement contact time must be finite and > 0 s, got {args.phi0_s:g}")
    return relaxation_law(args.relaxation)


def run_coupled(args: argparse.Namespace) -> int:
    """The coupled route of `cupcheck lifetime` (its table, --json and --out as for the others)."""
    from validation.output import atomic_directory, write_table

    model, u_start, choice, cup = coupled_model(args)
    for note in choice.notes:
        print(f"note: {note}", file=sys.stderr)
    if args.out:
        with atomic_directory(args.out) as tmp:
            results = [_lifetime(model, F, u_start, args) for F in args.force_N]
            for r in results:
                write_table(tmp / f"trajectory_F1_{r.force_N:g}N.csv",
                            {"cup": cup["name"], **r.trajectory_columns()},
                            stage=f"lifetime at F1 = {r.force_N:g} N")
            (tmp / "summary.json").write_text(json.dumps([{**r.summary(), "cup": cup} for r in results],
                                                         indent=2, allow_nan=False) + "\n")
    else:
        results = [_lifetime(model, F, u_start, args) for F in args.force_N]
    if args.json:
        print(json.dumps([{**r.summary(), "cup": cup} for r in results], indent=2))
        return 0
    print(f"cup: {choice.label}; released at u = {1e3 * u_start:.4g} mm (r_start "
          f"{cup['r_start_mm']:.4g} mm by eq 3); route coupled: F1, V and the contact profile from "
          f"{args.suction_table}, interface gas {args.interface}{_relaxation_note(cup)}; largest "
          f"holdable force {model.largest_holdable_force(u_start):.4g} N")
    print(f"{'F1_N':>8} {'lifetime_s':>12} {'reason':>11} {'u_end_mm':>8} {'p_b_end_kPa':>11}")
    for r in results:
        life = f"{r.lifetime_s:.6g}" if math.isfinite(r.lifetime_s) else "inf"
        u_end = f"{1e3 * r.u_m[-1]:8.3f}" if r.u_m.size else f"{'-':>8}"
        pb = f"{r.p_b_Pa[-1] / 1e3:11.4g}" if r.dp_Pa.size else f"{'-':>11}"
        print(f"{r.force_N:8.4g} {life:>12} {r.reason:>11} {u_end} {pb}")
    return 0


def _lifetime(model, F1: float, u_start: float, args: argparse.Namespace):
    return model.lifetime(F1, u_start, t_max_s=args.t_max_s, rtol=args.rtol)


def _relaxation_note(cup: dict[str, Any]) -> str:
    if "relaxation" not in cup:
        return ""
    return f", relaxation {cup['relaxation']} (phi0 = {cup['phi0_s']:.4g} s)"
