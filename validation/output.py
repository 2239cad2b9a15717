"""Output that never leaves half-written results behind, and progress on a terminal."""

from __future__ import annotations

import csv
import os
import platform
import re
import secrets
import shutil
import stat
import sys
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path

#: the packages whose versions every output's provenance records
_PACKAGES = ("cupcheck", "numpy", "scipy", "scikit-fem", "meshio")


def software_versions() -> dict[str, str]:
    """Versions of Python and of the packages the FEM result depends on."""
    from importlib import metadata      # slow to import: only when a provenance is written

    versions = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return versions


#: progress callback used by long computations: progress(fraction_done in [0, 1], message)
Progress = Callable[[float, str], None]


def _real(path: str | os.PathLike) -> Path:
    """`path` with every symlink resolved (also of a tail that does not exist yet)."""
    return Path(os.path.realpath(os.path.expanduser(os.fspath(path))))


_SPECIAL = ((stat.S_ISCHR, "character device"), (stat.S_ISBLK, "block device"), (stat.S_ISFIFO, "FIFO"),
            (stat.S_ISSOCK, "socket"))


def _check_path(label: str, path: str | os.PathLike, kind: str) -> Path:
    """One output path on its own (`kind`: file, directory or store); its resolved path."""
    shown = os.fspath(path)
    if not shown.strip():
        raise ValueError(f"{label}: the path is empty; give a {'file' if kind == 'file' else 'directory'} name")
    real = _real(path)
    try:
        mode = os.stat(real).st_mode
    except (FileNotFoundError, NotADirectoryError):   # a missing name (or a file on the way: below)
        mode = None
    except OSError as exc:                              # a symlink loop, a name too long, no access
        raise ValueError(f"{label}: cannot use '{shown}': {exc.strerror}") from None
    if mode is not None:
        special = next((name for test, name in _SPECIAL if test(mode)), None)
        if special is not None:
            raise ValueError(f"{label}: '{shown}' is a {special}, not a "
                             f"{'regular file' if kind == 'file' else 'directory'}; cupcheck will not replace it")
        if kind == "file" and stat.S_ISDIR(mode):
            raise ValueError(f"{label}: '{shown}' is a directory; give a file name")
        if kind != "file" and not stat.S_ISDIR(mode):
            raise ValueError(f"{label}: '{shown}' exists and is not a directory")
        if kind == "directory" and not _replaceable(real):
            raise ValueError(f"{label}: '{shown}' holds files cupcheck did not write (it has no "
                             f"{MANIFEST}); a run replaces its output directory as a whole, so give a "
                             f"new or empty directory")
    ancestor = real.parent
    while not ancestor.exists() and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise ValueError(f"{label}: cannot create the directory of '{shown}': '{ancestor}' is not a directory")
    return real


#: the file that lists a directory output's files; a directory holding one is cupcheck's to replace
MANIFEST = "manifest.json"
#: what a directory output written before manifests existed holds (lifetime and validate: a
#: summary; example: the FEM curve's sidecar)
_LEGACY_RECORDS = ("summary.json", "stiffness_fem.json")


def _replaceable(directory: Path) -> bool:
    """An existing directory a run may replace as a whole: empty, or written by cupcheck."""
    names = {p.name for p in directory.iterdir()}
    return not names or any(n in names for n in (MANIFEST, *_LEGACY_RECORDS))


def _inside(path: Path, directory: Path) -> bool:
    return path == directory or directory in path.parents


