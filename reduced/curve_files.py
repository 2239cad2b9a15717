"""The stiffness curve's files: a plain CSV table and its JSON sidecar, written and read in one place.

The CSV names every unit in its column names (``u_mm,h_mm,F0_N,r_c_mm,l_mm,V_mm3``; readable by
pandas.read_csv and numpy.genfromtxt as they are); the sidecar of the same name (``curve.json``)
holds the provenance (key ``provenance``: the written record, among it the cup design and the
contact law, `reduced.design`) and, optionally, the contact-pressure profile of every sample as
the FEM writes them (``steps.pressure_r_mm[i]``, ``steps.pressure_kPa[i]``). `read_profiles_csv`
reads a measured or user-made profile table (``u_mm,r_mm,p_kPa``, one row per point).

Arrays pass in and out in SI units under the curve's field names (`reduced.stiffness_curve`);
each file appears atomically (written to a temporary file and renamed).
"""

from __future__ import annotations

import json
import os
import secrets
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from reduced.design import DESIGN_KEYS
from reduced.profile_leak import ContactProfile

__all__ = ["CSV_COLUMNS", "OPTIONAL_COLUMNS", "write_curve_csv", "read_curve_csv", "read_profiles_csv",
           "profiles_from_lists", "profiles_to_lists"]

#: CSV column name -> (curve field, factor from the CSV unit to SI)
CSV_COLUMNS: dict[str, tuple[str, float]] = {
    "u_mm": ("u_m", 1e-3),
    "h_mm": ("h_m", 1e-3),
    "F0_N": ("F0_N", 1.0),
    "r_c_mm": ("r_c_m", 1e-3),
    "l_mm": ("l_m", 1e-3),
    "V_mm3": ("V_m3", 1e-9),
}
#: the curve's optional fields (columns a measured curve may lack)
OPTIONAL_COLUMNS = ("r_c_m", "l_m", "V_m3")
_PROVENANCE_TAG = "# provenance:"       # the former in-CSV form, still read


def write_curve_csv(path: str | os.PathLike, arrays: Mapping[str, np.ndarray | None], h1_m: float,
                    provenance: Mapping[str, Any], profiles=None, sidecar: bool = True) -> Path:
    """Write the curve's `arrays` (SI, by field name: u_m, F0_N and the optional columns, None where
    absent) as the CSV at `path` and, with `sidecar`, the provenance, h1 and profiles to
    ``path.with_suffix('.json')``."""
    u = np.asarray(arrays["u_m"])
    cols = {"u_mm": u * 1e3, "h_mm": (h1_m - u) * 1e3, "F0_N": arrays["F0_N"]}
    for csv_name, (name, factor) in CSV_COLUMNS.items():
        if name in OPTIONAL_COLUMNS and arrays.get(name) is not None:
            cols[csv_name] = arrays[name] / factor
    table = np.column_stack(list(cols.values()))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if sidecar:
        data: dict[str, Any] = {"provenance": provenance, "h1_mm": 1e3 * h1_m}
        if profiles is not None:
            data["steps"] = profiles_to_lists(profiles)
        text = json.dumps(data, indent=1, sort_keys=True, default=str) + "\n"
        _atomic_write(path.with_suffix(".json"), lambda f: f.write(text))

    def write_table(f) -> None:
        f.write(",".join(cols) + "\n")
        np.savetxt(f, table, delimiter=",", fmt="%.10g")

    _atomic_write(path, write_table)
    return path


