"""The hand-off between a stiffness source and the reduced model: a `StiffnessCurve`.

A stiffness curve is plain data: the cup spring force F0 (Sec. 3, eq. 7) sampled over the
top-plate displacement u = h1 - h, optionally with what a finite-element model knows better
than the rigid-cone laws -- the inner contact radius r_c(h) (cf. eq. 3), the contact-strip
width l(h) (cf. eq. 5) and the enclosed cavity volume V(h) (cf. eq. 4) -- and its provenance.

It can come from an FEM run, a measured CSV or the Appendix A formula; the reduced model does
not know which. Arrays are SI inside; the CSV is a plain table that names every unit in its
column names (readable by pandas.read_csv and numpy.genfromtxt as they are)::

    u_mm,h_mm,F0_N,r_c_mm,l_mm,V_mm3
    0.0,12.0,0.0,...

Its provenance travels in a JSON sidecar of the same name (``curve.json``, key ``provenance``),
among it the cup design the curve was computed for (``geometry``: r0_mm, r1_mm, alpha_deg,
h1_mm, the thickness profile), which `design` returns; a lifetime takes the cup from there.
An FEM curve also records its interface with the plane (``contact``, ``friction``,
``contact_source``), which `contact` returns.
Optionally the curve carries the contact-pressure profile p(r) of every sample (`profiles`, for
the leak through the profile, `reduced.profile_leak`); the sidecar holds them as the FEM writes
them, ``steps.pressure_r_mm[i]`` and ``steps.pressure_kPa[i]``, and `read_profiles_csv` reads a
measured or user-made one (``u_mm,r_mm,p_kPa``, one row per point).

Interpolation is monotone piecewise-cubic (PCHIP): it never overshoots between samples, so
a monotone measured curve stays monotone. Evaluating outside the sampled range is an error,
not an extrapolation.
"""

from __future__ import annotations

import json
import os
import secrets
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
from scipy.interpolate import PchipInterpolator

from reduced.profile_leak import ContactProfile

__all__ = ["StiffnessCurve", "CSV_COLUMNS", "read_profiles_csv", "profiles_from_lists"]

#: CSV column name -> (dataclass field, factor from the CSV unit to SI)
CSV_COLUMNS: dict[str, tuple[str, float]] = {
    "u_mm": ("u_m", 1e-3),
    "h_mm": ("h_m", 1e-3),
    "F0_N": ("F0_N", 1.0),
    "r_c_mm": ("r_c_m", 1e-3),
    "l_mm": ("l_m", 1e-3),
    "V_mm3": ("V_m3", 1e-9),
}
_OPTIONAL = ("r_c_m", "l_m", "V_m3")
_PROVENANCE_TAG = "# provenance:"       # the former in-CSV form, still read
#: the keys a recorded design must have for the reduced model to use it
DESIGN_KEYS = ("r0_mm", "r1_mm", "alpha_deg", "h1_mm")


