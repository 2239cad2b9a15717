"""Lifetime of a suction cup under a pull force: the paper's reduced leakage model (eqs 3-24).

The cup is pressed on to r_start with no pull force (this fixes the trapped gas), the pull force
F1 is applied at t = 0, and air leaks in through the critical constrictions until the contact
radius reaches r1 or the force balance loses its equilibrium (fold). Several forces may be given.

--reference-mode fixes every convention so results can be checked from outside: Appendix A
stiffness (x0 = r0, x1 = r1, d0 = 2 mm, d1 = 0, E = 4 MPa), no relaxation (E = 4 MPa also for
p/E), air at 293.15 K (eta = 1.81e-5 Pa s, m = 28.97 u), p_a = 1e5 Pa, rigid-cone geometry
(eqs 3-5), u_c from the table by log-log interpolation.

The critical gap u_c(p/E) comes from the calibrated surface pmma-1.89 (sandblasted PMMA, 1.89 um
rms: Persson theory, EMT) unless --surface, --psd, --line-scan or --uc-table names another, as in
`cupcheck example` and the scenes. --surface illustrative takes the ILLUSTRATIVE table shipped in
reduced/data (a power law through the paper's 0.68 um at p/E = 0.025; not a rough-contact result).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from validation.bridge.pipeline import DEFAULT_SURFACE
from validation.commands._cup import add_contact_arguments, add_cup_arguments, add_cup_law_arguments, cup_laws
from validation.commands._fem_route import FEM_KEYS, FEM_ONLY, run_fem_route
from validation.commands._reduced_options import ILLUSTRATIVE, build_uc, check_run_options, relaxation_law
from validation.commands._surface import add_surface_arguments
from validation.study_schema import add_flags

NAME = "lifetime"
HELP = "lifetime of a suction cup under pull forces (reduced leakage model, eqs 3-24)"
#: the study's fields `lifetime` spells as flags (`validation.study_schema.add_flags`); its other options
#: (--stiffness, --d0-mm, --nu of the surface's E*, the gas, the integration, --json, ...) are its own
KEYS = ("cup.preset", "cup.geometry", "cup.allow_unusual_design", "stiffness.route", "loads.r_start_mm",
        "cup.l0_mm", "cup.l1_mm", "contact.law", "contact.friction", *FEM_KEYS, "loads.F1_N", "material.E_MPa",
        "loads.kappa", "surface.uc_table", "surface.preset", "material.relaxation", "fluid.kind")


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_cup_arguments(p, "with --stiffness FILE, the curve's own design is used and an explicit "
                         "cup must agree with it")
    add_cup_law_arguments(p)
    fem = p.add_argument_group("fem route (--route fem)")
    add_contact_arguments(fem, "the paper's soap-cleaned PMMA is not frictionless, so give the law you mean")
    add_flags(fem, FEM_KEYS, helps={
        "stiffness.fidelity": "for --route fem: mesh level of the cup (default medium with --route fem: "
                              "lifetimes within 1 %% of the fine level's, ~11 s of CPU each; coarse is ~3x "
                              "faster and up to 5 %% off, see benchmarks/fem_route_mesh_study.md)"})
    add_flags(p, ("loads.F1_N",), helps={"loads.F1_N": "pull force(s) F1 in N, > 0 (default: 10)"},
              **{"--force": {"metavar": "F1_N"}})
    p.add_argument("--stiffness", default="appendix-a", metavar="appendix-a|FILE.csv",
                   help="stiffness force F0: the Appendix A formula, or a StiffnessCurve CSV "
                        "(columns u_mm,F0_N[,h_mm,r_c_mm,l_mm,V_mm3]; its JSON sidecar, if any, "
                        "names the cup design) (default: appendix-a)")
    p.add_argument("--suction-table", dest="suction_table", default=None, metavar="FILE.json",
                   help="for --route coupled: the FEM's (u, dp) table written by `cupcheck suction`")
    p.add_argument("--interface", default="linear", choices=("linear", "p_b", "p_a"),
                   help="for --route coupled: the gas pressure in the contact zone next to the seal, "
                        "rising linearly from p_b to p_a across it, or the bounds p_b, p_a (default: linear)")
    add_flags(p, ("material.E_MPa",), helps={
        "material.E_MPa": "Young's modulus in MPa for Appendix A and for p/E without relaxation (default: 4)"})
    p.add_argument("--d0-mm", dest="d0_mm", type=float, default=2.0,
                   help="Appendix A wall thickness at r0 in mm (d1 = 0) (default: 2)")
    add_flags(p, ("loads.kappa",), **{"--kappa": {"metavar": "KAPPA"}})
    src = p.add_mutually_exclusive_group()
    add_flags(src, ("surface.uc_table", "surface.preset"), helps={
        "surface.uc_table": "critical gap table, columns p_over_E,u_c_m (u_c in m; 0 = sealed) "
                            "(default: the surface pmma-1.89)",
        "surface.preset": f"calibrated preset (see `cupcheck uc --list-surfaces`); {DEFAULT_SURFACE} when no "
                          f"surface or table is given, and `{ILLUSTRATIVE}` the power-law u_c table of "
                          "reduced/data (not a rough-contact result)"},
        **{"--uc-table": {"metavar": "FILE.csv"}})
    add_surface_arguments(p, src, preset=False)
    p.add_argument("--uc-method", default="emt", choices=("emt", "critical-junction"),
                   help="with a surface: u_c route of Persson theory (default: emt, as in the paper)")
    p.add_argument("--gamma", type=float, default=0.45,
                   help="with a surface: Yang-Persson gamma [-] (default: 0.45)")
    p.add_argument("--a-c", dest="a_c", type=float, default=0.42,
                   help="with a surface: percolation threshold A/A0 [-] (default: 0.42)")
    p.add_argument("--nu", type=float, default=0.5,
                   help="with a surface: Poisson ratio of the cup for E* = E/(1-nu^2) [-] (default: 0.5, "
                        "the paper's rubber; `stiffness` defaults to 0.49 because its displacement "
                        "elements lock above 0.495)")
    add_flags(p, ("material.relaxation",), helps={
        "material.relaxation": "relaxation modulus E_eff(t): none, the default power law (4.4 MPa at 1 s, "
                               "1.8 MPa at 3e4 s), or a CSV with columns t_s,E_Pa (default: none)"},
        **{"--relaxation": {"type": str, "metavar": "none|default|FILE.csv"}})
    p.add_argument("--phi0-s", dest="phi0_s", type=float, default=None,
                   help="contact time of the stiffness measurement in s (default: l/rdot at r_start "
                        "and 0.12 mm/s plate speed, 13.0 s for cup A)")
    add_flags(p, ("fluid.kind",), helps={
        "fluid.kind": "what fills the cavity and leaks in: air (ideal gas, eqs 8, 19) or water "
                      "(incompressible, eq 24; p_b from the force balance, may be negative) (default: air)"})
    p.add_argument("--liquid-viscosity-Pa-s", dest="liquid_viscosity", type=float, default=1.002e-3,
                   help="viscosity of the liquid in Pa s for --fluid water "
                        "(default: 1.002e-3, water at 20 C)")
    p.add_argument("--cavitation-kPa", dest="cavitation_kPa", type=float, default=None,
                   help="for --fluid water: the pressure in kPa below which the liquid cavitates (a "
                        "vapour bubble at that pressure opens and the cup rises); water's vapour "
                        "pressure is 2.34 kPa at 20 C (default: none, the liquid sustains tension)")
    p.add_argument("--T-K", dest="T_K", type=float, default=293.15, help="temperature in K (default: 293.15)")
    p.add_argument("--p-a-Pa", dest="p_a_Pa", type=float, default=1e5,
                   help="ambient pressure in Pa (default: 1e5)")
    p.add_argument("--t-max-s", dest="t_max_s", type=float, default=1e12,
                   help="time horizon in s; still attached then = 'horizon' (default: 1e12)")
    p.add_argument("--rtol", type=float, default=1e-6,
                   help="relative tolerance of the time integration (default: 1e-6)")
    p.add_argument("--reference-mode", action="store_true",
                   help="the reference conventions above (Appendix A, E = 4 MPa, no relaxation, "
                        "cone geometry, air at 293.15 K, p_a = 1e5 Pa)")
    p.add_argument("--json", action="store_true",
                   help="print a JSON list, one object per force (force_N, lifetime_s [s, null if "
                        "infinite], reason, sealed, ballistic_share, ...)")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="write trajectory CSVs (one per force, units in the column names) and "
                        "summary.json to DIR, atomically")


@dataclass(frozen=True)
class LifetimeCase:
    """What the command line asks for: the model, the cup it was built for (`CupChoice`), where
    r, V, l come from (cup_laws) and the route's options for `validation.bridge.lifetimes.lifetimes`."""

    model: Any
    choice: Any
    cup_laws: str
    options: dict


