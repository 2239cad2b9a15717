"""Compute a cup's stiffness curve F0(h), r_c(h), l(h), V(h) with the axisymmetric finite-strain FEM.

The cup's top plate is pressed onto the rigid plane z = 0 (displacement control, u from 0 to
--u-max-mm, default 0.9 h1); the wall is a compressible neo-Hookean solid, in frictionless,
sticking or Coulomb-friction contact with the plane (--contact, --friction). Writes the hand-off
CSV (u_mm,h_mm,F0_N,r_c_mm,l_mm,V_mm3; l is the force-quartile width of the sealing strip) and a JSON sidecar next to it (same name, .json) with the
provenance, the solver statistics and per step the contact-pressure profile p(r), the instability
flags and the other widths (lengths in mm). All files appear together or not at all.

Every input is checked before the solve: a bad value, an output path that cannot be written, or
--nu above 0.495 with the displacement formulation (which locks there: use --formulation mixed)
stops with one line and exit status 2 (without --formulation, nu above 0.495 takes the mixed
formulation); a solve that fails before any step converged exits 1. Neither writes a curve.

A path that fails after some converged steps keeps them: the curve and sidecar are written up to
the last converged u, flagged partial in the sidecar's provenance ("partial": true,
"failed_at_u_mm", "failure_reason", "u_max_mm_that_runs"), one line says where and why it stopped
and which --u-max-mm runs, and the exit status is 3. Any failure leaves its record (the residual
history) in <out>.failure.json; a later complete run removes it.

examples:
  cupcheck stiffness --cup A --contact sticking --out out/cupA_sticking.csv
  cupcheck stiffness --cup A --contact coulomb --friction 0.5 --out out/cupA_mu05.csv
  cupcheck stiffness --geometry my_cup.toml --fidelity medium --out my_cup.csv
  cupcheck stiffness --mesh meshes/user_lip.msh --u-max-mm 3 --out lip.csv
"""

from __future__ import annotations

import argparse
import hashlib
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

from validation.commands._cup import add_contact_arguments, add_cup_arguments, contact_choice, load_cup_design
from validation.commands._paths import check_writable
from validation.bridge.pipeline import LOCKING_NU

NAME = "stiffness"
#: exit status of a run that wrote only the converged part of its path (a partial curve)
PARTIAL_EXIT = 3
HELP = "FEM stiffness curve F0(h), r_c, l, V of cup A, B or your own design (CSV + JSON sidecar)"

#: --fields-out suffixes (any case): .vtu, .vtk hold the last step, .xdmf every step; meshio's
#: other formats drop the 9-node cells or the fields
FIELD_SUFFIXES = (".vtu", ".vtk", ".xdmf")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    g = add_cup_arguments(parser, "also the base of --geometry")
    g.add_argument("--thickness-convention", choices=("normal", "vertical"),
                   help="wall thickness measured along the cavity surface's normal or vertically "
                        "(default: normal, or the geometry file's)")
    g.add_argument("--mesh", metavar="FILE", type=Path,
                   help="your own quadratic cross-section (.msh/.vtu, boundary names top_plate, "
                        "cavity[, outer, rim]; see meshes/README.md) instead of a generated mesh")
    g.add_argument("--mesh-unit", choices=("mm", "m"), default="mm",
                   help="length unit of the coordinates in --mesh (default mm)")
    m = parser.add_argument_group("material and contact")
    m.add_argument("--E-MPa", type=float, default=4.0, dest="E_MPa",
                   help="Young's modulus E [MPa] (default 4)")
    m.add_argument("--nu", type=float, default=0.49, help="Poisson's ratio [-] (default 0.49)")
    m.add_argument("--formulation", choices=("displacement", "mixed"), default=None,
                   help="displacement (nu <= 0.495, it locks above) or mixed u-p (nearly "
                        "incompressible, nu up to 0.4999) (default: by nu, mixed above 0.495)")
    add_contact_arguments(m, "the soap-lubricated glass on which the paper measured F0, Sec. 5.5")
    r = parser.add_argument_group("run")
    r.add_argument("--fidelity", choices=("coarse", "medium", "fine"), default=None,
                   help="mesh level of a generated mesh (default medium: F0 within 1 %% of the "
                        "converged curve; coarse ~2 %%, 4x faster; see docs/stiffness.md)")
    r.add_argument("--u-max-mm", type=float, default=None, dest="u_max_mm",
                   help="largest plate displacement u [mm], in (0, h1] (default 0.9 h1; at h1 the plate edge reaches the plane)")
    r.add_argument("--fields-out", type=Path, metavar="FILE",
                   help="also write the fields (displacement, Cauchy stress, contact pressure): "
                        "the last step as .vtu (or .vtk), or every step as an .xdmf time series "
                        "over u [m], with the run's design, contact law, mesh level and material "
                        "(cupcheck render captions with them); a missing directory is created")
    r.add_argument("--out", type=Path, required=True, metavar="CSV",
                   help="the stiffness curve (.csv); the sidecar goes to the same name with .json "
                        "(a missing directory is created)")


