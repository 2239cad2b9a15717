"""`cupcheck` command line: one subcommand per module in `validation.commands`.

Each command module defines ``NAME``, ``HELP``, ``add_arguments(parser)`` and ``run(args) -> int``.
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
import errno
import importlib
import os
import signal
import sys
import warnings
from collections.abc import Sequence
from typing import NoReturn

#: errno values that mean an output could not be written
_WRITE_ERRORS = {errno.ENOSPC, errno.EROFS, errno.EACCES, errno.EFBIG, errno.EDQUOT, errno.EPERM}
#: subcommand modules, in the order `cupcheck --help` lists them
COMMANDS = ("example", "lifetime", "paper", "render", "run", "stiffness", "suction", "sweep", "uc", "validate")


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


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="cupcheck",
        description="Suction-cup cross-checks: axisymmetric FEM stiffness and the Tiwari-Persson "
                    "leakage model (Soft Matter 2019, arXiv:1906.01459). SI units inside; every "
                    "option names its unit.")
    parser.add_argument("--version", action="version", version=f"cupcheck {version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"validation.commands.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"validation.commands.{name}":
                raise
            continue
        p = sub.add_parser(module.NAME, help=module.HELP, description=module.__doc__,
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        module.add_arguments(p)
        p.set_defaults(_run=module.run, _parser=p)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one subcommand; return its exit status (argparse errors and --help raise SystemExit)."""
    try:
        os.environ.setdefault("PYTHONWARNINGS", "ignore")   # the workers' library warnings: not for the terminal
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")              # nor this process's
            return _main(argv)
    except KeyboardInterrupt:                # during start-up or while a command was reporting
        return _interrupted("cupcheck")


def _interrupted(who: str) -> int:
    print(f"{who}: interrupted", file=sys.stderr)
    return 130


def _main(argv: Sequence[str] | None) -> int:
    parser = build_parser()
    given = list(sys.argv[1:] if argv is None else argv)
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