def build_model(args: argparse.Namespace) -> LifetimeCase:
    """Validate the options and build the `LeakageModel` (cheap; raises ValueError on bad input).

    The cup comes from the stiffness curve's recorded design, else from --geometry / --cup
    (`validation.bridge.design`).
    """
    from reduced.appendix_a import appendix_a_curve
    from reduced.gas import Gas
    from reduced.lifetime import LeakageModel, reference_model
    from validation.guards import check_design, check_modulus, check_stiffness_curve
    from validation.bridge.lifetimes import lifetimes, route_options

    check_run_options(args)
    check_modulus(args.E_MPa, "--E-MPa")
    laws = cup_laws(args)
    options = route_options(args.route, args.cup_laws)
    curve, choice = _curve_and_cup(args, laws)
    check_design(choice.design.describe(), args.allow_unusual_design, source=choice.label)
    check_stiffness_curve(curve, 1e3 * choice.design.h1_m, f"--stiffness '{args.stiffness}'", args.E_MPa)
    cup = choice.cup
    uc = build_uc(args)
    if args.reference_mode:
        changed = [opt for opt, val, default in (
            ("--stiffness", args.stiffness, "appendix-a"), ("--E-MPa", args.E_MPa, 4.0),
            ("--d0-mm", args.d0_mm, 2.0), ("--relaxation", args.relaxation, "none"),
            ("--cup-laws", laws, "cone"), ("--route", args.route, "paper"), ("--T-K", args.T_K, 293.15),
            ("--p-a-Pa", args.p_a_Pa, 1e5), ("--phi0-s", args.phi0_s, None),
            ("--fluid", args.fluid, "air"), ("--cavitation-kPa", args.cavitation_kPa, None),
            ("--kappa", args.kappa, 1.0))
            if val != default]
        if changed:
            raise ValueError(f"--reference-mode: fixes {', '.join(changed)}; drop them")
        return LifetimeCase(reference_model(cup, uc), choice, laws, options)
    p_cav = args.cavitation_kPa
    if p_cav is not None and args.fluid != "water":
        raise ValueError("--cavitation-kPa: only with --fluid water")
    if p_cav is not None and not (math.isfinite(p_cav) and 0 <= 1e3 * p_cav < args.p_a_Pa):
        raise ValueError(f"--cavitation-kPa: must be in [0, p_a) = [0, {args.p_a_Pa / 1e3:g}) kPa, "
                         f"got {p_cav:g}")
    if curve is None:
        if not (math.isfinite(args.d0_mm) and args.d0_mm > 0):
            raise ValueError(f"--d0-mm: wall thickness must be > 0 mm, got {args.d0_mm:g}")
        curve = appendix_a_curve(cup, E_Pa=1e6 * args.E_MPa, d0_m=1e-3 * args.d0_mm)
    if not (math.isfinite(args.kappa) and args.kappa > 0):
        raise ValueError(f"kappa: stiffness scale factor must be > 0, got {args.kappa}")
    relax = relaxation_law(args.relaxation)
    gas = Gas(T_K=args.T_K)
    model = LeakageModel(cup=cup, stiffness=curve, u_c=uc, gas=gas, p_a_Pa=args.p_a_Pa,
                         E_Pa=1e6 * args.E_MPa, relaxation=relax, phi0_s=args.phi0_s, kappa=args.kappa,
                         fluid=args.fluid, liquid_viscosity_Pa_s=args.liquid_viscosity,
                         cavitation_pressure_Pa=None if p_cav is None else 1e3 * p_cav,
                         label=choice.label)
    with within_partial_curve(curve, args.stiffness):
        lifetimes(model, [], args.route, **options)   # builds the start state: checks geometry and curve range now
    return LifetimeCase(model, choice, laws, options)


