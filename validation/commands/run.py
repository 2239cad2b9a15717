"""Run a scene: say what you want to see, compute only that (validation/scenes/schema.py: the keys).

Writes the scene's outputs into DIR atomically, with DIR/manifest.json (every file written with
its name and kind, the scene as resolved with its defaults, software versions and timings).
Products are cached on disk, in the user's cache (--cache-dir; default the platform's cache directory,
~/.cache/cupcheck/scenes on Linux, or $CUPCHECK_CACHE_DIR/scenes): a second run of the same scene
computes nothing. A rerun into the same DIR draws only the outputs whose inputs changed or whose
files were edited or deleted (the manifest records what each file was made from and its sha256);
one that changes nothing writes nothing. --no-cache computes and draws everything afresh. The
figures are drawn in a second process while the curves and lifetimes are computed (on Linux with
two processors or more; elsewhere one after the other).

An FEM stiffness curve whose path fails after some converged steps keeps them: the outputs drawn
from it use the converged part, flagged partial (the curve's sidecar, a curve_partial_to_u_mm
column in the lifetime tables, "partial" in the manifest); a lifetime that needs a state beyond it
is refused for its force (reason beyond_partial_curve), the others computed; one line says where
the path stopped and which stiffness.u_max_mm runs, and the exit status is 3.

examples:
  cupcheck run scenes/lifetime_vs_force_cupA.toml --out out/lifetime
  cupcheck run scenes/uc_presets.toml --out out/uc --no-cache
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from validation.bridge.cache import CACHE_ENV, user_cache_dir

NAME = "run"
HELP = "run a scene file: the curves, lifetimes and figures it asks for (cached)"
#: exit status of a run whose stiffness curve is the converged part of a failed FEM path
PARTIAL_EXIT = 3


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", type=Path, metavar="SCENE.toml", help="the scene file")
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory (written atomically)")
    p.add_argument("--cache-dir", type=Path, default=user_cache_dir("scenes"), metavar="DIR",
                   help=f"where products are cached (default: %(default)s, the user's cache; "
                        f"${CACHE_ENV} moves it)")
    p.add_argument("--no-cache", action="store_true", help="compute every product afresh, cache nothing")
    p.add_argument("--quiet", action="store_true",
                   help="no progress bar (there is none either when stderr is not a terminal)")


def run(args: argparse.Namespace) -> int:
    from validation.scenes.outputs import run_scene
    from validation.scenes.schema import load_scene

    scene = load_scene(args.scene)                    # every check before any work
    from validation.output import check_outputs, command_inputs
    check_outputs(directories={"--out": args.out}, stores={"--cache-dir": None if args.no_cache else args.cache_dir},
                  inputs={**command_inputs(args), "cup.geometry": scene["cup"]["geometry"],
                          "surface.uc_table": scene["surface"]["uc_table"]})
    if args.out.exists() and not args.out.is_dir():
        raise ValueError(f"--out: '{args.out}' exists and is not a directory")

    bar = None
    if not args.quiet and sys.stderr.isatty():       # quiet when not on a terminal
        import shutil

        from tqdm import tqdm
        size = shutil.get_terminal_size((100, 20))     # a terminal that reports 0 x 0 hides tqdm's bar
        bar = tqdm(total=len(scene.outputs), desc="run", unit="output", file=sys.stderr, leave=False,
                   ncols=size.columns or 100, nrows=size.lines or 20)

    def progress(message: str) -> None:
        """'output k of n: name' advances the bar; the rest (product, FEM u reached, force k of n) is its note."""
        if message.startswith("output "):
            bar.n = int(message.split()[1]) - 1
            bar.set_description(f"run {message.split(': ', 1)[1]}")
        bar.set_postfix_str(message if not message.startswith("output ") else "", refresh=True)

    try:
        result = run_scene(scene, args.out, cache_dir=None if args.no_cache else args.cache_dir,
                           progress=progress if bar is not None else None, reuse=not args.no_cache,
                           figure_process=True)
    finally:
        if bar is not None:
            bar.close()
    timing = ", ".join(f"{k} {v:.2f} s" for k, v in result.timings.items())
    if result.up_to_date:
        print(f"run: the {len(result.files)} files in {args.out} are up to date (nothing written)")
    else:
        kept = f", {len(result.kept)} unchanged kept" if result.kept else ""
        print(f"run: wrote {len(result.files) - len(result.kept)} files{kept} and manifest.json to {args.out} "
              f"({timing or 'nothing computed'})")
    from validation.scenes.outputs import partial_lines
    for line in partial_lines(result.partial):         # a curve that stopped short: exit 3, as stiffness
        print(f"run: {line}", file=sys.stderr)
    return PARTIAL_EXIT if result.partial else 0
