"""`cupcheck` command line: one subcommand per module in `validation.commands`.

`COMMANDS` lists each command with its module and one-line help; a command's module (which defines
``HELP``, the same line, ``add_arguments(parser)`` and ``run(args) -> int``) is imported only when that
command is invoked, so bare ``cupcheck`` and ``--help`` import none of them (nor numpy).
Every error is one line on stderr, ``cupcheck <command>: error: <what>``, with exit status 2 for
bad input, whether argparse finds it (an unknown choice, a value that is not a number, a missing
required option) or the command does (a ``ValueError`` whose message names the field and its
allowed range); a solver that fails (``RuntimeError``) prints where and why and exits 1.
``--help`` prints the full usage as usual; bare ``cupcheck`` prints the command list and exits 0
(nothing was asked, nothing went wrong); ``--version`` prints the version. Ctrl-C at any moment is
one line and exit status 130. Warnings of the libraries underneath (numpy, scipy, joblib, dask),
in this process and in its workers, never reach the user: what a user must know, cupcheck says
itself, as a note or in the output's provenance.
"""

from __future__ import annotations

import argparse
import atexit
import errno
import importlib
import os
import signal
import sys
import warnings
from collections.abc import Iterable, Sequence
from typing import NoReturn

#: errno values that mean an output could not be written
_WRITE_ERRORS = {errno.ENOSPC, errno.EROFS, errno.EACCES, errno.EFBIG, errno.EDQUOT, errno.EPERM}
#: command -> (its module, its one-line help), in the order `cupcheck --help` lists them
COMMANDS: dict[str, tuple[str, str]] = {
    "example": ("validation.commands.example",
                "main job: cup A FEM stiffness -> lifetime against pull force on pmma-1.89 (CSV and PNG)"),
    "lifetime": ("validation.commands.lifetime",
                 "lifetime of a suction cup under pull forces (reduced leakage model, eqs 3-24)"),
    "paper": ("validation.commands.paper",
              "draw the paper's calculated figures: FEM-fed beside the paper's inputs, its stated numbers marked"),
    "render": ("validation.commands.render",
               "3D view (cut-away, footprint from below, squeeze GIF) of a stiffness run's fields file"),
    "run": ("validation.commands.run", "run a scene file: the curves, lifetimes and figures it asks for (cached)"),
    "stiffness": ("validation.commands.stiffness",
                  "FEM stiffness curve F0(h), r_c, l, V of cup A, B or your own design (CSV + JSON sidecar)"),
    "suction": ("validation.commands.suction",
                "FEM response to the cavity suction on a (u, dp) grid, for lifetime --route coupled (JSON)"),
    "sweep": ("validation.commands.sweep",
              "many cup designs on dask.distributed: stiffness, Appendix A ratio, lifetimes (Parquet, CSV, maps)"),
    "uc": ("validation.commands.uc",
           "critical gap u_c(p) of a rough surface (Persson theory; presets, PSD or line scan)"),
    "validate": ("validation.commands.validate",
                 "cross-check report: Appendix A, cone laws, lifetimes, speed-accuracy, extremes, the paper's "
                 "numbers, Coulomb friction, the fem route by contact law (CSV, MD, PNG, JSON)"),
}


class OneLineParser(argparse.ArgumentParser):
    """An `argparse.ArgumentParser` whose errors are one line (no usage block) and exit 2.

    `add_subparsers` makes the subcommands' parsers of the same class, so the line names the
    subcommand: ``cupcheck stiffness: error: argument --cup: invalid choice: 'C' (choose from 'A', 'B')``.
    """

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {_one_line(message)}\n")


def version() -> str:
    """The installed cupcheck's version (the package metadata), or the source tree's."""
    from importlib.metadata import PackageNotFoundError, version as installed

    try:
        return installed("cupcheck")
    except PackageNotFoundError:
        return "unknown (not installed)"


class _VersionAction(argparse.Action):
    """``--version``: the version is looked up only when asked (the package metadata is slow to import)."""

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS,
                 default: str = argparse.SUPPRESS, help: str = "show program's version number and exit"):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None) -> NoReturn:
        print(f"cupcheck {version()}")
        parser.exit()