@contextmanager
def within_partial_curve(curve: Any, path: str) -> Iterator[None]:
    """A partial curve (the converged part of a failed FEM path) is used within its range only: a
    state beyond it (the reduced model never extrapolates) is refused naming --stiffness."""
    from validation.bridge.pipeline import partial_note

    note = partial_note(getattr(curve, "provenance", {}))
    try:
        yield
    except ValueError as exc:
        if note is None:
            raise
        raise ValueError(f"--stiffness: '{path}' is {note}, and this lifetime needs a state beyond it: "
                         f"{exc}") from None


def _curve_and_cup(args: argparse.Namespace, laws: str):
    """(the stiffness curve or None for Appendix A, the `CupChoice`)."""
    from reduced.stiffness_curve import StiffnessCurve
    from validation.bridge.design import explicit_design, resolve_cup

    options = dict(cup=args.cup, geometry_file=args.geometry, r_start_mm=args.r_start_mm,
                   l0_mm=args.l0_mm, l1_mm=args.l1_mm)
    if args.stiffness == "appendix-a":
        if laws == "curve":
            raise ValueError(f"--{'route' if args.route == 'profile' else 'cup-laws'}: "
                             f"'{args.route if args.route == 'profile' else 'curve'}' needs an FEM "
                             f"stiffness curve (--stiffness FILE.csv with r_c_mm, V_mm3, l_mm)")
        return None, resolve_cup(None, **options)
    h1 = None if _has_h(args.stiffness) else explicit_design(args.cup, args.geometry).h1_m
    curve = StiffnessCurve.from_csv(args.stiffness, h1_m=h1)
    return curve, resolve_cup(curve, curve_label=f"'{args.stiffness}'", laws=laws, **options)


