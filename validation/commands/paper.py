"""Draw the paper's calculated figures (Tiwari & Persson, Sec. 5) in one command.

Each figure shows the FEM-fed result (cup A or B, frictionless FEM at --fidelity, the profile
route) beside the paper's own inputs (Appendix A's F0, Table 1's rigid cone, the paper route),
with the numbers the paper states marked on it (validation/data/paper_numbers.toml: each with
the section, table or caption it comes from). Written into DIR atomically: per figure a PNG, an
SVG and a CSV of everything drawn (columns design, contact, mesh, route, surface), and
manifest.json with one sentence per figure on what agrees with the paper and what does not.
The gallery of the set: docs/paper-figures.md.

figures: F0_vs_u_cups, lifetime_vs_force_cups, r_pb_vs_time, p_Ndot_vs_time, lifetime_vs_kappa,
lifetime_vs_rms, lifetime_vs_r_start, uc_vs_pressure

examples:
  cupcheck paper --out out/paper        # the whole set, coarse FEM: ~35 s of CPU cold, ~8 s warm
  cupcheck paper --out out/paper --only lifetime_vs_force_cups --fidelity medium
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from validation.bridge.cache import CACHE_ENV, user_cache_dir

NAME = "paper"
HELP = "draw the paper's calculated figures: FEM-fed beside the paper's inputs, its stated numbers marked"
#: the set's figures (validation.scenes.paper.PAPER_FIGURES; spelled out so that --help imports no model)
FIGURE_NAMES = ("F0_vs_u_cups", "lifetime_vs_force_cups", "r_pb_vs_time", "p_Ndot_vs_time", "lifetime_vs_kappa",
                "lifetime_vs_rms", "lifetime_vs_r_start", "uc_vs_pressure")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory (written atomically)")
    p.add_argument("--fidelity", choices=("coarse", "medium", "fine"), default="coarse",
                   help="FEM mesh level of the FEM-fed lines (default: %(default)s)")
    p.add_argument("--only", nargs="+", choices=FIGURE_NAMES, metavar="FIGURE",
                   help="draw only these figures (default: all eight, listed above)")
    p.add_argument("--cache-dir", type=Path, default=user_cache_dir("scenes"), metavar="DIR",
                   help=f"where products are cached (default: %(default)s, the user's cache; ${CACHE_ENV} moves it)")
    p.add_argument("--no-cache", action="store_true", help="compute every product afresh, cache nothing")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")


def run(args: argparse.Namespace) -> int:
    from validation.output import check_outputs, command_inputs

    check_outputs(directories={"--out": args.out}, stores={"--cache-dir": None if args.no_cache else args.cache_dir},
                  inputs=command_inputs(args))
    from validation.scenes.paper import run_paper

    def progress(message: str) -> None:
        if message.startswith("figure "):
            print(f"paper: {message}", file=sys.stderr, flush=True)

    results = run_paper(args.out, fidelity=args.fidelity, cache_dir=None if args.no_cache else args.cache_dir,
                        only=tuple(args.only) if args.only else None, progress=None if args.quiet else progress)
    print(f"paper: wrote {sum(len(r.files) for r in results)} files and manifest.json to {args.out}")
    for r in results:
        print(f"  {r.figure.name}: {r.sentence}")
    return 0