def check_outputs(files: Mapping[str, object] | None = None, directories: Mapping[str, object] | None = None,
                  inputs: Mapping[str, object] | None = None, stores: Mapping[str, object] | None = None,
                  companions: Mapping[str, tuple[object, str]] | None = None) -> None:
    """Refuse, before any work, outputs that would destroy something (a ValueError naming both).

    Each mapping goes from the name the user wrote (``--out``, ``cup.geometry``) to a path (None:
    not given). `files` are written whole, `directories` replaced as a whole, `stores` added to
    (a sweep). Refused: an empty path; a special file (device, FIFO, socket), also through a
    symlink; a file output that is a directory or a directory that is not one; an existing
    directory cupcheck did not write (no manifest); an output that is an input of the same run
    or holds one; two outputs that are one file (or one inside the other's directory).
    `companions` are files the user did not name (a curve's JSON sidecar beside its CSV), each
    with the key of its JSON kind: an existing file there is replaced only if it is of that kind.
    """
    companions = dict(companions or {})
    files = {**(files or {}), **{label: path for label, (path, _) in companions.items()}}
    outs: list[tuple[str, str, Path, str]] = []
    for kind, given in (("file", files), ("directory", directories), ("store", stores)):
        for label, path in (given or {}).items():
            if path is not None:
                outs.append((label, os.fspath(path), _check_path(label, path, kind), kind))
    for i, (la, pa, ra, ka) in enumerate(outs):
        for lb, pb, rb, kb in outs[i + 1:]:
            if ra == rb or (ka != "file" and _inside(rb, ra)) or (kb != "file" and _inside(ra, rb)):
                raise ValueError(f"{la}: '{pa}' and {lb} '{pb}' are one output; give them different names")
    for label, path in (inputs or {}).items():
        if path is None or not os.fspath(path).strip():
            continue
        real = _real(path)
        for lo, po, ro, ko in outs:
            same = real == ro or (ko == "directory" and _inside(real, ro))
            if not same and real.exists() and ro.exists():
                same = os.path.samefile(real, ro)
            if same:
                where = "is" if real == ro or ko == "file" else "holds"
                raise ValueError(f"{lo}: '{po}' {where} the input {label} '{os.fspath(path)}' of this run; "
                                 f"writing it would destroy the input")
    for label, (path, key) in companions.items():
        if path is not None and _real(path).is_file() and not _json_with(_real(path), key):
            raise ValueError(f"{label}: '{os.fspath(path)}' exists and is not what cupcheck writes there (a JSON "
                             f"object with '{key}'); move it or choose another output name")


def _json_with(path: Path, key: str) -> bool:
    """True if `path` holds a JSON object with `key` (a file cupcheck wrote there before)."""
    import json

    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and key in data


def check_file_names(planned: Mapping[str, Iterable[str]], reserved: Mapping[str, str] | None = None) -> None:
    """Refuse, before any work, two outputs of one run that would write one file (a ValueError
    naming both; one would be lost). `planned` maps each output, as the user named it, to the
    file names it writes in the run's directory; `reserved`, the names the run writes itself
    (``manifest.json``) to what writes them. One output naming a file twice is not a conflict."""
    owner = dict(reserved or {})
    for label, names in planned.items():
        for name in names:
            other = owner.setdefault(name, label)
            if other != label:
                raise ValueError(f"{label}: its file '{name}' is also written by {other}; one would be lost "
                                 f"(give them different names or values)")


#: attributes of a command's arguments that name an input file (label as the user wrote it)
_INPUT_OPTIONS = {"geometry": "--geometry", "mesh": "--mesh", "psd": "--psd", "line_scan": "--line-scan",
                  "uc_table": "--uc-table", "stiffness": "--stiffness", "relaxation": "--relaxation",
                  "suction_table": "--suction-table", "fields": "fields", "scene": "scene", "sweep": "sweep"}
#: values of those options that name no file
_NOT_FILES = ("appendix-a", "none", "default")


def command_inputs(args: object) -> dict[str, object]:
    """The input files a command's parsed arguments name, for `check_outputs` (a stiffness
    curve brings its sidecar)."""
    found: dict[str, object] = {}
    for attr, label in _INPUT_OPTIONS.items():
        value = getattr(args, attr, None)
        if value is None or (isinstance(value, str) and value in _NOT_FILES):
            continue
        found[label] = value
        if attr == "stiffness" and os.fspath(value).strip():
            found["--stiffness's sidecar"] = Path(value).with_suffix(".json")
    return found


def check_option_values(argv: list[str]) -> None:
    """An option given an empty value (``--out ""``, ``--out=``) is refused: an empty path would
    mean the working directory."""
    for i, arg in enumerate(argv):
        if arg.startswith("--") and arg.endswith("=") and len(arg) > 3:
            raise ValueError(f"{arg[:-1]}: the value is empty")
        if arg.startswith("--") and "=" not in arg and i + 1 < len(argv) and not argv[i + 1].strip():
            raise ValueError(f"{arg}: the value is empty")


def _failure_records(path: Path) -> list[Path]:
    """Where a failed run into `path` leaves its record (``<out>.failure.json``)."""
    return [path.with_suffix(".failure.json"), path.with_name(f"{path.name}.failure.json")]


def _remove_stale_failure(path: Path) -> None:
    """A later success removes the record of an earlier failure (only a cupcheck failure record)."""
    import json

    for record in _failure_records(path):
        try:
            data = json.loads(record.read_text())
        except (OSError, ValueError):
            continue
        if isinstance(data, dict) and "error" in data and "residual_history" in data:
            record.unlink(missing_ok=True)


