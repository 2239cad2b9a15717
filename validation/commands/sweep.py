"""Sweep many cup designs on dask.distributed: FEM stiffness, Appendix A ratio, lifetimes, maps.

Reads SWEEP.toml (a base design and axes: a full grid, or Latin hypercube or Sobol samples;
`validation.sweeps.spec` documents the keys), evaluates every design (FEM stiffness curve, F0 at
chosen u, small-u stiffness and its ratio to Appendix A, r_c and l at r_start, the largest holdable
force, lifetimes at the chosen F1; a design that fails becomes a row with its reason) and writes
into DIR:

  designs/<hash>.json           one committed result per design (a rerun computes only the missing)
  results.parquet, results.csv  the tidy table: one row per design and force, units in the names
  map_*.png, pareto_lifetime_volume.png   maps over two axes and the Pareto front

examples:
  cupcheck sweep scenes/sweep_alpha_thickness.toml --out out/sweep            # all cores
  cupcheck sweep my_sweep.toml --out out/sweep --workers 1 --retry-failed
  cupcheck sweep my_sweep.toml --out out/sweep --scheduler tcp://127.0.0.1:8786
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

NAME = "sweep"
HELP = "many cup designs on dask.distributed: stiffness, Appendix A ratio, lifetimes (Parquet, CSV, maps)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("sweep", type=Path, metavar="SWEEP.toml", help="the sweep file")
    p.add_argument("--out", type=Path, required=True, metavar="DIR",
                   help="output directory; an existing one is resumed (its committed designs are kept)")
    p.add_argument("--workers", type=int, default=None,
                   help="worker processes of the local dask cluster (default: all cores)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="an existing dask scheduler (e.g. tcp://127.0.0.1:8786) instead of a local cluster")
    p.add_argument("--retry-failed", action="store_true", help="also recompute designs whose rows failed")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    from validation.sweeps.execute import pending_designs, run_sweep
    from validation.sweeps.figures import sweep_caption, sweep_figures
    from validation.sweeps.spec import load_sweep, lock_store
    import dask
    from validation.sweeps.worker import PRELOAD

    spec = load_sweep(args.sweep)
    from validation.output import check_outputs, command_inputs
    check_outputs(stores={"--out": args.out}, inputs=command_inputs(args))
    if args.workers is not None and not 1 <= args.workers <= 256:
        raise ValueError(f"--workers: must be in [1, 256], got {args.workers}")
    if args.out.exists() and not args.out.is_dir():
        raise ValueError(f"--out: '{args.out}' exists and is not a directory")
    store_lock = lock_store(args.out)  # noqa: F841 (held until run returns: one sweep per store)
    total = len(spec.designs())
    todo = len(pending_designs(spec, args.out, args.retry_failed)) if args.out.is_dir() else total
    print(f"sweep: {total} designs, {todo} to compute, {total - todo} already done", file=sys.stderr)
    bar = None
    if not args.quiet and todo:
        from tqdm import tqdm
        bar = tqdm(total=todo, desc="designs", unit="design", file=sys.stderr,
                   disable=None)                    # None: quiet when stderr is not a terminal

    def progress(done: int, failed: int, n: int, key: str) -> None:
        if bar is not None:
            bar.update(1)
            bar.set_postfix(failed=failed, remaining=n - done)

    dask.config.set(PRELOAD)             # the workers leave Ctrl-C to this process (one line)
    result = run_sweep(spec, args.out, workers=args.workers, scheduler=args.scheduler,
                       retry_failed=args.retry_failed, progress=progress)
    if bar is not None:
        bar.close()
    if result.dashboard:
        print(f"sweep: dask dashboard was at {result.dashboard}", file=sys.stderr)
    names = [a["name"] for a in spec.axes]
    figures = sweep_figures(result.table, names, args.out, sweep_caption(spec.base, names))
    print(f"sweep: {result.designs} designs ({result.computed} computed, {result.reused} reused, "
          f"{result.failed} failed) in {result.wall_s:.1f} s; wrote {result.table}, results.csv and "
          f"{len(figures)} figures")
    return 0