def run(args: argparse.Namespace) -> int:
    job = _prepare(args)                     # every check happens here, before the solve
    from fem.postprocess import BIOT_STRETCH
    from validation.bridge import handoff
    from validation.output import atomic_file, terminal_progress
    from validation.bridge.pipeline import converged_part, fem_curve, fem_path

    from fem.solver import ConvergenceError
    from validation.commands._failure import failure_record, solver_failure

    log = Path(args.out).with_suffix(".failure.json")
    stop = None
    try:
        response = fem_path(None, job["material"], job["contact"], job["fidelity"], job["u_max_m"],
                            terminal_progress("stiffness"), mesh=job["mesh"])
    except ConvergenceError as exc:
        kept = converged_part(exc)
        if kept is None:                     # nothing beyond u = 0 converged
            raise solver_failure(exc, log) from None
        response, stop = kept
    curve = fem_curve(response, job["geometry"], job["fidelity"], job["contact"].source, job["mesh_info"],
                      stop=stop)
    prov = curve.provenance
    with atomic_file(job["sidecar"]) as tmp_json, atomic_file(args.out) as tmp_csv:
        curve.to_csv(tmp_csv, sidecar=False)
        handoff.write_sidecar(handoff.sidecar(response, prov), tmp_json)
        if args.fields_out is not None:
            from fem.fields import write_fields
            with atomic_file(args.fields_out) as tmp_fields:
                every_step = tmp_fields.suffix.lower() == ".xdmf"
                write_fields(response, tmp_fields, step=None if every_step else -1,
                             provenance=_fields_provenance(job))
    if stop is not None:                     # after the writes, which removed an earlier record
        failure_record(stop.error, log)
    s = response.stats
    if stop is None:
        print(f"cupcheck stiffness: wrote {args.out} and {job['sidecar'].name}: "
              f"{job['contact'].contact.label()} contact (from the {job['contact'].source}), {s.steps} steps, "
              f"{s.newton_iterations} Newton iterations, {s.dofs} dofs, {s.wall_time_s:.1f} s; "
              f"F0 = {response.F0_N[-1]:.4g} N at u = {1e3 * response.u_m[-1]:.4g} mm")
    if response.folding_u_m is not None:
        print(f"cupcheck stiffness: note: from u = {1e3 * response.folding_u_m:.4g} mm the wall is "
              f"compressed beyond Biot's stretch {BIOT_STRETCH} (smallest {response.min_stretch.min():.3f}): "
              "a free surface may fold there, and the curve beyond depends on the mesh", file=sys.stderr)
    if stop is not None:
        runs = _round_down(1e3 * stop.u_max_m_that_runs)
        print(f"cupcheck stiffness: partial: the path stopped at u = {1e3 * stop.failed_at_u_m:.4g} mm "
              f"({stop.reason}); wrote the converged part, u = 0 to {1e3 * stop.u_max_m_that_runs:.4g} mm, "
              f"to {args.out} and {job['sidecar'].name} (flagged partial); --u-max-mm {runs:.4g} runs; "
              f"the record is in {log}", file=sys.stderr)
        return PARTIAL_EXIT
    return 0


