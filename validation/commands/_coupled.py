"""`cupcheck lifetime --route coupled`: the options read into `validation.bridge.coupled.route.CoupledOptions`,
the lifetimes from the FEM suction table, printed and written as for the other routes."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

from validation.commands._reduced_options import (build_uc, check_run_options, refuse_other_options,
                                                   relaxation_law)

#: lifetime options that the coupled route replaces or does not model: (option, value, default)
_NOT_HERE = (("--stiffness", "stiffness", "appendix-a"), ("--fluid", "fluid", "air"),
             ("--cavitation-kPa", "cavitation_kPa", None), ("--cup-laws", "cup_laws", None),
             ("--d0-mm", "d0_mm", 2.0), ("--l0-mm", "l0_mm", None), ("--l1-mm", "l1_mm", None))


def coupled_options(args: argparse.Namespace):
    """The typed options of the command line (every check; ValueError naming the option)."""
    from validation.bridge.coupled.route import CoupledOptions

    refuse_other_options(args, "coupled", _NOT_HERE, "takes F1, V, r and the contact profile from the "
                         "suction table and does not model water")
    if args.suction_table is None:
        raise ValueError("--suction-table: --route coupled needs the FEM table of `cupcheck suction` (.json)")
    if not Path(args.suction_table).is_file():
        raise ValueError(f"--suction-table: no such file '{args.suction_table}'")
    check_run_options(args)
    relaxation = _relaxation(args)
    return CoupledOptions(suction_table=Path(args.suction_table), cup=args.cup,
                          geometry_file=args.geometry, r_start_mm=args.r_start_mm, interface=args.interface,
                          kappa=args.kappa, T_K=args.T_K, p_a_Pa=args.p_a_Pa, relaxation=relaxation,
                          phi0_s=args.phi0_s)


def _relaxation(args: argparse.Namespace):
    """The `RelaxationModulus` of --relaxation (none, default or a CSV), as the paper route reads
    it; --phi0-s checked here so that its error names the option."""
    if args.relaxation == "none":
        if args.phi0_s is not None:
            raise ValueError("--phi0-s: the measurement contact time applies with --relaxation only")
        return None
    if args.phi0_s is not None and not (math.isfinite(args.phi0_s) and args.phi0_s > 0):
        raise ValueError(f"--phi0-s: measurement contact time must be finite and > 0 s, got {args.phi0_s:g}")
    return relaxation_law(args.relaxation)


def run_coupled(args: argparse.Namespace) -> int:
    """The coupled route of `cupcheck lifetime` (its table, --json and --out as for the others)."""
    from validation.bridge.coupled.route import coupled_model
    from validation.bridge.lifetimes import lifetimes
    from validation.output import atomic_directory, write_table

    options = coupled_options(args)
    model, choice, cup = coupled_model(options, build_uc(args))
    for note in choice.notes:
        print(f"note: {note}", file=sys.stderr)
    lifetimes(model, [], "coupled")        # builds the cavity: a table or u_c that does not fit is refused now

    def compute():
        return lifetimes(model, args.force_N, "coupled", t_max_s=args.t_max_s, rtol=args.rtol)

    if args.out:
        with atomic_directory(args.out) as tmp:
            results = compute()
            for r in results:
                write_table(tmp / f"trajectory_F1_{r.force_N:g}N.csv",
                            {"cup": cup["name"], **r.trajectory_columns()},
                            stage=f"lifetime at F1 = {r.force_N:g} N")
            (tmp / "summary.json").write_text(json.dumps([{**r.summary(), "cup": cup} for r in results],
                                                         indent=2, allow_nan=False) + "\n")
    else:
        results = compute()
    if args.json:
        print(json.dumps([{**r.summary(), "cup": cup} for r in results], indent=2))
        return 0
    print(f"cup: {choice.label}; released at u = {cup['u_start_mm']:.4g} mm (r_start "
          f"{cup['r_start_mm']:.4g} mm by eq 3); route coupled: F1, V and the contact profile from "
          f"{args.suction_table}, interface gas {args.interface}{_relaxation_note(cup)}; largest "
          f"holdable force {results.largest_force_N:.4g} N")
    print(f"{'F1_N':>8} {'lifetime_s':>12} {'reason':>11} {'u_end_mm':>8} {'p_b_end_kPa':>11}")
    for r in results:
        life = f"{r.lifetime_s:.6g}" if math.isfinite(r.lifetime_s) else "inf"
        u_end, pb = r.details["u_final_mm"], r.details["p_b_final_Pa"]
        u_end = f"{u_end:8.3f}" if u_end is not None else f"{'-':>8}"
        pb = f"{pb / 1e3:11.4g}" if pb is not None else f"{'-':>11}"
        print(f"{r.force_N:8.4g} {life:>12} {r.reason:>11} {u_end} {pb}")
    return 0


def _relaxation_note(cup: dict[str, Any]) -> str:
    if "relaxation" not in cup:
        return ""
    return f", relaxation {cup['relaxation']} (phi0 = {cup['phi0_s']:.4g} s)"