def build_parser(commands: Iterable[str] | None = None) -> argparse.ArgumentParser:
    """The `cupcheck` parser with the full parsers (the command's module imported, its options
    added) of `commands` (None: of every command); none given, every command is listed by its help
    line alone (bare ``cupcheck``, ``--help``, an unknown command)."""
    parser = OneLineParser(
        prog="cupcheck",
        description="Suction-cup cross-checks: axisymmetric FEM stiffness and the Tiwari-Persson "
                    "leakage model (Soft Matter 2019, arXiv:1906.01459). SI units inside; every "
                    "option names its unit.")
    parser.add_argument("--version", action=_VersionAction)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    full = set(COMMANDS if commands is None else commands)
    for name, (module_name, line) in COMMANDS.items():
        if name not in full:
            if not full:
                sub.add_parser(name, help=line)
            continue
        module = importlib.import_module(module_name)
        p = sub.add_parser(name, help=line, description=module.__doc__,
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        module.add_arguments(p)
        p.set_defaults(_run=module.run, _parser=p)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one subcommand; return its exit status (argparse errors and --help raise SystemExit).
    From the command line (argv None) a Ctrl-C that arrives after the command has returned leaves
    the command's status: its outputs are complete, so the interpreter's exit is not a run to report
    as interrupted. Until the last exit handler it ends the process at once; after it (registered
    first, it runs last) it is ignored, because the interpreter's finalization resets a Python
    handler to the default, death by SIGINT, but keeps an ignored signal ignored."""
    if argv is None:
        atexit.register(signal.signal, signal.SIGINT, signal.SIG_IGN)
    try:
        os.environ.setdefault("PYTHONWARNINGS", "ignore")   # the workers' library warnings: not for the terminal
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")              # nor this process's
            status = _main(argv)
    except KeyboardInterrupt:                # during start-up or while a command was reporting
        status = _interrupted("cupcheck")
    if argv is None and signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
        signal.signal(signal.SIGINT, lambda *_: _exit_now(status))
    return status


def _exit_now(status: int) -> None:
    """Leave with `status`, skipping the interpreter's finalization (the run is over)."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(status)


def _interrupted(who: str) -> int:
    print(f"{who}: interrupted", file=sys.stderr)
    return 130


def _main(argv: Sequence[str] | None) -> int:
    given = list(sys.argv[1:] if argv is None else argv)
    # the command is the first word that is not an option (`cupcheck` itself takes no values)
    invoked = next((a for a in given if not a.startswith("-")), None)
    parser = build_parser([invoked] if invoked in COMMANDS else [])
    if not given:                            # bare `cupcheck`: what it can do
        parser.print_help()
        return 0
    args, unknown = parser.parse_known_args(given)
    if unknown:                              # said by the subcommand, not by `cupcheck`
        args._parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    if hasattr(signal, "SIGXFSZ"):           # a file-size limit: an OSError to report, not a kill
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    try:
        from validation.output import check_option_values
        check_option_values(given)
        return int(args._run(args) or 0)
    except OSError as exc:                   # a full disk, a read-only directory, a size limit
        where = f" ('{exc.filename}')" if exc.filename else ""
        what = "cannot write the output: " if exc.errno in _WRITE_ERRORS else ""
        print(_one_line(f"cupcheck {args.command}: failed: {what}{exc.strerror or exc}{where}"), file=sys.stderr)
        return 1
    except ValueError as exc:
        print(f"cupcheck {args.command}: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except RuntimeError as exc:
        print(f"cupcheck {args.command}: failed: {_one_line(str(exc))}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return _interrupted(f"cupcheck {args.command}")


def _one_line(message: str) -> str:
    """The message on one line, its control characters (a terminal escape in a file name the user
    gave, say) shown escaped instead of acting on the terminal."""
    text = " ".join(line.strip() for line in str(message).splitlines() if line.strip())
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


if __name__ == "__main__":
    sys.exit(main())
