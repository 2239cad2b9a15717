"""Writing that never leaves half-written results: a temporary beside the output, renamed over it
on success, under a lock that keeps two runs off one output."""

from __future__ import annotations

import os
import re
import secrets
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .paths import MANIFEST, _check_path, _real
from .provenance import software_versions

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