def _has_h(path: str) -> bool:
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"--stiffness: no such file '{path}'")
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ValueError(f"--stiffness: '{path}' is not a UTF-8 text file") from None
    for line in text.splitlines():
        if line.strip() and not line.startswith("#"):
            return "h_mm" in [c.strip() for c in line.split(",")]
    return False


def write_trajectories(results, out: Path, cup: dict) -> None:
    """One CSV per force (the cup's name first, units in the column names) and summary.json."""
    from validation.output import write_table

    for r in results:
        write_table(out / f"trajectory_F1_{r.force_N:g}N.csv", {"cup": cup["name"], **r.trajectory_columns()},
                    stage=f"lifetime at F1 = {r.force_N:g} N")
    (out / "summary.json").write_text(json.dumps(summaries(results, cup), indent=2, allow_nan=False) + "\n")


def summaries(results, cup: dict) -> list[dict]:
    """Per force the result's summary and the cup it was computed for."""
    return [{**r.summary(), "cup": cup} for r in results]


def run(args: argparse.Namespace) -> int:
    from validation.bridge.lifetimes import lifetimes
    from validation.bridge.pipeline import partial_note
    from validation.output import atomic_directory, terminal_progress

    from validation.output import check_file_names, check_outputs, command_inputs
    check_outputs(directories={"--out": args.out}, inputs=command_inputs(args))
    check_file_names({f"--force {f!r}": [f"trajectory_F1_{f:g}N.csv"] for f in args.force_N if args.out})
    if args.route == "fem":
        return run_fem_route(args)
    given = [option for option, name, default in FEM_ONLY if getattr(args, name) != default]
    if given:
        raise ValueError(f"{given[0]}: applies to --route fem only")
    if args.route == "coupled":
        from validation.commands._coupled import run_coupled
        return run_coupled(args)
    for option, value, default in (("--suction-table", args.suction_table, None),
                                   ("--interface", args.interface, "linear")):
        if value != default:
            raise ValueError(f"{option}: applies to --route coupled only")
    case = build_model(args)
    model, choice = case.model, case.choice
    cup = {**choice.describe(), "laws": case.cup_laws, "route": args.route}
    for note in choice.notes:
        print(f"note: {note}", file=sys.stderr)
    if args.surface == ILLUSTRATIVE and not args.json:
        print("note: using the ILLUSTRATIVE u_c table (reduced/data/uc_illustrative.csv)", file=sys.stderr)
    # a reference-mode lifetime takes milliseconds, a relaxed one ~0.1 s: report only long sweeps
    cost = len(args.force_N) * (1 if model.reference else 30)
    progress = terminal_progress("lifetime") if cost >= 100 else None

    note = partial_note(getattr(model.stiffness, "provenance", {}))
    if note is not None:
        print(f"note: --stiffness '{args.stiffness}' is {note}; used within that range", file=sys.stderr)

    def compute():
        with within_partial_curve(model.stiffness, args.stiffness):
            return lifetimes(model, args.force_N, args.route, progress=progress, t_max_s=args.t_max_s,
                             rtol=args.rtol, **case.options)

    if args.out:
        with atomic_directory(args.out) as tmp:
            results = compute()
            write_trajectories(results, tmp, cup)
    else:
        results = compute()
    if args.json:
        print(json.dumps(summaries(results, cup), indent=2))
    else:
        laws = "cone laws (3)-(5)" if case.cup_laws == "cone" else "the stiffness curve"
        seal = ("the curve's contact-pressure profiles" if args.route == "profile" else
                "one strip at eq (6)'s pressure" + (f" (l0, l1: {choice.l_source})" if case.cup_laws == "cone" else ""))
        print(f"cup: {choice.label} from the {choice.source}; r_start {cup['r_start_mm']:.4g} mm; "
              f"r, V from {laws}; route {args.route}: the leak crosses {seal}")
        print(f"{'F1_N':>8} {'lifetime_s':>12} {'reason':>11} {'ballistic':>9} {'r_end_mm':>8}")
        for r in results:
            life = f"{r.lifetime_s:.6g}" if math.isfinite(r.lifetime_s) else "inf"
            print(f"{r.force_N:8.4g} {life:>12} {r.reason:>11} {r.details['ballistic_share']:9.3f} "
                  f"{r.trajectory['r_mm'][-1]:8.3f}")
    return 0
