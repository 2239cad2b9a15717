"""Output paths refused before any work: special files, inputs, directories cupcheck did not
write, two outputs that are one file, empty values."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable, Mapping
from pathlib import Path

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
