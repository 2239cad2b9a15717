"""Compute a cup's response to the cavity's suction on a (u, dp) grid: the input of the coupled route.

For every plate displacement u > 0 the cup is pressed onto the plane without suction, then the
pressure difference dp = p_a - p_b is ramped on its cavity surface with the plate held; at
u <= 0 (the plate above the free cup's touching height) the plate is raised at fixed dp, and a
state whose rim has left the plane is marked as holding no seal (`fem.suction`). Writes a JSON table (`reduced.suction_table.SuctionTable`: per (u, dp) the pull
on the handle F1, the cavity volume, the seal radius and the contact-pressure profile) that
`cupcheck lifetime --route coupled --suction-table FILE` reads. Every input is checked before the
solve (one line, exit 2); a solve that fails exits 1; no file is left behind either way.

--grid adaptive builds only the states of that grid which the lifetimes at --force on --surface
and the largest holdable force read: the table with holes around their paths
(`validation.bridge.coupled.around`), the same states `lifetime --route coupled` builds, its
raised rows down to where the paths let go (at the latest the plate's floor h1 - 2 L,
`fem.branch_end`). --grid full (the default) builds every state of the grid, its raised rows
down to -0.6 h1 (`validation.bridge.coupled.build.FULL_DEPTH_H1`).

The contact law is --contact (with --friction for coulomb), else the --geometry file's [contact]
table, else frictionless; the table's provenance records it and where it came from.

examples:
  cupcheck suction --cup A --out out/cupA_suction.json
  cupcheck suction --cup B --fidelity coarse --dp-kPa 0 25 50 75 100 --out cupB.json
  cupcheck suction --cup A --fidelity coarse --grid adaptive --force 5 10 20 --out cupA_5_20N.json
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from validation.commands._cup import add_contact_arguments, add_cup_arguments, contact_choice, load_cup_design
from validation.commands._surface import add_surface_arguments, has_surface

NAME = "suction"
HELP = "FEM response to the cavity suction on a (u, dp) grid, for lifetime --route coupled (JSON)"

from validation.bridge.coupled.build import DEFAULT_GRID


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_cup_arguments(parser, "also the base of --geometry")
    m = parser.add_argument_group("material and contact")
    m.add_argument("--E-MPa", type=float, default=4.0, dest="E_MPa", help="Young's modulus E [MPa] (default 4)")
    m.add_argument("--nu", type=float, default=0.49, help="Poisson's ratio [-], at most 0.495 (default 0.49)")
    add_contact_arguments(m, "path independent, so the order press-then-suck does not matter; "
                             "sticking and coulomb give the response to that order")
    r = parser.add_argument_group("grid and run")
    r.add_argument("--fidelity", choices=("coarse", "medium", "fine"), default="medium",
                   help="mesh level (default medium)")
    r.add_argument("--u-mm", type=float, nargs="+", default=None, dest="u_mm", metavar="U",
                   help="plate displacements [mm], increasing, in [h1 - 2 L, h1] (L: the wall's "
                        "length; h1 - 2 L the plate's floor); u <= 0 is the plate above the free "
                        "cup's touching height, raised at fixed dp (default: 105 values from 0.001 "
                        "to 0.8 h1, graded towards 0, u = 0 and 540 raised rows evenly down to the "
                        "floor; --grid full builds those down to -0.6 h1)")
    r.add_argument("--dp-kPa", type=float, nargs="+", default=list(DEFAULT_GRID.dp_kPa), dest="dp_kPa",
                   metavar="DP",
                   help="pressure differences p_a - p_b [kPa], from 0, increasing, at most 1000 "
                        "(default 0, 1, ..., 100)")
    r.add_argument("--grid", choices=("full", "adaptive"), default="full",
                   help="every state of the grid, or only those the lifetimes at --force on --surface "
                        "need (default full)")
    r.add_argument("--force", dest="force_N", type=float, nargs="+", default=None, metavar="F1_N",
                   help="with --grid adaptive: the pull forces [N] the table is for (default 5 10 20 40)")
    add_surface_arguments(parser, r.add_mutually_exclusive_group())
    parser.set_defaults(uc_method="emt", gamma=0.45, a_c=0.42, uc_table=None)
    r.add_argument("--out", type=Path, required=True, metavar="JSON",
                   help="the suction table (.json); a missing directory is created")


def run(args: argparse.Namespace) -> int:
    job = _prepare(args)
    from fem.solver import ConvergenceError
    from fem.suction import suction_grid
    from validation.commands._failure import solver_failure
    from validation.bridge.coupled.table import suction_table
    from validation.output import atomic_file, terminal_progress

    provenance = {"geometry": job["geometry"], "fidelity": args.fidelity, "contact_source": job["contact"].source}
    try:
        if job["goal"] is not None:
            table, what = _adaptive(args, job, provenance, terminal_progress("suction"))
        else:
            grid = suction_grid(job["mesh"], job["material"], job["u_m"], job["dp_Pa"],
                                contact=job["contact"].contact, progress=terminal_progress("suction"))
            table, what = suction_table(grid, provenance), f"{grid.u_m.size} x {grid.dp_Pa.size} states"
    except ConvergenceError as exc:
        raise solver_failure(exc, Path(args.out).with_suffix(".failure.json")) from None
    with atomic_file(args.out) as tmp:
        table.to_json(tmp)
    s = table.provenance["solver"]
    print(f"cupcheck suction: wrote {args.out}: {what}, "
          f"{s['newton_iterations']} Newton iterations, {s['dofs']} dofs, {s['wall_time_s']:.1f} s; "
          f"largest pull in the table {table.F1_N.max():.4g} N")
    return 0


def _adaptive(args: argparse.Namespace, job: dict, provenance: dict, progress):
    """The table with holes around the goal's paths on the lattice u_m x dp_Pa
    (`validation.bridge.coupled.around`, as the lifetimes' products build it)."""
    from fem.suction import SuctionStates
    from validation.bridge.coupled.build import AroundSpec, around_table

    contact = job["contact"].contact
    # pressed from the kept row below in one step, as the products' build (frictionless states do
    # not depend on the path)
    states = SuctionStates(job["mesh"], job["material"], contact, initial_step=1.0, max_step=1.0)
    u, dp = job["u_m"], job["dp_Pa"]
    table = around_table(states, u, dp, job["goal"], AroundSpec(), contact, provenance,
                         f"{u.size} u x {dp.size} dp", progress)
    raised = int(np.sum(table.built.any(axis=1) & (table.u_m <= 0)))
    return table, (f"{int(table.built.sum())} states around the paths of {u.size} x {dp.size} ({raised} raised "
                   f"rows, down to u = {1e3 * table.u_m[np.flatnonzero(table.built.any(axis=1))[0]]:.4g} mm), "
                   f"{states.solved} states solved")


def _prepare(args: argparse.Namespace) -> dict:
    """Validate every input and build the mesh and material (cheap); raise ValueError."""
    from fem.cup import cup_height
    from fem.material import NeoHookean
    from fem.mesh import cup_mesh
    from fem.suction import plate_floor_of
    from validation.bridge.coupled.build import full_rows
    from validation.commands._paths import check_writable
    from validation.bridge.pipeline import LOCKING_NU
    from validation.guards import check_design, check_modulus

    out = Path(args.out)
    if out.suffix.lower() != ".json":
        raise ValueError(f"out: the suction table must be a .json file (any case), got '{out}'")
    check_writable(out, "out")
    from validation.output import check_outputs, command_inputs
    check_outputs(files={"--out": out}, inputs=command_inputs(args))
    if not (0.0 <= args.nu <= LOCKING_NU):
        raise ValueError(f"nu: Poisson's ratio must be in [0, {LOCKING_NU}], got {args.nu:g}")
    material = NeoHookean(E_Pa=check_modulus(args.E_MPa) * 1e6, nu=args.nu)
    design = load_cup_design(args)
    contact = contact_choice(args, design)
    geo = design.geometry
    geometry = geo.describe()
    check_design(geometry, args.allow_unusual_design, source=geo.name)
    mesh = cup_mesh(geo, args.fidelity)
    h1, floor = cup_height(mesh), plate_floor_of(mesh)
    if args.u_mm is not None:
        u = 1e-3 * np.array(args.u_mm, float)
    else:
        u = DEFAULT_GRID.u_m(h1, floor) if args.grid == "adaptive" else full_rows(DEFAULT_GRID, mesh)
    if not (np.all(np.isfinite(u)) and np.all(np.diff(u) > 0) and u[0] >= floor * (1 + 1e-9)
            and u[-1] <= h1 * (1 + 1e-9)):
        raise ValueError(f"u_mm: plate displacements must increase within [h1 - 2 L, h1] = [{1e3 * floor:.6g}, "
                         f"{1e3 * h1:.6g}] mm, got {args.u_mm}")
    dp = np.array(args.dp_kPa, float)
    if not (np.all(np.isfinite(dp)) and dp[0] == 0 and np.all(np.diff(dp) > 0) and dp[-1] <= 1000
            and dp.size >= 2):
        raise ValueError(f"dp_kPa: pressure differences must start at 0 and increase, at most "
                         f"1000 kPa, at least two, got {args.dp_kPa}")
    return {"mesh": mesh, "material": material, "u_m": np.minimum(u, h1), "dp_Pa": 1e3 * dp,
            "geometry": geometry, "contact": contact, "goal": _goal(args, h1)}


def _goal(args: argparse.Namespace, h1_m: float):
    """The `SuctionGoal` of --grid adaptive (None for the full grid); ValueError naming the option."""
    if args.grid == "full":
        for option, given in (("--force", args.force_N is not None), ("--surface", has_surface(args))):
            if given:
                raise ValueError(f"{option}: applies to --grid adaptive only")
        return None
    from reduced.gas import Gas
    from reduced.lifetime import LeakageModel
    from validation.bridge.coupled.adaptive import SuctionGoal
    from validation.bridge.design import resolve_cup
    from validation.commands._reduced_options import build_uc

    forces = [5.0, 10.0, 20.0, 40.0] if args.force_N is None else args.force_N
    if not all(np.isfinite(f) and f > 0 for f in forces):
        raise ValueError(f"--force: pull forces must be > 0 N, got {' '.join(f'{f:g}' for f in forces)}")
    choice = resolve_cup(None, cup=args.cup, geometry_file=args.geometry, laws="curve")
    model = LeakageModel(cup=choice.cup, u_c=build_uc(args), gas=Gas(T_K=293.15), p_a_Pa=1e5)
    return SuctionGoal(model, tuple(forces))


if __name__ == "__main__":  # pragma: no cover
    from validation.cli import main
    sys.exit(main([NAME, *sys.argv[1:]]))