def _prepare(args: argparse.Namespace) -> dict[str, Any]:
    """Validate every input and build the mesh and material (cheap); raise ValueError."""
    from fem.cup import cup_height
    from fem.mesh import DEFAULT_FIDELITY, cup_mesh
    from validation.bridge.pipeline import mesh_record, neo_hookean

    out = Path(args.out)
    if out.suffix.lower() != ".csv":
        raise ValueError(f"out: the stiffness curve must be a .csv file (any case), got '{out}'")
    check_writable(out, "out")
    check_writable(out.with_suffix(".json"), "out", "its sidecar")
    if args.fields_out is not None:
        fields = Path(args.fields_out)
        if fields.suffix.lower() not in FIELD_SUFFIXES:
            raise ValueError(f"fields_out: must end in .vtu or .vtk (the last step) or .xdmf (every "
                             f"step), in any case, got '{fields}'")
        check_writable(fields, "fields_out")
    from validation.output import check_outputs, command_inputs
    check_outputs(files={"--out": out, "--fields-out": args.fields_out}, inputs=command_inputs(args),
                  companions={"--out's sidecar": (out.with_suffix(".json"), "provenance")})
    from validation.guards import check_design, check_modulus

    material = neo_hookean(check_modulus(args.E_MPa) * 1e6, args.nu, args.formulation)
    fidelity = args.fidelity or DEFAULT_FIDELITY
    if args.mesh is not None:
        given = [o for o, v in (("--geometry", args.geometry), ("--fidelity", args.fidelity), ("--cup", args.cup),
                                ("--thickness-convention", args.thickness_convention)) if v is not None]
        if given:
            raise ValueError(f"mesh: a mesh file fixes the geometry and the mesh; drop {', '.join(given)}")
        contact = contact_choice(args)
        from fem.mesh_files import read_mesh        # meshio: only for a mesh file
        mesh = read_mesh(args.mesh, unit=args.mesh_unit)
        geometry = {"name": f"mesh file {Path(args.mesh).name}"}
        mesh_info = mesh_record(mesh, None, {"file": str(args.mesh), "unit": args.mesh_unit,
                                             "sha256": hashlib.sha256(Path(args.mesh).read_bytes()).hexdigest()})
        fidelity = None
    else:
        design = load_cup_design(args)
        contact = contact_choice(args, design)
        geo = design.geometry
        if args.thickness_convention is not None:
            geo = replace(geo, thickness_convention=args.thickness_convention)
        geometry = geo.describe()
        check_design(geometry, args.allow_unusual_design, source=geo.name)
        mesh = cup_mesh(geo, fidelity)
        mesh_info = mesh_record(mesh, fidelity)
    h1 = cup_height(mesh)
    if args.u_max_mm is None:
        u_max = 0.9 * h1
    else:
        u_max = _positive(args.u_max_mm, "u_max_mm", "plate displacement") * 1e-3
        if u_max > h1 * (1 + 1e-9):          # beyond the round-off of the mm -> m conversion
            raise ValueError(f"u_max_mm: plate displacement must be in (0, h1] = (0, "
                             f"{1e3 * h1:.9g}] mm, got {args.u_max_mm:.9g}")
        u_max = min(u_max, h1)
    return {"mesh": mesh, "material": material, "u_max_m": u_max, "geometry": geometry,
            "mesh_info": mesh_info, "fidelity": fidelity, "sidecar": out.with_suffix(".json"),
            "contact": contact}


def _fields_provenance(job: dict[str, Any]) -> dict[str, str]:
    """What the fields file records of its run (render captions with it): the design, the contact
    law, the mesh level ("file" for a mesh file) and the material."""
    m = job["material"]
    return {"design": job["geometry"]["name"], "contact": job["contact"].contact.label(),
            "mesh": job["fidelity"] or "file",
            "material": f"neo-Hookean E = {1e-6 * m.E_Pa:g} MPa, nu = {m.nu:g} ({m.formulation})"}


def _round_down(value: float, digits: int = 4) -> float:
    """`value` > 0 rounded down to `digits` significant digits (a --u-max-mm that stays within)."""
    import math

    scale = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.floor(value / scale) * scale


def _positive(value: float, name: str, what: str) -> float:
    if not (value == value and 0 < value < float("inf")):
        raise ValueError(f"{name}: {what} must be > 0, got {value:g}")
    return float(value)


if __name__ == "__main__":  # pragma: no cover
    from validation.cli import main
    sys.exit(main([NAME, *sys.argv[1:]]))
