"""Output paths the commands check before any work."""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["check_writable"]


def check_writable(path: Path, name: str, what: str = "") -> None:
    """Refuse, before the solve, an output path that is a directory or whose directory can be
    neither found nor created (the writers create missing parent directories)."""
    label = f"{what} '{path}'" if what else f"'{path}'"
    if path.is_dir():
        raise ValueError(f"{name}: {label} is a directory; give a file name")
    ancestor = path.parent
    while not ancestor.exists() and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise ValueError(f"{name}: cannot create the directory of {label}: '{ancestor}' is a file")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise ValueError(f"{name}: cannot write {label}: no write permission in '{ancestor}'")