def read_curve_csv(path: str | os.PathLike, h1_m: float | None = None) -> dict[str, Any]:
    """The fields of a curve written by `write_curve_csv`, or of a measured one with at least
    ``u_mm,F0_N``: the SI arrays by field name, ``h1_m``, ``provenance`` and ``profiles``.

    h1 is taken from the `h_mm` column (h1 = u + h) when present; otherwise `h1_m` must be given
    (the undeformed height of the cup the curve was measured on). The provenance comes from the
    sidecar when there is one (or from a ``# provenance:`` line, the former format).
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"stiffness: no such file '{path}'")
    provenance: dict[str, Any] = {}
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except UnicodeDecodeError:
        raise ValueError(f"stiffness: '{path}' is not a UTF-8 text file") from None
    body = []
    for line in lines:
        if line.startswith(_PROVENANCE_TAG):
            provenance = json.loads(line[len(_PROVENANCE_TAG):])
        elif line.strip() and not line.startswith("#"):
            body.append(line)
    if not body:
        raise ValueError(f"stiffness: '{path}' has no header line")
    header = [c.strip() for c in body[0].split(",")]
    unknown = [c for c in header if c not in CSV_COLUMNS]
    if unknown:
        raise ValueError(f"stiffness: unknown column(s) {unknown} in '{path}'; "
                         f"allowed: {', '.join(CSV_COLUMNS)}")
    for required in ("u_mm", "F0_N"):
        if required not in header:
            raise ValueError(f"stiffness: '{path}' lacks the required column '{required}'")
    if len(body) < 2:                    # (numpy would warn on a header alone)
        raise ValueError(f"stiffness: '{path}' has no rows; a stiffness curve needs at least 2 samples")
    try:
        data = np.loadtxt(body[1:], delimiter=",", ndmin=2)
    except ValueError as exc:
        raise ValueError(f"stiffness: '{path}' has a non-numeric entry ({exc})") from None
    if data.shape[1] != len(header):
        raise ValueError(f"stiffness: '{path}' rows have {data.shape[1]} fields, header {len(header)}")
    si = {CSV_COLUMNS[c][0]: data[:, i] * CSV_COLUMNS[c][1] for i, c in enumerate(header)}
    if "h_m" in si:
        h1 = si["u_m"] + si.pop("h_m")
        if np.ptp(h1) > 1e-6 * max(abs(h1.mean()), 1e-12) + 1e-9:
            raise ValueError(f"stiffness: '{path}': u_mm + h_mm is not constant (h1 varies by "
                             f"{1e3 * np.ptp(h1):.3g} mm)")
        h1_csv = float(h1.mean())
        if h1_m is not None and abs(h1_m - h1_csv) > 1e-6:
            raise ValueError(f"h1_mm: given {1e3 * h1_m:.6g} mm but '{path}' implies {1e3 * h1_csv:.6g} mm")
        h1_m = h1_csv
    if h1_m is None:
        raise ValueError(f"h1_mm: '{path}' has no h_mm column; give the cup's undeformed height")
    side = _sidecar(path)
    provenance = side.get("provenance") or provenance
    provenance.setdefault("source", f"csv:{path.name}")
    steps = side.get("steps", {})
    profiles = None
    if "pressure_r_mm" in steps and "pressure_kPa" in steps:
        try:
            profiles = profiles_from_lists(steps["pressure_r_mm"], steps["pressure_kPa"])
        except ValueError as exc:
            raise ValueError(f"stiffness: the sidecar '{path.with_suffix('.json')}': steps.{exc}") from None
    return {**si, "h1_m": h1_m, "provenance": provenance, "profiles": profiles}


def _sidecar(csv_path: Path) -> dict[str, Any]:
    """The curve's JSON sidecar (``provenance``, optionally ``steps`` with the profiles), {} without one."""
    side = csv_path.with_suffix(".json")
    if not side.is_file():
        return {}
    try:
        data = json.loads(side.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"stiffness: cannot parse the sidecar '{side}': {exc}") from None
    if not isinstance(data, Mapping) or not isinstance(data.get("provenance"), Mapping):
        raise ValueError(f"stiffness: the sidecar '{side}' has no 'provenance' table")
    wrong = _sidecar_type_error(data)
    if wrong:
        raise ValueError(f"stiffness: the sidecar '{side}': {wrong}")
    return {**data, "provenance": dict(data["provenance"])}


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _sidecar_type_error(data: Mapping) -> str:
    """What in a sidecar has the wrong type ('' if nothing): the provenance keys the curve reads
    (geometry, contact, friction, source) and the profiles of ``steps``."""
    prov = data["provenance"]
    geometry = prov.get("geometry")
    if geometry is not None and not isinstance(geometry, Mapping):
        return f"provenance.geometry: expected a table, got {type(geometry).__name__}"
    for key in DESIGN_KEYS:
        if isinstance(geometry, Mapping) and key in geometry and not _is_number(geometry[key]):
            return f"provenance.geometry.{key}: expected a number, got {geometry[key]!r:.40}"
    for key, ok, what in (("contact", lambda v: v is None or isinstance(v, str), "a string"),
                          ("friction", _is_number, "a number"),
                          ("source", lambda v: v is None or isinstance(v, str), "a string")):
        if key in prov and not ok(prov[key]):
            return f"provenance.{key}: expected {what}, got {prov[key]!r:.40}"
    steps = data.get("steps", {})
    if not isinstance(steps, Mapping):
        return f"steps: expected a table, got {type(steps).__name__}"
    for key in ("pressure_r_mm", "pressure_kPa"):
        rows = steps.get(key, [])
        if not isinstance(rows, list) or not all(isinstance(r, list) and all(map(_is_number, r)) for r in rows):
            return f"steps.{key}: expected one list of numbers per sample"
    return ""


