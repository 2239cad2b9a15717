"""The main job, end to end: cup A's FEM stiffness -> the reduced model on a calibrated rough surface ->
the lifetime against the pull force F1 = 5, 10, ..., 80 N.

1. FEM (fem.cup.compress_cup): cup A of Table 1 / Sec. 5.5 (alpha 33 deg, wall 2.5 -> 0.3 mm at
   r = 5 -> 20 mm), compressible neo-Hookean E = 4 MPa, nu = 0.49, pressed onto the plane to 0.9 h1
   at the default mesh level (medium), frictionless contact by default (the paper's soap-lubricated
   measurements; --contact sticking is Appendix A's no-slip bound, --contact coulomb --friction MU
   lies between; a --geometry file's [contact] table sets the law unless --contact is given).
2. Rough contact: u_c(p/E) of the calibrated sandblasted PMMA, 1.89 um rms (`pmma-1.89`, Persson
   theory, EMT, nu = 0.5), the surface of the paper's Figs. for cup A.
3. Reduced model (Sec. 3-4) in reference conventions (no relaxation, E = 4 MPa in p/E, air at
   293.15 K, p_a = 1e5 Pa), by the chosen route:
   - profile (the default, as in the main job): F0, r_c, V from the FEM curve, the leak through
     its contact-pressure profiles;
   - paper: F0(h) from step 1, r, V, l from the cone laws (3)-(5) with Table 1's l0, l1
     (--cup-laws curve takes them from the FEM instead), the leak through eq (6)'s uniform strip;
   - coupled: the FEM cup under the cavity's suction on a (u, dp) grid (`cupcheck suction`,
     built here and cached in --cache-dir, or read from --suction-table): F1, V and the profile of
     every state from the FEM, replacing eqs (3)-(7) and beta (`reduced.coupled`). Building the
     table takes ~3 min (coarse) to ~8 min (medium) once per design and law.
   - fem: the cup's whole life in the FEM (`validation.bridge.fem_route`): pressed to r_start (or
     --press-u-mm, --press-force-N) with the gas escaping, sealed, held at F1 along its equilibrium
     branch while the gas leaks in through each state's own profile (~10-20 s per force, coarse);
     with --fluid water the cavity holds incompressible water that flows in by eq (24) (~10 s per
     force, coarse; no cavitation: the water may go into tension).
   --fluid water fills the cavity with water on the paper, profile and fem routes (eq 24).
   Another design (--geometry FILE) runs the same chain on its own geometry (`validation.bridge.design`).
   A curve of `cupcheck stiffness` (--stiffness CURVE.csv) replaces step 1: its design, contact law,
   mesh level and material are the example's; a --cup, --geometry, --contact, --friction or
   --fidelity that contradicts the curve is refused.

Writes to DIR, atomically:

  lifetime_vs_force.csv   cup, route, contact, mesh, surface, force_N, lifetime_s, reason, then
                          ballistic_share, r_final_mm (paper, profile) or u_final_mm (coupled), and
                          p_b_final_Pa
  lifetime_vs_force.png   lifetime against F1 (FEM-fed, and Appendix A-fed for comparison), F0(u)
  lifetime_vs_force_data.csv  what the figure draws, point by point (series, quantities, x, y)
  stiffness_fem.csv       the FEM stiffness curve u_mm,h_mm,F0_N,r_c_mm,l_mm,V_mm3 (+ .json sidecar)
  suction_table.json      coupled route: the FEM suction table the lifetimes used
  trajectory_F1_<F>N.csv  fem route: each force's FEM states (t, N or the water volume V_w, p_b, u,
                          plate force, V, r_c, seal radius, r_out, leak rate or water inflow)
  manifest.json           the files and the study (`validation.bridge.study.Study`) they were computed for

An FEM path that fails after some converged steps (before --u-max-mm, default 0.9 h1) keeps them,
as in `cupcheck stiffness`: the curve is its converged part, flagged partial (its sidecar, a
curve_partial_to_u_mm column, the manifest's "partial"); a force whose lifetime needs a state beyond
it is refused (reason beyond_partial_curve), the others computed; one line names the --u-max-mm
that runs, the record goes to DIR.failure.json, and the exit status is 3.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from validation.bridge.cache import user_cache_dir
from validation.commands._cup import (add_contact_arguments, add_cup_arguments, add_cup_law_arguments,
                                      contact_choice, cup_laws, load_cup_design)
from validation.commands._example_inputs import check_suction_table, curve_inputs
from validation.study_schema import add_flags, check_route, field_of, parse, values_from_args

if TYPE_CHECKING:
    from fem.interface import ContactChoice
    from validation.bridge.study import Study

NAME = "example"
HELP = "main job: cup A FEM stiffness -> lifetime against pull force on pmma-1.89 (CSV and PNG)"

FORCES_N = tuple(float(f) for f in range(5, 85, 5))
#: the study's fields `example` spells as flags (`validation.study_schema`; contact: `contact_choice`)
KEYS = ("cup.preset", "cup.geometry", "cup.allow_unusual_design", "cup.l0_mm", "cup.l1_mm", "stiffness.route",
        "loads.r_start_mm", "stiffness.fidelity", "stiffness.u_max_mm", "surface.preset", "surface.uc_table",
        "loads.press_u_mm", "loads.press_force_N", "stiffness.du_mm", "fluid.kind")
#: exit status of a run whose FEM curve is the converged part of a failed path (as `cupcheck stiffness`)
PARTIAL_EXIT = 3


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (written atomically)")
    g = add_cup_arguments(p, "the FEM runs on it and the lifetimes use it")
    g.add_argument("--stiffness", default=None, metavar="CURVE.csv",
                   help="a stiffness curve of `cupcheck stiffness` (with its .json sidecar) instead of the "
                        "FEM run: its design, contact law, mesh level and material are used; an option "
                        "that contradicts them is refused")
    add_cup_law_arguments(p, default_route="profile")
    add_contact_arguments(p.add_argument_group("FEM contact"),
                          "as in the paper: its F0 was measured on soap-lubricated glass and its "
                          "lifetimes on soap-cleaned surfaces, Sec. 5.3-5.5; sticking is Appendix A's "
                          "no-slip bound, whose contact-pressure profile is singular at the stick "
                          "edges and not mesh-converged")
    add_flags(p, ("stiffness.fidelity", "stiffness.u_max_mm"), helps={
        "stiffness.fidelity": "FEM mesh level (default: medium, F0 within 1 %% of the converged curve; "
                              "coarse ~2 %%, 4x faster; see `cupcheck validate` for the errors)",
        "stiffness.u_max_mm": "the FEM curve's largest plate displacement u [mm], in (0, h1] (default: 0.9 h1); "
                              "a path that fails before it keeps its converged part (exit status 3)"})
    c = p.add_argument_group("coupled route")
    c.add_argument("--suction-table", dest="suction_table", default=None, metavar="FILE.json",
                   help="the design's table from `cupcheck suction` (default: built at --fidelity "
                        "with --contact and cached)")
    c.add_argument("--cache-dir", type=Path, default=user_cache_dir("suction"), metavar="DIR",
                   help="where built suction tables are kept (default: %(default)s, the user's cache; "
                        "$CUPCHECK_CACHE_DIR moves it)")
    c.add_argument("--no-cache", action="store_true", help="build the suction table afresh, keep nothing")
    add_flags(p.add_argument_group("fem route"), ("loads.press_u_mm", "loads.press_force_N", "stiffness.du_mm"))
    add_flags(p, ("fluid.kind",))
    add_flags(p.add_mutually_exclusive_group(), ("surface.preset", "surface.uc_table"), helps={
        "surface.preset": "calibrated surface preset for u_c(p/E) (default: pmma-1.89)",
        "surface.uc_table": "critical gap table instead, columns p_over_E,u_c_m (u_c in m)"},
        **{"--uc-table": {"metavar": "FILE.csv"}})


def _inputs(args: argparse.Namespace, geometry=None):
    """Every check before the solve: (the FEM geometry, its contact law (`contact_choice`), the
    u_c table's label); `geometry`: the design of a --stiffness curve (its law is checked there)."""
    import os

    from validation.guards import check_design, check_uc_table

    from validation.study_schema import check_u_max

    contact = None
    if geometry is None:
        design = load_cup_design(args)
        contact = contact_choice(args, design)
        geometry = design.geometry
    check_design(geometry.describe(), args.allow_unusual_design, source=geometry.name)
    check_u_max(args.u_max_mm, geometry, "cli")
    if args.uc_table is not None:
        if not os.path.isfile(args.uc_table):
            raise ValueError(f"uc-table: no such file {args.uc_table!r}")
        from reduced.critical_gap import UcTable
        table = UcTable.from_csv(args.uc_table)
        check_uc_table(table.p_over_E, table.u_c_m, "uc-table: u_c_m")
        return geometry, contact, Path(args.uc_table).name
    from validation.bridge.pipeline import DEFAULT_SURFACE, surface_uc_table
    name = args.surface or DEFAULT_SURFACE
    surface_uc_table(name)                 # an unknown preset is refused before the FEM
    return geometry, contact, name


def write_table(results, path: Path, cup: str, study: Study, partial: dict[str, Any] | None = None) -> None:
    """The lifetimes, one row per force: the cup, what they were computed for (`Study.record`), the
    outcome; on a partial curve (`Products.partial`) a refused force's row has the reason
    beyond_partial_curve and blank values, and every row says where the curve ends."""
    from validation.output import write_table as write_csv

    route = study.route
    refused = {r["force_N"] for r in (partial or {}).get("refused", [])}
    s = {r.force_N: r.summary() for r in results}
    forces = [f for f in study.loads.forces_N if f in s or f in refused]
    rows = [s.get(f, {"lifetime_s": "", "reason": "beyond_partial_curve"}) for f in forces]
    own = {"coupled": ("u_final_mm",), "fem": ("u_final_mm", "seal_r_final_mm")}.get(
        route, ("ballistic_share", "r_final_mm"))
    largest = {"largest_force_N": results.largest_force_N} if route == "fem" else {}
    record = {k: v for k, v in study.record().items() if k not in ("design", "route")}
    ends = {"curve_partial_to_u_mm": partial["u_max_mm_that_runs"]} if partial else {}
    write_csv(path, {"cup": cup, "route": route, **record, "force_N": forces,
                     "lifetime_s": [x["lifetime_s"] if x["lifetime_s"] is not None else math.inf for x in rows],
                     "reason": [x["reason"] for x in rows], **largest,
                     **{key: [_blank(x.get(key)) for x in rows] for key in (*own, "p_b_final_Pa")}, **ends},
              stage="example lifetimes")


def _write_trajectories(results, tmp: Path, cup: str) -> None:
    """The fem route's FEM states of each force, one CSV per force (none where the cup let go at once)."""
    from validation.output import write_table as write_csv

    for r in results:
        columns = r.trajectory_columns()
        if columns:
            write_csv(tmp / f"trajectory_F1_{r.force_N:g}N.csv",
                      {"cup": cup, "t_s": columns["t_s"], **{k: v for k, v in columns.items() if k != "t_s"}},
                      stage=f"example trajectory at F1 = {r.force_N:g} N")


def _blank(value):
    """A final state's value, or an empty field where the cup held no state (over_force)."""
    return "" if value is None else value


def study_of(args: argparse.Namespace, contact: ContactChoice) -> Study:
    """The main job as a `validation.bridge.study.Study`: the study's fields as the flags give them
    (`KEYS`; E = 4 MPa, nu = 0.49, `contact`), at F1 = 5, 10, ..., 80 N."""
    from validation.study_schema import study_from_values

    law = contact.contact
    values = {k: v for k, v in values_from_args(args, KEYS).items() if v is not None}
    if args.geometry is not None:
        values["cup.geometry"] = str(args.geometry)
    if args.uc_table is not None:                       # the table instead of the default preset
        values["surface.preset"] = None
    values.update({"contact.law": law.law, "contact.friction": law.friction if law.law == "coulomb" else None,
                   "loads.F1_N": FORCES_N})
    return study_from_values(values, contact_source=contact.source, stiffness="fem", cup_laws=args.cup_laws,
                             refine=4, suction_table=args.suction_table)


def check_fields(args: argparse.Namespace) -> None:
    """The study's numbers as the flags give them (`validation.study_schema.parse`: sign and shared
    guard, named by flag) and the rules between the route and the other fields (`check_route`)."""
    values = values_from_args(args, KEYS)
    defaults = {k: field_of(k).default_in("cli") for k in KEYS}
    for key, value in values.items():
        if field_of(key).type == "number" and value is not None:
            parse(field_of(key), value, "cli")
    given = {k for k, v in values.items() if v is not None and v != defaults[k]}
    check_route(values, given, "cli")


def _steps(response, curve) -> Any:
    """The FEM path's load steps: the run's, or those a given curve's sidecar records."""
    if response is not None:
        return response.stats.steps
    return curve.provenance.get("solver", {}).get("steps", len(curve.u_m) - 1)


def plot(series: dict, curve, cup, path: Path, title: str, table: Path | None = None) -> None:
    """Lifetime against F1 per series and the FEM's F0(u) beside Appendix A's, in the toolkit's
    style; `title` names the design, contact law, mesh level, route and surface; `table`: what
    is drawn, point by point (`validation.scenes.figures.figure_table`)."""
    import matplotlib.pyplot as plt

    from reduced.appendix_a import appendix_a_force
    from validation.style import COLUMN_WIDTH_IN, cupcheck_style, log_axis, save_figure

    with cupcheck_style():
        fig, ax = plt.subplots(1, 2, figsize=(2 * COLUMN_WIDTH_IN, 2.6))
        for (label, res), style in zip(series.items(), ("o-", "s--", "^:")):
            pts = [(r.force_N, r.lifetime_s) for r in res if math.isfinite(r.lifetime_s) and r.lifetime_s > 0]
            if pts:
                ax[0].plot(*zip(*pts), style, label=label)
        log_axis(ax[0], "y")
        ax[0].set(xlabel="pull force $F_1$ (N)", ylabel="lifetime (s)")
        fig.suptitle(title, fontsize=7)
        ax[0].legend(fontsize=6)
        u = curve.u_m
        ax[1].plot(1e3 * u, curve.F0_N, label="FEM")
        ax[1].plot(1e3 * u, appendix_a_force(u, cup.alpha_deg, 4e6, 2e-3, cup.r0_m, cup.r1_m), "--",
                   label="Appendix A")
        ax[1].set(xlabel="plate displacement u (mm)", ylabel="stiffness force $F_0$ (N)")
        ax[1].legend(fontsize=6)
        if table is not None:
            from validation.scenes.figures import write_figure_table
            write_figure_table(fig, table, title)
        save_figure(fig, path)


def run(args: argparse.Namespace) -> int:
    from validation.bridge import handoff
    from validation.output import atomic_directory, terminal_progress
    from validation.bridge.products import Products

    from fem.mesh import DEFAULT_FIDELITY

    t0 = time.perf_counter()
    from validation.output import check_outputs, command_inputs
    check_outputs(directories={"--out": args.out}, stores={"--cache-dir": args.cache_dir}, inputs=command_inputs(args))
    given = curve_study = None
    if args.stiffness is not None:
        given = curve_inputs(args)                    # the curve's design, law, level, material
        geometry, contact, curve_study = given
    args.fidelity = args.fidelity or DEFAULT_FIDELITY
    laws = cup_laws(args, coupled=True, fem=True)
    check_fields(args)
    if given is None:
        geometry, contact, uc_label = _inputs(args)
    else:
        uc_label = _inputs(args, geometry)[2]
    check_suction_table(args, geometry, contact)
    study = study_of(args, contact)
    if curve_study is not None:
        study = replace(study, **curve_study)
    products = Products(study, suction_cache_dir=None if args.no_cache else args.cache_dir,
                        fem_progress=terminal_progress("FEM"), keep_partial=True)
    from fem.solver import ConvergenceError
    from validation.commands._failure import failure_record, solver_failure

    with atomic_directory(args.out) as tmp:
        try:
            response = None if args.stiffness else products.fem_path(None)
            curve = products.curve()
        except ConvergenceError as exc:
            raise solver_failure(exc, Path(f"{Path(args.out)}.failure.json")) from None
        choice = products.cup_choice()
        if response is None:                           # the given curve, with its own sidecar
            curve.to_csv(tmp / "stiffness_fem.csv")
        else:
            curve.to_csv(tmp / "stiffness_fem.csv", sidecar=False)
            handoff.write_sidecar(handoff.sidecar(response, curve.provenance), tmp / "stiffness_fem.json")
        if args.route == "coupled":
            products.suction_table().to_json(tmp / "suction_table.json")
        results = products.lifetimes()
        holdable = results.largest_force_N
        series = {f"FEM-fed, {args.route} route": results}
        if args.route != "paper":        # the same FEM F0 through the paper's strip, for comparison
            paper = replace(study, route="paper", cup_laws="cone", refine=1)
            series["FEM F0, paper route (strip, eqs 3-7)"] = products.derived(
                paper, inherit=("uc_table", "curve", "cup")).lifetimes()
        series["Appendix A-fed, paper route (d0 2 mm)"] = products.appendix_a(refine=1).lifetimes()
        partial = products.partial()
        write_table(results, tmp / "lifetime_vs_force.csv", choice.cup.name, study, partial)
        if args.route == "fem":
            _write_trajectories(results, tmp, choice.cup.name)
        plot(series, curve, choice.cup, tmp / "lifetime_vs_force.png",
             f"{choice.label}, FEM {contact.contact.label()} ({args.fidelity}), {args.route} route, {uc_label}",
             tmp / "lifetime_vs_force_data.csv")
        _write_manifest(tmp, study, partial)
    wall = time.perf_counter() - t0
    failure = Path(f"{Path(args.out)}.failure.json")
    if partial is not None and response is not None:   # after the directory, which removed an earlier record
        failure_record(products.path_stop().error, failure)
    slope = float(curve.force(curve.h1_m - 1e-3))
    patch = getattr(products.uc_table(), "patch_length_m", None)
    crossed = {"profile": "the FEM's contact-pressure profiles" + (f", averaged over patches of {1e6 * patch:.0f} um"
                                                                 if patch else " (raw: the u_c table has no patch length)"),
               "coupled": "the contact-pressure profile of each (u, dp) state of the FEM suction table "
                          f"(largest holdable force {holdable:.4g} N)" if args.route == "coupled" else "",
               "fem": "the contact-pressure profile of each FEM state along the cup's equilibrium branch "
                      f"(largest holdable force {holdable:.4g} N)",
               "strip": "one strip at eq (6)'s pressure" + (f" (l0, l1: {choice.l_source})"
                                                            if laws == "cone" else "")}[_seal(args.route)]
    end = "0.9 h1" if study.u_max_mm is None and partial is None else f"{1e3 * curve.u_m[-1]:.4g} mm"
    print(f"{choice.label}: FEM {contact.contact.label()} stiffness (from the "
          f"{contact.source}; {args.fidelity}, {_steps(response, curve)} steps), "
          f"F0(1 mm) = {slope:.3g} N, F0({end}) = {curve.F0_N[-1]:.3g} N; u_c from {uc_label}; "
          f"r_start {1e3 * choice.cup.r_start_m:.4g} mm; r, V from the "
          f"{_rv_source(args.route, laws)}; {args.route} route: the leak "
          f"crosses {crossed}")
    names = list(series)
    print(f"  {'F1 (N)':>7} " + " ".join(f"{n.split(',')[0] + ', ' + n.split(', ')[1].split(' ')[0]:>24}"
                                         for n in names) + "  end")
    at = [{r.force_N: r for r in series[n]} for n in names]
    for r in results:
        print(f"  {r.force_N:7g} " + " ".join(f"{s[r.force_N].lifetime_s:24.4g}" if r.force_N in s else f"{'':>24}"
                                              for s in at) + f"  {r.reason}")
    extra = {"coupled": ", suction_table.json", "fem": ", trajectory_F1_*.csv"}.get(args.route, "")
    print(f"wrote {Path(args.out) / 'lifetime_vs_force.csv'}, lifetime_vs_force.png (its data: "
          f"lifetime_vs_force_data.csv), stiffness_fem.csv"
          f"{extra} in {wall:.1f} s")
    if partial is None:
        return 0
    if response is None:                                # a given partial curve: used within its range
        from validation.bridge.pipeline import partial_note
        refused = ", ".join(f"{r['force_N']:g}" for r in partial["refused"])
        print(f"note: --stiffness '{args.stiffness}' is {partial_note(curve.provenance)}; used within that range"
              + (f"; lifetimes refused at F1 = {refused} N, beyond the curve" if refused else ""), file=sys.stderr)
        return 0
    from validation.scenes.outputs import partial_lines
    for line in partial_lines({"study": partial}, "cli"):
        print(f"cupcheck example: {line}; the record is in {failure}", file=sys.stderr)
    return PARTIAL_EXIT


def _write_manifest(tmp: Path, study: Study, partial: dict[str, Any] | None = None) -> None:
    """manifest.json: the files written, the study they were computed for and, for a partial FEM
    curve, its record (`Products.partial`)."""
    import json

    from validation.output import MANIFEST, software_versions

    files = sorted(p.name for p in tmp.iterdir() if p.is_file())
    (tmp / MANIFEST).write_text(json.dumps({"files": [{"path": f} for f in files], "study": study.describe(),
                                            **({"partial": partial} if partial else {}),
                                            "versions": software_versions()}, indent=1, default=str) + "\n")


def _seal(route: str) -> str:
    """What the leak crosses on `route` (the key of the printed description)."""
    return {"paper": "strip", "profile": "profile", "coupled": "coupled", "fem": "fem"}[route]


def _rv_source(route: str, laws: str) -> str:
    if route == "coupled":
        return "FEM suction table"
    if route == "fem":
        return "FEM states"
    return "FEM curve" if laws == "curve" else "cone laws (3)-(4)"
