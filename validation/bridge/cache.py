"""One disk cache for every product: `joblib.Memory` keyed by content.

A cached function's key is its code and arguments (joblib hashes them), plus what the caller puts
in: `source_hash` of the packages that compute the product (a code change invalidates exactly its
products) and `file_digest` of every input file the product reads, so that an edited design file
or u_c table is a new key, while the file's path, passed as an ignored argument, is not part of
the key. An entry that cannot be read is recomputed with one line on stderr; a cache that cannot
be written is bypassed likewise.

Where: one cache per user, `user_cache_dir` (``$CUPCHECK_CACHE_DIR`` if set, else the platform's
user cache directory, ``~/.cache/cupcheck`` on Linux or ``$XDG_CACHE_HOME/cupcheck``), one
subdirectory per kind of product; never the working directory, so a read-only one works.
"""

from __future__ import annotations

import hashlib
import os
import sys
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import Any, TypeVar

__all__ = ["Cache", "source_hash", "file_digest", "user_cache_dir", "CACHE_ENV"]

#: the environment variable that moves every cupcheck cache (the --cache-dir options still win)
CACHE_ENV = "CUPCHECK_CACHE_DIR"

F = TypeVar("F", bound=Callable[..., Any])
_ROOT = Path(__file__).resolve().parents[2]


@lru_cache(maxsize=None)
def source_hash(*parts: str) -> str:
    """A hash of the sources of packages or single files, paths relative to the repository
    ("fem", "validation/bridge/coupled", "reduced/suction_table.py")."""
    h = hashlib.sha256()
    for part in parts:
        root = _ROOT / part
        for path in [root] if root.is_file() else sorted(root.rglob("*.py")):
            h.update(path.relative_to(_ROOT).as_posix().encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def user_cache_dir(kind: str | None = None) -> Path:
    """The user's cupcheck cache (`CACHE_ENV`, else platformdirs' user cache directory), or its
    subdirectory for one kind of product ("scenes", "suction", "validate")."""
    from platformdirs import user_cache_path

    root = os.environ.get(CACHE_ENV, "").strip()
    base = Path(root).expanduser() if root else user_cache_path("cupcheck", appauthor=False)
    return base / kind if kind else base


def file_digest(path: str | Path | None) -> str | None:
    """The sha256 of an input file's bytes (None for no file): its part of a cache key."""
    if path is None:
        return None
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


class Cache:
    """`joblib.Memory` in `directory` (None: no disk cache, the functions run as they are)."""

    def __init__(self, directory: str | Path | None):
        self.directory = None if directory is None else Path(directory)
        self._memory = None
        if directory is not None:
            from joblib import Memory
            self._memory = Memory(str(directory), verbose=0)

    def cached(self, func: F, ignore: list[str] | None = None) -> F:
        """`func` through the cache; arguments named in `ignore` are not part of the key."""
        if self._memory is None:
            return func
        memorized = self._memory.cache(func, ignore=ignore)
        name = getattr(func, "__name__", "product")

        def warn(message: str) -> None:      # joblib's own: a traceback over many lines
            first = message.splitlines()[0] if message else ""
            what = "an unreadable entry, recomputed" if first.startswith("Exception while loading") else first
            print(f"cupcheck: cache {self.directory}: {name}: {what}", file=sys.stderr)

        memorized.warn = warn

        def call(*args: Any, **kwargs: Any) -> Any:
            try:
                return memorized(*args, **kwargs)
            except OSError as exc:           # the cache cannot be written: compute without it
                if not str(exc.filename or "").startswith(str(self.directory)):
                    raise
                print(f"cupcheck: cache {self.directory}: not used ({exc.strerror or exc})", file=sys.stderr)
                return func(*args, **kwargs)
        return call  # type: ignore[return-value]