def profiles_from_lists(r_mm: list, p_kPa: list) -> tuple[ContactProfile | None, ...]:
    """Profiles from per-sample lists of radii [mm] and pressures [kPa] (the FEM sidecar's form);
    points at the same radius are merged (the largest pressure), fewer than 2 points is None."""
    out: list[ContactProfile | None] = []
    for i, (r, p) in enumerate(zip(r_mm, p_kPa)):
        r, p = np.asarray(r, dtype=float) * 1e-3, np.asarray(p, dtype=float) * 1e3
        if r.shape != p.shape:
            raise ValueError(f"pressure_kPa[{i}]: {p.size} pressures for {r.size} radii")
        radii, inverse = np.unique(r, return_inverse=True)
        merged = np.zeros(radii.size)
        np.maximum.at(merged, inverse, p)
        out.append(ContactProfile(radii, merged) if radii.size >= 2 and merged.max() > 0 else None)
    return tuple(out)


def profiles_to_lists(profiles) -> dict[str, list]:
    """The sidecar form of `profiles`: ``pressure_r_mm`` and ``pressure_kPa``, one list per sample."""
    return {"pressure_r_mm": [[] if p is None else (p.r_m * 1e3).tolist() for p in profiles],
            "pressure_kPa": [[] if p is None else (p.p_Pa * 1e-3).tolist() for p in profiles]}


def read_profiles_csv(path: str | os.PathLike, u_m: np.ndarray) -> tuple[ContactProfile | None, ...]:
    """Contact-pressure profiles from a long CSV ``u_mm,r_mm,p_kPa`` (one row per point), one per
    displacement of `u_m` (each u_mm must be one of the curve's samples, to 1e-6 mm)."""
    table = np.genfromtxt(path, delimiter=",", names=True)
    if table.dtype.names is None or set(table.dtype.names) != {"u_mm", "r_mm", "p_kPa"}:
        raise ValueError(f"profiles: '{path}' must have exactly the columns u_mm, r_mm, p_kPa")
    rows = np.atleast_1d(table)
    u_mm = 1e3 * np.asarray(u_m)
    which = np.array([int(np.argmin(np.abs(u_mm - u))) for u in rows["u_mm"]])
    off = np.abs(u_mm[which] - rows["u_mm"]) > 1e-6
    if off.any():
        raise ValueError(f"profiles: u_mm = {rows['u_mm'][off][0]:g} in '{path}' is not a sample of the curve")
    r_mm = [np.sort(rows["r_mm"][which == k]) for k in range(u_mm.size)]
    p_kPa = [rows["p_kPa"][which == k][np.argsort(rows["r_mm"][which == k])] for k in range(u_mm.size)]
    return profiles_from_lists(r_mm, p_kPa)


def _atomic_write(path: Path, write) -> None:
    """Write through `write(file)` to a unique sibling and rename it onto `path`."""
    # created with the normal (umask) permissions, unlike mkstemp's 0600
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
    try:
        with open(tmp, "x") as f:
            write(f)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