@dataclass(frozen=True)
class StiffnessCurve:
    """Cup spring force F0 over the plate displacement u, with optional geometry (SI units).

    Parameters
    ----------
    u_m : strictly increasing plate displacements u = h1 - h [m].
    F0_N : stiffness force F0(u) [N] (eq. 7), measured with p_b = p_a.
    h1_m : undeformed cup height h1 [m], so that h = h1 - u.
    r_c_m, l_m, V_m3 : optional inner contact radius [m], contact-strip width [m] and
        enclosed cavity volume [m^3] at the same samples.
    provenance : free-form description of where the data come from (source, parameters).
    profiles : optional contact-pressure profile per sample (None where nothing touches).
    """

    u_m: np.ndarray
    F0_N: np.ndarray
    h1_m: float
    r_c_m: np.ndarray | None = None
    l_m: np.ndarray | None = None
    V_m3: np.ndarray | None = None
    provenance: Mapping[str, Any] = field(default_factory=dict)
    profiles: tuple[ContactProfile | None, ...] | None = None

    def __post_init__(self) -> None:
        u = _frozen_array(self.u_m, "u_m")
        if u.size < 2:
            raise ValueError(f"u_m: a stiffness curve needs at least 2 samples, got {u.size}")
        if np.any(np.diff(u) <= 0):
            raise ValueError("u_m: displacements must be strictly increasing")
        if not (np.isfinite(self.h1_m) and self.h1_m > 0):
            raise ValueError(f"h1_m: undeformed cup height must be > 0 m, got {self.h1_m}")
        object.__setattr__(self, "u_m", u)
        object.__setattr__(self, "F0_N", _frozen_array(self.F0_N, "F0_N", u.size))
        for name in _OPTIONAL:
            value = getattr(self, name)
            if value is not None:
                arr = _frozen_array(value, name, u.size)
                if np.any(arr < 0):
                    raise ValueError(f"{name}: must be >= 0")
                object.__setattr__(self, name, arr)
        object.__setattr__(self, "provenance", dict(self.provenance))
        if self.profiles is not None:
            if len(self.profiles) != u.size:
                raise ValueError(f"profiles: expected one profile (or None) per sample, {u.size}, "
                                 f"got {len(self.profiles)}")
            object.__setattr__(self, "profiles", tuple(self.profiles))

    # ------------------------------------------------------------------ views
    @property
    def h_m(self) -> np.ndarray:
        """Cup height h = h1 - u at the samples [m]."""
        return self.h1_m - self.u_m

    @property
    def u_range_m(self) -> tuple[float, float]:
        return float(self.u_m[0]), float(self.u_m[-1])

    @property
    def h_range_m(self) -> tuple[float, float]:
        """(smallest, largest) sampled cup height [m]."""
        return float(self.h1_m - self.u_m[-1]), float(self.h1_m - self.u_m[0])

    @property
    def design(self) -> dict[str, Any] | None:
        """The cup design recorded in the provenance (``geometry`` with r0_mm, r1_mm, alpha_deg,
        h1_mm, ...), or None when the curve names none (a measured curve, a user's mesh)."""
        geometry = self.provenance.get("geometry")
        if isinstance(geometry, Mapping) and all(k in geometry for k in DESIGN_KEYS):
            return dict(geometry)
        return None

    @property
    def contact(self) -> dict[str, Any] | None:
        """The interface the curve was computed with, recorded in the provenance: ``law``
        (frictionless, sticking, coulomb), ``friction`` (Coulomb's mu, 0 for the other laws) and
        ``source`` (who chose the law: "command line", "geometry file my_cup.toml", ...; None
        where the curve does not say), or None when the curve names no law (a measured curve,
        Appendix A)."""
        law = self.provenance.get("contact")
        if not isinstance(law, str):
            return None
        return {"law": law, "friction": float(self.provenance.get("friction", 0.0)),
                "source": self.provenance.get("contact_source")}

    def has(self, name: str) -> bool:
        """True if the optional column `name` ('r_c_m', 'l_m' or 'V_m3') is present."""
        return getattr(self, name) is not None

    # --------------------------------------------------------- interpolation
    def force(self, h_m: float | np.ndarray) -> np.ndarray:
        """Stiffness force F0(h) [N] by monotone (PCHIP) interpolation."""
        return self._interpolant("F0_N")(self._u_of(h_m))

    def force_slope(self, h_m: float | np.ndarray) -> np.ndarray:
        """dF0/du = -dF0/dh [N/m] of the interpolant."""
        return self._interpolant("F0_N").derivative()(self._u_of(h_m))

    def contact_radius(self, h_m: float | np.ndarray) -> np.ndarray:
        """Inner contact radius r_c(h) [m]."""
        return self._interpolant("r_c_m")(self._u_of(h_m))

    def contact_width(self, h_m: float | np.ndarray) -> np.ndarray:
        """Contact-strip width l(h) [m]."""
        return self._interpolant("l_m")(self._u_of(h_m))

    def volume(self, h_m: float | np.ndarray) -> np.ndarray:
        """Enclosed cavity volume V(h) [m^3]."""
        return self._interpolant("V_m3")(self._u_of(h_m))

    def scaled(self, kappa: float) -> StiffnessCurve:
        """The curve with F0 replaced by kappa*F0 (the paper's stiffness factor, Fig. 1stiffnessFactor)."""
        if not (np.isfinite(kappa) and kappa > 0):
            raise ValueError(f"kappa: stiffness scale factor must be > 0, got {kappa}")
        prov = dict(self.provenance, scaled_by=float(kappa))
        profiles = None if self.profiles is None else tuple(
            None if p is None else ContactProfile(p.r_m, kappa * p.p_Pa) for p in self.profiles)
        return StiffnessCurve(self.u_m, kappa * self.F0_N, self.h1_m, self.r_c_m, self.l_m,
                              self.V_m3, prov, profiles)

    def _u_of(self, h_m: float | np.ndarray) -> np.ndarray:
        u = self.h1_m - np.asarray(h_m, dtype=float)
        lo, hi = self.u_range_m
        tol = 1e-12 * max(1.0, hi - lo)
        outside = ~((u >= lo - tol) & (u <= hi + tol))  # also True for NaN
        if np.any(outside):
            bad = float(np.atleast_1d(u)[np.atleast_1d(outside)][0])
            raise ValueError(
                f"h_mm: {1e3 * (self.h1_m - bad):.6g} mm is outside the stiffness curve's "
                f"range [{1e3 * (self.h1_m - hi):.6g}, {1e3 * (self.h1_m - lo):.6g}] mm")
        return np.clip(u, lo, hi)

    def _interpolant(self, name: str) -> PchipInterpolator:
        interps = self._interpolants
        if name not in interps:
            raise ValueError(f"{name}: this stiffness curve has no such column "
                             f"(provenance: {self.provenance.get('source', 'unknown')})")
        return interps[name]

    @cached_property
    def _interpolants(self) -> dict[str, PchipInterpolator]:
        names = ("F0_N",) + tuple(n for n in _OPTIONAL if self.has(n))
        return {n: PchipInterpolator(self.u_m, getattr(self, n), extrapolate=False) for n in names}

    # --------------------------------------------------------------------- IO
    def to_csv(self, path: str | os.PathLike, sidecar: bool = True) -> Path:
        """Write the curve as a plain CSV (units in the column names) and, with `sidecar`, its
        provenance to the JSON sidecar ``path.with_suffix('.json')`` (key ``provenance``).

        Each file appears atomically (written to a temporary file and renamed). A caller that
        writes a richer sidecar itself (`validation.bridge.handoff`) passes ``sidecar=False``.
        """
        cols = {"u_mm": self.u_m * 1e3, "h_mm": self.h_m * 1e3, "F0_N": self.F0_N}
        for csv_name, (name, factor) in CSV_COLUMNS.items():
            if name in _OPTIONAL and self.has(name):
                cols[csv_name] = getattr(self, name) / factor
        table = np.column_stack(list(cols.values()))
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        if sidecar:
            data: dict[str, Any] = {"provenance": self.provenance, "h1_mm": 1e3 * self.h1_m}
            if self.profiles is not None:
                data["steps"] = profiles_to_lists(self.profiles)
            text = json.dumps(data, indent=1, sort_keys=True, default=str) + "\n"
            _atomic_write(path.with_suffix(".json"), lambda f: f.write(text))

        def write_table(f) -> None:
            f.write(",".join(cols) + "\n")
            np.savetxt(f, table, delimiter=",", fmt="%.10g")

        _atomic_write(path, write_table)
        return path

    @classmethod
    def from_csv(cls, path: str | os.PathLike, h1_m: float | None = None) -> StiffnessCurve:
        """Read a curve written by `to_csv`, or a measured one with at least `u_mm,F0_N`.

        h1 is taken from the `h_mm` column (h1 = u + h) when present; otherwise `h1_m` must
        be given (the undeformed height of the cup the curve was measured on). The provenance
        comes from the JSON sidecar ``path.with_suffix('.json')`` when there is one (or from a
        ``# provenance:`` line, the former format).
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
        return cls(h1_m=h1_m, provenance=provenance, profiles=profiles, **si)


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


def _frozen_array(value: Any, name: str, size: int | None = None) -> np.ndarray:
    arr = np.array(value, dtype=float).reshape(-1)
    if size is not None and arr.size != size:
        raise ValueError(f"{name}: expected {size} samples, got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: contains NaN or infinite values")
    arr.flags.writeable = False
    return arr
