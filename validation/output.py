"""Output that never leaves half-written results behind, and progress on a terminal."""

from __future__ import annotations

import csv
import os
import platform
import secrets
import shutil
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

#: the packages whose versions every output's provenance records
_PACKAGES = ("cupcheck", "numpy", "scipy", "scikit-fem", "meshio")


def software_versions() -> dict[str, str]:
    """Versions of Python and of the packages the FEM result depends on."""
    versions = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return versions


#: progress callback used by long computations: progress(fraction_done in [0, 1], message)
Progress = Callable[[float, str], None]


@contextmanager
def exclusive(out: Path) -> Iterator[None]:
    """Hold the output `out` for this run: a second run writing the same output is refused at
    once (an OS file lock, `filelock`, released even when the process is killed), so two runs
    never interleave their files. The lock file ``.<name>.lock`` is removed on release."""
    from filelock import FileLock, Timeout

    lock_path = out.parent / f".{out.name}.lock"
    lock = FileLock(str(lock_path), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        raise ValueError(f"out: '{out}' is being written by another cupcheck run; wait for it or "
                         f"choose another output") from None
    try:
        yield
    finally:
        lock.release()
        lock_path.unlink(missing_ok=True)


@contextmanager
def atomic_directory(out: str | os.PathLike) -> Iterator[Path]:
    """Yield a fresh temporary directory next to `out`; on success its files move into `out`.

    On any exception nothing is written to `out` and the temporary directory is removed, so a
    failed or interrupted run leaves no half-written output; each file arrives whole (a rename).
    """
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with exclusive(out):
        tmp = Path(tempfile.mkdtemp(dir=out.parent, prefix=f".{out.name}.", suffix=".tmp"))
        try:
            yield tmp
            out.mkdir(parents=True, exist_ok=True)
            for item in sorted(tmp.rglob("*")):
                target = out / item.relative_to(tmp)
                if item.is_dir():
                    target.mkdir(parents=True, exist_ok=True)
                else:
                    os.replace(item, target)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


@contextmanager
def atomic_file(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path next to `path`; on success it is renamed to `path`."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with exclusive(path):
        # a unique sibling name, created with the normal (umask) permissions, unlike mkstemp's 0600
        tmp = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp{path.suffix}")
        tmp.touch(exist_ok=False)
        try:
            yield tmp
            os.replace(tmp, path)
        finally:
            Path(tmp).unlink(missing_ok=True)


#: columns whose infinite values mean something (an infinite lifetime: sealed or beyond the
#: horizon; an unbounded strip pressure: a line contact); NaN is refused everywhere
INFINITE_OK = ("lifetime_s", "p_Pa")


def check_finite(name: str, values, stage: str, infinite_ok: bool = False) -> None:
    """The one guard every public output passes: no NaN (and no inf unless it means something);
    a RuntimeError naming the column and the stage that produced it."""
    import numpy as np

    arr = np.asarray(values, dtype=object)
    numbers = np.array([float(v) for v in arr.ravel() if isinstance(v, (int, float)) and not isinstance(v, bool)])
    bad = np.isnan(numbers) | (np.isinf(numbers) & (not infinite_ok))
    if bad.any():
        raise RuntimeError(f"{stage}: column {name} has {int(bad.sum())} non-finite value(s) "
                           f"({numbers[bad][0]}): refusing to write it")


def write_table(path: str | os.PathLike, columns: dict[str, object], stage: str = "output") -> Path:
    """A plain CSV: one header line (units in the names), then rows; numbers as %.10g, text quoted
    only where it must be. No comment lines, so pandas.read_csv and numpy.genfromtxt read it as is.

    `columns` maps each name to a sequence (all of one length) or to one value repeated (a label).
    Every column passes `check_finite` (`stage` names what produced it).
    """
    for name, values in columns.items():
        if not isinstance(values, str):
            check_finite(name, [values] if isinstance(values, (int, float)) else values, stage,
                         infinite_ok=name in INFINITE_OK)
    lengths = {len(v) for v in columns.values() if not isinstance(v, (str, int, float))}
    if len(lengths) > 1:
        raise ValueError(f"write_table: columns of different lengths {sorted(lengths)}")
    n = lengths.pop() if lengths else 1
    cells = [[v] * n if isinstance(v, (str, int, float)) else list(v) for v in columns.values()]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for row in zip(*cells):
            w.writerow([x if isinstance(x, str) else f"{float(x):.10g}" for x in row])
    return Path(path)


def terminal_progress(label: str, stream=None, min_interval_s: float = 0.2) -> Progress:
    """A `Progress` callback that redraws one status line on a terminal (stderr by default).

    When the stream is not a terminal (CI, pipes) it prints a plain line at most every ~10 %.
    """
    stream = stream or sys.stderr
    tty = stream.isatty()
    state = {"t": 0.0, "decile": -1}

    def report(fraction: float, message: str) -> None:
        now = time.monotonic()
        fraction = min(max(fraction, 0.0), 1.0)
        if tty:
            if now - state["t"] < min_interval_s and fraction < 1.0:
                return
            state["t"] = now
            end = "\n" if fraction >= 1.0 else ""
            stream.write(f"\r{label}: {100 * fraction:5.1f}% {message}\033[K{end}")
        else:
            decile = int(10 * fraction)
            if decile == state["decile"]:
                return
            state["decile"] = decile
            stream.write(f"{label}: {100 * fraction:5.1f}% {message}\n")
        stream.flush()

    return report
