"""Check the README's numbers against fresh runs of the commands that print them.

The README marks each number it quotes from a run with an HTML comment (invisible on the rendered
page), so nothing here guesses where a number comes from:

    <!-- check-command NAME: SHELL COMMAND -->   a command, run once in a fresh directory
    <!-- check-command NAME: block -->           the fenced code block right after the comment
    <!-- check-command NAME: block && COMMAND -->  ... and then COMMAND
    <!-- check NAME: VALUE from csv FILE COLUMN where KEY=X -->
    <!-- check NAME: VALUE from stdout /REGEX/ -->

A command runs in bash in an empty temporary directory, with `cupcheck` meaning this checkout's
command line (`python -m validation.cli`, this repository first on PYTHONPATH) and `python` this
interpreter; ``{repo}`` is the repository. A `check` reads the number from the command's CSV (the
row whose KEY equals X) or from its standard output (the regex's first group, searched line by
line) and compares it to VALUE, the README's digits: the fresh number printed with as many
decimals as VALUE has must be VALUE. VALUE must also appear in the README's text just above the
comment (the lines since the previous blank line, or the code block it follows), so that the
comment and the prose cannot drift apart.

Timings and the tables of the benchmarks (`benchmarks/`: routes, friction, scenes, sweeps, the
Speed section) are not checked: they are measurements of a machine, reproduced by the benchmark
each names.

Prints a table (line, command, README value, fresh value, ok) and exits 0 if every number
matches, 1 on a mismatch or a command that fails, 2 on a malformed annotation.

    python scripts/check_readme.py                     # every command the README annotates
    python scripts/check_readme.py --only main design  # a subset
"""

from __future__ import annotations

import argparse
import csv
import os
import re
import shlex
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
_COMMAND = re.compile(r"<!--\s*check-command\s+([\w-]+):\s*(.*?)\s*-->")
_CHECK = re.compile(r"<!--\s*check\s+([\w-]+):\s*(\S+)\s+from\s+(.*?)\s*-->")
_CSV = re.compile(r"csv\s+(\S+)\s+(\S+)\s+where\s+(\w+)=(\S+)$")
_STDOUT = re.compile(r"stdout\s+/(.*)/$")
_COMMENT = re.compile(r"<!--.*?-->", re.S)
_NUMBER = re.compile(r"[-+]?\d+(\.\d+)?")
#: how far above its comment a value must appear in the README's text (a paragraph, a code block)
_CONTEXT_LINES = 15


@dataclass(frozen=True)
class Command:
    """A command whose output the README quotes: its name, bash text and README line."""

    name: str
    script: str
    line: int


@dataclass(frozen=True)
class Check:
    """One quoted number: the command it comes from, the README's digits, where to read it."""

    name: str
    value: str
    source: str
    line: int


class AnnotationError(ValueError):
    """A malformed or inconsistent annotation (README line in the message)."""


def parse(text: str) -> tuple[dict[str, Command], list[Check]]:
    """The commands and checks annotated in the README `text`; AnnotationError if one is malformed,
    names an unknown command, or quotes a value the text above it does not show."""
    lines = text.splitlines()
    commands: dict[str, Command] = {}
    checks: list[Check] = []
    for i, line in enumerate(lines):
        for m in _COMMAND.finditer(line):
            name, script = m.group(1), m.group(2)
            if name in commands:
                raise AnnotationError(f"README line {i + 1}: command '{name}' defined twice")
            if script == "block" or script.startswith("block && "):
                script = _next_block(lines, i) + "\n" + script[len("block && "):]
            commands[name] = Command(name, script, i + 1)
        for m in _CHECK.finditer(line):
            name, value, source = m.groups()
            if not _NUMBER.fullmatch(value):
                raise AnnotationError(f"README line {i + 1}: '{value}' is not a number")
            if not (_CSV.match(source) or _STDOUT.match(source)):
                raise AnnotationError(f"README line {i + 1}: cannot read 'from {source}' (csv FILE COLUMN "
                                      f"where KEY=X, or stdout /REGEX/)")
            above = _COMMENT.sub("", "\n".join([*_paragraph_above(lines, i), line[:m.start()]]))
            if not re.search(rf"(?<![\d.]){re.escape(value)}(?![\d])", above):
                raise AnnotationError(f"README line {i + 1}: the value {value} is not in the text above "
                                      f"its comment")
            checks.append(Check(name, value, source, i + 1))
    for c in checks:
        if c.name not in commands:
            raise AnnotationError(f"README line {c.line}: no check-command '{c.name}'")
    return commands, checks


def _next_block(lines: list[str], i: int) -> str:
    """The fenced code block that starts on the line after line i."""
    j = i + 1
    if j >= len(lines) or not lines[j].startswith("```"):
        raise AnnotationError(f"README line {i + 1}: 'block' must come right before a ``` code block")
    end = next((k for k in range(j + 1, len(lines)) if lines[k].startswith("```")), None)
    if end is None:
        raise AnnotationError(f"README line {j + 1}: the code block is not closed")
    return "\n".join(lines[j + 1:end])


