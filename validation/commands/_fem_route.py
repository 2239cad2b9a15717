"""`cupcheck lifetime --route fem`: the cup pressed, sealed and held at F1 along its FEM equilibrium
branch (`validation.bridge.fem_route`), every option checked before the FEM runs; printed and
written as for the other routes, with this route's end state (u, p_b, seal radius)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from validation.commands._reduced_options import build_uc, check_run_options, refuse_other_options
from validation.study_schema import field_of

#: mesh level of the fem route when --fidelity is not given: the coarsest whose lifetimes are within
#: 1 % of the next finer level's (benchmarks/fem_route_mesh_study.md; one lifetime ~11 s of CPU, coarse ~4 s)
DEFAULT_FIDELITY = "medium"

#: lifetime options the fem route replaces or does not model: (option, attribute, default)
_NOT_HERE = (("--stiffness", "stiffness", "appendix-a"), ("--suction-table", "suction_table", None),
             ("--cavitation-kPa", "cavitation_kPa", None),
             ("--cup-laws", "cup_laws", None), ("--d0-mm", "d0_mm", 2.0), ("--l0-mm", "l0_mm", None),
             ("--l1-mm", "l1_mm", None), ("--kappa", "kappa", 1.0), ("--relaxation", "relaxation", "none"),
             ("--phi0-s", "phi0_s", None))

#: the study's fields `lifetime` spells as the fem route's own flags (`validation.study_schema`), besides the contact
FEM_KEYS = ("stiffness.fidelity", "loads.press_u_mm", "loads.press_force_N", "stiffness.du_mm")
#: options of the fem route only: (option, attribute, default)
FEM_ONLY = tuple((f.flag, f.dest, f.default_in("cli"))
                 for f in map(field_of, ("contact.law", "contact.friction", *FEM_KEYS)))

#: the study's fields that say how the cup is pressed before it is sealed (one of them)
_PRESSES = ("loads.r_start_mm", "loads.press_u_mm", "loads.press_force_N")


def fem_route_case(args: argparse.Namespace) -> tuple[Any, dict[str, Any], Any, dict[str, Any]]:
    """(the `LeakageModel`, the route's options, the `CupChoice`, the cup's description), every
    option checked (ValueError naming it) and no FEM solved."""
    from reduced.gas import Gas
    from reduced.lifetime import LeakageModel
    from validation.bridge.design import resolve_cup
    from validation.bridge.fem_route import FemCup, Press, register
    from validation.bridge.study import Loads
    from validation.commands._cup import contact_choice, load_cup_design
    from validation.guards import check_design, check_modulus
    from validation.study_schema import check_route, parse, values_from_args

    refuse_other_options(args, "fem", _NOT_HERE, "computes the cup's mechanics, volume and contact profile "
                         "in the FEM (elastic wall, a cavity of gas or of water without cavitation)")
    check_run_options(args)
    E_MPa = check_modulus(args.E_MPa, "--E-MPa")
    if not (math.isfinite(args.du_mm) and args.du_mm > 0):
        raise ValueError(f"--du-mm: the plate step along the branch must be > 0 mm, got {args.du_mm:g}")
    presses = values_from_args(args, _PRESSES)
    for key in ("loads.press_u_mm", "loads.press_force_N"):
        if presses[key] is not None:
            parse(field_of(key), presses[key], "cli")
    check_route({**presses, "stiffness.route": "fem"}, [k for k, v in presses.items() if v is not None], "cli")
    how = Loads(press_u_mm=presses["loads.press_u_mm"], press_force_N=presses["loads.press_force_N"]).press()
    press = None if how is None else Press(*how)
    design = load_cup_design(args)
    contact = contact_choice(args, design)
    check_design(design.geometry.describe(), args.allow_unusual_design, source=design.geometry.name)
    choice = resolve_cup(None, cup=args.cup, geometry_file=args.geometry, r_start_mm=args.r_start_mm,
                         laws="curve")
    geometry = design.geometry if args.geometry is not None else (args.cup or "A")
    fidelity = args.fidelity or DEFAULT_FIDELITY
    fem_cup = FemCup(geometry, fidelity, E_Pa=1e6 * E_MPa, contact=contact.contact)
    model = LeakageModel(cup=choice.cup, u_c=build_uc(args), gas=Gas(T_K=args.T_K), p_a_Pa=args.p_a_Pa,
                         E_Pa=1e6 * E_MPa, interface=args.interface, label=choice.label,
                         fluid=args.fluid, liquid_viscosity_Pa_s=args.liquid_viscosity)
    route = register()
    options = {**route.options, "cup": fem_cup, "press": press, "du_m": 1e-3 * args.du_mm}
    route.check(model, options)
    cup = {**choice.describe(), "route": "fem", "fem_cup": fem_cup.describe(), "contact": contact.describe(),
           **({"press": {"kind": press.kind, "value": press.value}} if press else {}), "du_mm": args.du_mm,
           "interface": args.interface}
    return model, options, choice, cup


def run_fem_route(args: argparse.Namespace) -> int:
    """The fem route of `cupcheck lifetime` (its table, --json and --out as for the others)."""
    from reduced.lifetime import largest_holdable_force, solve_lifetime
    from validation.bridge.fem_route import register
    from validation.bridge.lifetimes import Lifetimes
    from validation.output import atomic_directory, terminal_progress, write_table

    model, options, choice, cup = fem_route_case(args)
    for note in choice.notes:
        print(f"note: {note}", file=sys.stderr)
    # one status line per branch state on a terminal; elsewhere a plain line every ~10 %
    progress = terminal_progress("lifetime --route fem")
    route = register()

    def compute() -> Lifetimes:
        route.seal(model, options, progress)                   # pressing (once per cup and press)
        if progress:
            progress(0.05, "sealed; the largest holdable force (pull at fixed N0)")
        largest = largest_holdable_force(model, "fem", **options)
        results = []
        for force in args.force_N:
            results.append(solve_lifetime(model, force, route="fem", t_max_s=args.t_max_s, rtol=args.rtol,
                                          progress=progress, **options))
        return Lifetimes("fem", tuple(results), largest)

    if args.out:
        with atomic_directory(args.out) as tmp:
            results = compute()
            for r in results:
                write_table(tmp / f"trajectory_F1_{r.force_N:g}N.csv",
                            {"cup": cup["name"], **_trajectory(r)}, stage=f"lifetime at F1 = {r.force_N:g} N")
            (tmp / "summary.json").write_text(json.dumps(_summaries(results, cup), indent=2,
                                                         allow_nan=False) + "\n")
    else:
        results = compute()
    if args.json:
        print(json.dumps(_summaries(results, cup), indent=2))
        return 0
    fem = cup["fem_cup"]
    s0 = results[0].details
    print(f"cup: {choice.label}; {_pressed(args, cup, s0)} and sealed (u = "
          f"{s0['u_sealed_mm']:.4g} mm, {_content(s0)}); route fem: {fem['fidelity']} mesh, E "
          f"{fem['E_Pa'] / 1e6:g} MPa, nu {fem['nu']:g}, contact {_law(cup['contact'])} "
          f"({cup['contact']['source']}), plate step {cup['du_mm']:g} mm; largest holdable force "
          f"{'at least ' if 'largest_force_lower_bound' in s0 else ''}{results.largest_force_N:.4g} N")
    print(f"{'F1_N':>8} {'lifetime_s':>12} {'reason':>11} {'u_end_mm':>8} {'p_b_end_kPa':>11} {'seal_r_mm':>9}")
    for r in results:
        life = f"{r.lifetime_s:.6g}" if math.isfinite(r.lifetime_s) else "inf"
        d = r.details
        u_end = f"{d['u_final_mm']:8.3f}" if "u_final_mm" in d else f"{'-':>8}"
        pb = f"{d['p_b_final_Pa'] / 1e3:11.4g}" if "p_b_final_Pa" in d else f"{'-':>11}"
        seal = f"{d['seal_r_final_mm']:9.3f}" if "seal_r_final_mm" in d else f"{'-':>9}"
        print(f"{r.force_N:8.4g} {life:>12} {r.reason:>11} {u_end} {pb} {seal}")
    return 0


def _trajectory(r) -> dict[str, Any]:
    """The trajectory's columns, time first (an over-force result has none: one row at t = 0)."""
    tr = r.trajectory_columns()
    if not tr:
        d = r.details
        content = {"V_w_mm3": [d["V_w0_mm3"]]} if "V_w0_mm3" in d else {"N": [d["N0"]]}
        return {"t_s": [0.0], **content, "u_mm": [d["u_sealed_mm"]], "seal_r_mm": [d["seal_r_sealed_mm"]]}
    return {"t_s": tr["t_s"], **{k: v for k, v in tr.items() if k != "t_s"}}


def _summaries(results, cup: dict[str, Any]) -> list[dict]:
    return [{**r.summary(), "largest_force_N": results.largest_force_N, "cup": cup} for r in results]


def _pressed(args: argparse.Namespace, cup: dict[str, Any], sealed: dict[str, Any]) -> str:
    """How the cup was pressed, as the command line asked (a press by u or force: the r_c it reached)."""
    if args.press_u_mm is None and args.press_force_N is None:
        return f"pressed to r_start {cup['r_start_mm']:.4g} mm"
    how = f"to u = {args.press_u_mm:g} mm" if args.press_u_mm is not None else f"with {args.press_force_N:g} N"
    return f"pressed {how} (r_c {sealed['r_start_mm']:.4g} mm)"


def _content(sealed: dict[str, Any]) -> str:
    """What the sealed cavity holds: the water volume, or the gas's molecules."""
    if "V_w0_mm3" in sealed:
        return f"water V_w0 = {sealed['V_w0_mm3']:.4g} mm^3"
    return f"N0 = {sealed['N0']:.4e}"


def _law(contact: dict[str, Any]) -> str:
    return f"coulomb mu = {contact['friction']:g}" if contact["law"] == "coulomb" else contact["law"]
