"""`cupcheck` command line: one subcommand per module in `validation.commands`.

Each command module defines ``NAME``, ``HELP``, ``add_arguments(parser)`` and ``run(args) -> int``.
Bad input (a ``ValueError`` whose message names the field and its allowed range) prints one line
and exits with status 2; a solver that fails (``RuntimeError``) prints where and why and exits 1.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

#: subcommand modules, in the order `cupcheck --help` lists them
COMMANDS = ("example", "lifetime", "stiffness", "uc", "validate")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="cupcheck",
        description="Suction-cup cross-checks: axisymmetric FEM stiffness and the Tiwari-Persson "
                    "leakage model (Soft Matter 2019, arXiv:1906.01459). SI units inside; every "
                    "option names its unit.")
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
        p.set_defaults(_run=module.run)
    return parser




def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except ValueError as exc:
        print(f"cupcheck {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except RuntimeError as exc:
        print(f"cupcheck {args.command}: failed: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"cupcheck {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