def _paragraph_above(lines: list[str], i: int) -> list[str]:
    """The text a value comment refers to: the lines above line i up to a blank line (a code
    block counts whole), at most _CONTEXT_LINES."""
    out: list[str] = []
    in_block = False
    for k in range(i - 1, max(-1, i - 1 - _CONTEXT_LINES), -1):
        if lines[k].startswith("```"):
            in_block = not in_block
        elif not lines[k].strip() and not in_block:
            break
        out.append(lines[k])
    return out[::-1]


def run_command(command: Command, work: Path, python: str) -> tuple[int, str, str]:
    """Run a command in bash in `work`: (exit status, stdout, stderr)."""
    prelude = (f'cupcheck() {{ {shlex.quote(python)} -m validation.cli "$@"; }}\n'
               f'python() {{ {shlex.quote(python)} "$@"; }}\n'
               "set -e\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")])),
           "OMP_NUM_THREADS": os.environ.get("OMP_NUM_THREADS", "1"), "MPLBACKEND": "Agg",
           "CUPCHECK_CACHE_DIR": str(work / ".cache")}
    script = prelude + command.script.replace("{repo}", shlex.quote(str(REPO)))
    done = subprocess.run(["bash", "-c", script], cwd=work, env=env, capture_output=True, text=True)
    return done.returncode, done.stdout, done.stderr


def fresh_value(check: Check, work: Path, stdout: str) -> float:
    """The number `check` reads from its command's output (ValueError if it is not there)."""
    m = _CSV.match(check.source)
    if m:
        path, column, key, want = m.groups()
        with open(work / path, newline="") as f:
            for row in csv.DictReader(f):
                if key in row and _same(row[key], want):
                    return float(row[column])
        raise ValueError(f"{path}: no row with {key} = {want}")
    pattern = re.compile(_STDOUT.match(check.source).group(1))
    for line in stdout.splitlines():
        hit = pattern.search(line)
        if hit:
            return float(hit.group(1))
    raise ValueError(f"no line of the output matches /{pattern.pattern}/")


def _same(text: str, want: str) -> bool:
    try:
        return float(text) == float(want)
    except ValueError:
        return text == want


def printed(fresh: float, readme: str) -> str:
    """`fresh` with as many decimals as the README's digits `readme`."""
    decimals = len(readme.split(".")[1]) if "." in readme else 0
    return f"{fresh:.{decimals}f}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--readme", type=Path, default=REPO / "README.md", help="the file to check (default README.md)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="run only these commands")
    parser.add_argument("--list", action="store_true", help="list the annotated commands and exit")
    parser.add_argument("--python", default=sys.executable, help="the interpreter to run (default: this one)")
    args = parser.parse_args(argv)
    try:
        commands, checks = parse(args.readme.read_text(encoding="utf-8"))
        unknown = sorted(set(args.only or ()) - set(commands))
        if unknown:
            raise AnnotationError(f"--only: no check-command {', '.join(unknown)} (known: {', '.join(commands)})")
    except (AnnotationError, OSError) as exc:
        print(f"check_readme: error: {exc}", file=sys.stderr)
        return 2
    if args.list:
        for c in commands.values():
            n = sum(ch.name == c.name for ch in checks)
            print(f"{c.name:12} line {c.line:4}  {n} numbers  {c.script.splitlines()[0]}")
        return 0
    chosen = [c for c in commands.values() if not args.only or c.name in args.only]
    rows: list[tuple[str, ...]] = []
    bad = 0
    for command in chosen:
        with tempfile.TemporaryDirectory(prefix=f"check_readme_{command.name}_") as tmp:
            work = Path(tmp)
            code, stdout, stderr = run_command(command, work, args.python)
            for check in (c for c in checks if c.name == command.name):
                where = f"{args.readme.name}:{check.line}"
                if code != 0:
                    last = stderr.strip().splitlines()[-1] if stderr.strip() else f"exit {code}"
                    rows.append((where, command.name, check.value, f"failed: {last}", "FAIL"))
                    bad += 1
                    continue
                try:
                    fresh = fresh_value(check, work, stdout)
                except (OSError, ValueError, KeyError) as exc:
                    rows.append((where, command.name, check.value, f"not found: {exc}", "FAIL"))
                    bad += 1
                    continue
                ok = printed(fresh, check.value) == check.value
                bad += not ok
                rows.append((where, command.name, check.value, f"{printed(fresh, check.value)} ({fresh:.6g})",
                             "ok" if ok else "MISMATCH"))
    header = ("README line", "command", "README value", "fresh value", "ok")
    widths = [max(len(r[k]) for r in [header, *rows]) for k in range(len(header))]
    for r in [header, *rows]:
        print("  ".join(cell.ljust(w) for cell, w in zip(r, widths)).rstrip())
    print(f"{len(rows) - bad} of {len(rows)} numbers match" + (f"; {bad} do not" if bad else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
