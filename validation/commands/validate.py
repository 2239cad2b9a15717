"""Cross-check report: Appendix A vs FEM, rigid-cone laws vs FEM, the lifetime consequence
of the stiffness source, the speed-accuracy trade, the extremes, the paper's numbers, Coulomb
friction, and the cup's whole life in the FEM (the fem route by contact law).

Writes to DIR, atomically: README.md (all sections, tables inline), one CSV per table (units in the
column names), PNG figures, and summary.json with the headline numbers (appendix_a_slope_N_per_mm,
fem_slope_frictionless_N_per_mm, fem_slope_sticking_N_per_mm, ...). Every FEM run a section needs is
declared up front and run once, and kept between calls in the user's cache (--cache-dir; default
~/.cache/cupcheck/validate on Linux or $CUPCHECK_CACHE_DIR/validate; keyed by the run and the fem
sources; --no-cache keeps nothing). The report is written in full either way; the exit status is 1 when any of its checks
FAILs (the rows marked FAIL), 0 when all pass.

examples:
  cupcheck validate --quick --out out/validate-quick            # the CI subset, ~1 min
  cupcheck validate --out validation/report                     # the full report: sections 1-7 ~10 min on 2 cores;
                                                                #   section 8 (fem_life) hours (mu >= 1, sticking)
  cupcheck validate --only fem_life --out out/v                 # the cup's whole life in the FEM by contact law
  cupcheck validate --only appendix cone_laws --out out/v --no-cache
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from validation.bridge.cache import user_cache_dir

NAME = "validate"
HELP = ("cross-check report: Appendix A, cone laws, lifetimes, speed-accuracy, extremes, the paper's "
        "numbers, Coulomb friction, the fem route by contact law (CSV, MD, PNG, JSON)")


def add_arguments(p: argparse.ArgumentParser) -> None:
    from validation.crosscheck import section_names

    p.add_argument("--out", required=True, type=Path, metavar="DIR", help="output directory (written atomically)")
    p.add_argument("--quick", action="store_true",
                   help="a small representative subset (cup A only, coarse mesh, a few extremes)")
    p.add_argument("--only", nargs="+", metavar="SECTION",
                   help=f"run only these sections: {', '.join(section_names())} (default: all)")
    p.add_argument("--cache-dir", type=Path, default=user_cache_dir("validate"), metavar="DIR",
                   help="where FEM runs are kept between calls (default: %(default)s, the user's cache; "
                        "$CUPCHECK_CACHE_DIR moves it)")
    p.add_argument("--no-cache", action="store_true", help="compute every FEM run afresh, keep nothing")
    p.add_argument("--no-scene", action="store_true", help="skip the pyvista scene of the deformed cup")


def run(args: argparse.Namespace) -> int:
    import json
    import os

    os.environ.setdefault("MPLBACKEND", "Agg")
    from validation.crosscheck import RunMemo, planned_requests, run_validation
    from validation.output import atomic_directory, terminal_progress

    plan = planned_requests(args.quick, args.only)          # validates --only before any work
    from validation.output import check_outputs, command_inputs
    check_outputs(directories={"--out": args.out}, stores={"--cache-dir": None if args.no_cache else args.cache_dir}, inputs=command_inputs(args))
    if args.out.exists() and not args.out.is_dir():
        raise ValueError(f"--out: {args.out} exists and is not a directory")
    memo = RunMemo(cache_dir=None if args.no_cache else args.cache_dir)
    print(f"validate: {len(plan)} FEM runs planned ({'quick' if args.quick else 'full'})")
    with atomic_directory(args.out) as tmp:
        report = run_validation(tmp, quick=args.quick, only=args.only, memo=memo, scene=not args.no_scene,
                                progress=terminal_progress("validate"))
    s = report.summary
    keys = ("appendix_a_slope_N_per_mm", "fem_slope_frictionless_N_per_mm", "fem_slope_sticking_N_per_mm")
    for k in keys:
        if k in s:
            print(f"  {k} = {s[k]:.4g}")
    if "extremes_outcomes" in s:
        print(f"  extremes: {json.dumps(s['extremes_outcomes'])}")
    print(f"wrote {args.out}/README.md, {len(report.files)} tables and figures, summary.json "
          f"({s['fem_runs_computed']} FEM runs computed, {s['fem_runs_from_cache']} from cache, "
          f"{s['wall_s']:.0f} s)")
    failed = failed_checks(s)
    if failed:
        print(f"validate: {failed} check(s) FAIL (the rows marked FAIL in {args.out}/README.md); exit "
              f"status 1", file=sys.stderr)
        return 1
    return 0


def failed_checks(summary: dict) -> int:
    """How many rows of the report failed a check (today: the extremes' FAIL rows)."""
    return int(summary.get("extremes_outcomes", {}).get("FAIL", 0))