def _temporary_name(out: Path, suffix: str = "") -> Path:
    return out.with_name(f".{out.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp{suffix}")


def _remove_leftovers(out: Path) -> None:
    """Remove the temporaries a killed run writing `out` left (the caller holds `out`'s lock, so
    no live run owns them): ``.<name>.<pid>.<hex>.tmp*`` and ``.<name>.<pid>.<hex>.old``."""
    pattern = re.compile(rf"\.{re.escape(out.name)}\.\d+\.[0-9a-f]{{8}}\.(tmp.*|old)")
    for item in out.parent.iterdir():
        if pattern.fullmatch(item.name):
            if item.is_dir() and not item.is_symlink():
                shutil.rmtree(item, ignore_errors=True)
            else:
                item.unlink(missing_ok=True)


@contextmanager
def _parents(path: Path) -> Iterator[None]:
    """Create `path`'s missing parent directories; remove them again (when empty) on failure, so a
    refused or failed run leaves no empty directories behind."""
    missing = []
    parent = path.parent
    while not parent.exists():
        missing.append(parent)
        parent = parent.parent
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        yield
    except BaseException:
        for d in missing:              # deepest first
            try:
                d.rmdir()
            except OSError:
                break
        raise


@contextmanager
def exclusive(out: Path) -> Iterator[None]:
    """Hold the output `out` for this run: a second run writing the same output (also through a
    symlink: the lock is on the resolved path) is refused at once (an OS file lock, `filelock`,
    released even when the process is killed), so two runs never interleave their files. The
    lock file ``.<name>.lock`` is removed on release."""
    from filelock import FileLock, Timeout

    real = _real(out)
    lock_path = real.parent / f".{real.name}.lock"
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
    """Yield a fresh temporary directory next to `out`; on success it replaces `out` as a whole.

    On any exception nothing is written to `out` and the temporary directory is removed, so a
    failed or interrupted run leaves the previous output or nothing. The new `out` holds exactly
    what the run wrote and a ``manifest.json`` listing it (written here unless the run wrote its
    own), so no file of an earlier run stays beside it; an earlier failure record goes, and so do
    the temporaries of a killed run.
    """
    import json

    label = os.fspath(out)
    real = _check_path("out", out, "directory")
    with _parents(real), exclusive(Path(label)):
        _remove_leftovers(real)
        tmp = _temporary_name(real)
        tmp.mkdir(mode=0o777)            # the umask's permissions, unlike mkdtemp's 0700
        try:
            yield tmp
            manifest = tmp / MANIFEST
            if not manifest.exists():
                listed = sorted(p.relative_to(tmp).as_posix() for p in tmp.rglob("*") if p.is_file())
                manifest.write_text(json.dumps({"files": [{"path": p} for p in listed],
                                                "versions": software_versions()}, indent=1) + "\n")
            if real.exists():
                _check_path("out", label, "directory")      # still cupcheck's (checked under the lock)
                old = real.with_name(tmp.name[:-len(".tmp")] + ".old")
                os.rename(real, old)
                try:
                    os.rename(tmp, real)
                except BaseException:
                    os.rename(old, real)
                    raise
                shutil.rmtree(old, ignore_errors=True)
            else:
                os.rename(tmp, real)
            _remove_stale_failure(real)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


@contextmanager
def atomic_file(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path next to `path`; on success it is renamed to `path` (through a
    symlink: to the file it names). A special file is refused, not replaced."""
    real = _check_path("out", path, "file")
    with _parents(real), exclusive(Path(path)):
        _remove_leftovers(real)
        # a unique sibling name, created with the normal (umask) permissions, unlike mkstemp's 0600
        tmp = _temporary_name(real, real.suffix)
        tmp.touch(exist_ok=False)
        try:
            yield tmp
            os.replace(tmp, real)
            _remove_stale_failure(real)
        finally:
            Path(tmp).unlink(missing_ok=True)


#: columns whose infinite values mean something (an infinite lifetime: sealed or beyond the
#: horizon; an unbounded strip pressure: a line contact; an unbounded leak rate: the gas holds the
#: seal open; the time at which a sealed state is reached); NaN is refused everywhere
INFINITE_OK = ("lifetime_s", "p_Pa", "N_dot_per_s", "Q_w_mm3_per_s", "t_s")


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
