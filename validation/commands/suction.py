"""Compute a cup's response to the cavity's suction on a (u, dp) grid: the input of the coupled route.

For every plate displacement u the cup is pressed onto the plane without suction, then the
pressure difference dp = p_a - p_b is ramped on its cavity surface with the plate held
(`fem.suction`). Writes a JSON table (`reduced.suction_table.SuctionTable`: per (u, dp) the pull
on the handle F1, the cavity volume, the seal radius and the contact-pressure profile) that
`cupcheck lifetime --route coupled --suction-table FILE` reads. Every input is checked before the
solve (one line, exit 2); a solve that fails exits 1; no file is left behind either way.

The contact law is --contact (with --friction for coulomb), else the --geometry file's [contact]
table, else frictionless; the table's provenance records it and where it came from.

examples:
  cupcheck suction --cup A --out out/cupA_suction.json
  cupcheck suction --cup B --fidelity coarse --dp-kPa 0 25 50 75 100 --out cupB.json
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from validation.commands._cup import add_contact_arguments, add_cup_arguments, contact_choice, load_cup_design

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
                   help="plate displacements [mm], increasing, in (0, h1] (default: 105 values "
                        "from 0.001 to 0.8 h1, graded towards 0)")
    r.add_argument("--dp-kPa", type=float, nargs="+", default=list(DEFAULT_GRID.dp_kPa), dest="dp_kPa",
                   metavar="DP",
                   help="pressure differences p_a - p_b [kPa], from 0, increasing, at most 1000 "
                        "(default 0, 1, ..., 100)")
    r.add_argument("--out", type=Path, required=True, metavar="JSON",
                   help="the suction table (.json); a missing directory is created")


def run(args: argparse.Namespace) -> int:
    job = _prepare(args)
    from fem.solver import ConvergenceError
    from fem.suction import suction_grid
    from validation.commands._failure import solver_failure
    from validation.bridge.coupled.table import suction_table
    from validation.output import atomic_file, terminal_progress

    try:
        grid = suction_grid(job["mesh"], job["material"], job["u_m"], job["dp_Pa"], contact=job["contact"].contact,
                            progress=terminal_progress("suction"))
    except ConvergenceError as exc:
        raise solver_failure(exc, Path(args.out).with_suffix(".failure.json")) from None
    table = suction_table(grid, {"geometry": job["geometry"], "fidelity": args.fidelity,
                                 "contact_source": job["contact"].source})
    with atomic_file(args.out) as tmp:
        table.to_json(tmp)
    s = grid.stats
    print(f"cupcheck suction: wrote {args.out}: {grid.u_m.size} x {grid.dp_Pa.size} states, "
          f"{s.newton_iterations} Newton iterations, {s.dofs} dofs, {s.wall_time_s:.1f} s; "
          f"largest pull in the table {grid.F1_N.max():.4g} N")
    return 0


def _prepare(args: argparse.Namespace) -> dict:
    """Validate every input and build the mesh and material (cheap); raise ValueError."""
    from fem.cup import cup_height
    from fem.material import NeoHookean
    from fem.mesh import cup_mesh
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
    h1 = cup_height(mesh)
    u = DEFAULT_GRID.u_m(h1) if args.u_mm is None else 1e-3 * np.array(args.u_mm, float)
    if not (np.all(np.isfinite(u)) and np.all(np.diff(u) > 0) and u[0] > 0 and u[-1] <= h1 * (1 + 1e-9)):
        raise ValueError(f"u_mm: plate displacements must increase within (0, h1] = (0, "
                         f"{1e3 * h1:.6g}] mm, got {args.u_mm}")
    dp = np.array(args.dp_kPa, float)
    if not (np.all(np.isfinite(dp)) and dp[0] == 0 and np.all(np.diff(dp) > 0) and dp[-1] <= 1000
            and dp.size >= 2):
        raise ValueError(f"dp_kPa: pressure differences must start at 0 and increase, at most "
                         f"1000 kPa, at least two, got {args.dp_kPa}")
    return {"mesh": mesh, "material": material, "u_m": np.minimum(u, h1), "dp_Pa": 1e3 * dp,
            "geometry": geometry, "contact": contact}


if __name__ == "__main__":  # pragma: no cover
    from validation.cli import main
    sys.exit(main([NAME, *sys.argv[1:]]))
