"""The hand-off for the coupled cavity: the cup's response on a grid of plate displacement u and
cavity pressure difference dp = p_a - p_b, as plain data (a `SuctionTable`).

For every (u_i, dp_j) the table holds (a table may have holes: states only where the cup's
paths go, the others null in every grid and profile; `built`; and states without a seal: at
u <= 0, the plate above the free cup's touching height, and small dp the rim does not reach the
plane, `sealed` False there and null in every grid and profile, no numbers for a cup that holds
no suction; `SealOpen` where a value would read one): the pull on the handle F1 (eq. 5's F1 with the suction acting on the
deformed cup), the cavity volume V, the seal radius r_k (the cavity's edge), the outer edge r_cut
of the contact zone next to it, and the contact-pressure profile p(r) across that zone, the
pressure the plane carries with the interface gas at p_b. It comes from the FEM
(`fem.suction.suction_grid`, converted in `validation`) or from a formula (tests build one from
the paper's own eqs 3-7); the reduced model does not know which.

JSON (one file; units in the key names)::

    {"u_mm": [...], "dp_kPa": [...], "F1_N": [[...]], "V_mm3": [[...]], "seal_r_mm": [[...]],
     "cut_r_mm": [[...]], "E_Pa": 4e6, "profiles": [[{"r_mm": [...], "p_kPa": [...]}, ...]],
     "sealed": [[true, false, ...]],          (optional: absent means every state is sealed)
     "seal_rings": [[{"r_mm": [...], "F_N": [...]}, ...]],   (optional, below)
     "provenance": {...}}

`seal_rings` (optional; null at a hole): per state the nodes that touch the plane alone (a seal
narrowed to its last ring) as the leak reads them, each ring's radius and the plane's reaction on
it, at a radius of the state's profile (`reduced.coupled_seal`: the same reading as the fem
route's). Absent: the table records no reactions and its lumped profiles are read as they are.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from reduced.profile_leak import ContactProfile

__all__ = ["MissingStates", "SealOpen", "SuctionTable"]

_GRIDS = {"F1_N": ("F1_N", 1.0), "V_mm3": ("V_m3", 1e-9), "seal_r_mm": ("seal_r_m", 1e-3),
          "cut_r_mm": ("cut_r_m", 1e-3)}


class _AtStates(LookupError):
    """A value read at states of a `SuctionTable` it cannot give: `nodes` are their (i, j) indices on
    the table's axes, `u_m`, `dp_Pa` their coordinates; `what` says why (the subclass's)."""

    what = ""

    def __init__(self, nodes, u_axis: np.ndarray, dp_axis: np.ndarray, where: str = ""):
        self.nodes = tuple(sorted({(int(i), int(j)) for i, j in nodes}))
        self.u_m = tuple(float(u_axis[i]) for i, _ in self.nodes)
        self.dp_Pa = tuple(float(dp_axis[j]) for _, j in self.nodes)
        first = ", ".join(f"({1e3 * u:.4g} mm, {d / 1e3:.4g} kPa)" for u, d in zip(self.u_m[:3], self.dp_Pa[:3]))
        super().__init__(f"suction table: {self.what.format(n=len(self.nodes))} {where}: (u, dp) = {first}"
                         + (", ..." if len(self.nodes) > 3 else ""))


class MissingStates(_AtStates):
    """A value read at a hole of a `SuctionTable`: the states a builder must add."""

    what = "{n} state(s) not built"


class SealOpen(_AtStates):
    """A value read at a state without a seal (`SuctionTable.sealed` False): the cup there holds
    no suction, so a path reaching it has let go."""

    what = "the seal is open"


@dataclass(frozen=True, eq=False)
class SuctionTable:
    """The cup's states on the (u, dp) grid (module docstring); grids are [len(u), len(dp)],
    nan in each of them (and None in profiles) where the table has a hole or the state holds no
    seal (`sealed` False; None: every state is sealed)."""

    u_m: np.ndarray
    dp_Pa: np.ndarray
    F1_N: np.ndarray
    V_m3: np.ndarray
    seal_r_m: np.ndarray
    cut_r_m: np.ndarray
    profiles: tuple[tuple[ContactProfile | None, ...], ...]
    E_Pa: float
    provenance: dict[str, Any] = field(default_factory=dict)
    sealed: np.ndarray | None = None
    #: per state (r_m, F_N) of the lone nodes' ring loads (module docstring), None at a hole; None: not recorded
    seal_rings: tuple[tuple[tuple[np.ndarray, np.ndarray] | None, ...], ...] | None = None

    def __post_init__(self) -> None:
        u, dp = (np.array(a, dtype=float) for a in (self.u_m, self.dp_Pa))
        if u.ndim != 1 or u.size < 2 or np.any(np.diff(u) <= 0) or not np.all(np.isfinite(u)):
            raise ValueError("u_mm: the plate displacements must be finite and strictly increasing (>= 2)")
        if dp.ndim != 1 or dp.size < 2 or np.any(np.diff(dp) <= 0) or dp[0] != 0.0:
            raise ValueError("dp_kPa: the pressure differences must start at 0 and strictly increase (>= 2)")
        hole = None
        for name in ("F1_N", "V_m3", "seal_r_m", "cut_r_m"):
            a = np.array(getattr(self, name), dtype=float)
            if a.shape != (u.size, dp.size):
                raise ValueError(f"{name}: expected finite values on the {u.size} x {dp.size} grid, got shape {a.shape}")
            hole = np.isnan(a) if hole is None else hole
            if not np.array_equal(np.isfinite(a), ~hole):
                holes = "" if name == "F1_N" else ": its holes differ from F1_N's"
                raise ValueError(f"{name}: expected finite values on the {u.size} x {dp.size} grid "
                                 f"(nan only at a hole, and there in every grid{holes}), got other non-finite values")
            a.flags.writeable = False
            object.__setattr__(self, name, a)
        sealed = np.ones(hole.shape, dtype=bool) if self.sealed is None else np.array(self.sealed)
        if sealed.shape != hole.shape or sealed.dtype != bool:
            raise ValueError(f"sealed: expected true/false on the {u.size} x {dp.size} grid")
        if not np.all(hole[~sealed]):
            raise ValueError("sealed: a state without a seal must be null in every grid and profile")
        sealed.flags.writeable = False
        object.__setattr__(self, "sealed", sealed)
        if np.any(self.V_m3[~hole] <= 0):
            raise ValueError("V_mm3: cavity volumes must be > 0")
        if len(self.profiles) != u.size or any(len(row) != dp.size for row in self.profiles):
            raise ValueError(f"profiles: expected {u.size} rows of {dp.size} profiles")
        if any(self.profiles[i][j] is not None for i, j in zip(*np.nonzero(hole))):
            raise ValueError("profiles: expected null at every hole of the grids")
        if self.seal_rings is not None:
            object.__setattr__(self, "seal_rings", _checked_rings(self.seal_rings, self.profiles))
        if not (np.isfinite(self.E_Pa) and self.E_Pa > 0):
            raise ValueError(f"E_Pa: the modulus of the table must be > 0 Pa, got {self.E_Pa}")
        u.flags.writeable = dp.flags.writeable = False
        object.__setattr__(self, "u_m", u)
        object.__setattr__(self, "dp_Pa", dp)

    @cached_property
    def built(self) -> np.ndarray:
        """[len(u), len(dp)] True where the table holds the state, sealed or not (False: a hole)."""
        built = np.isfinite(self.F1_N) | ~self.sealed
        built.flags.writeable = False
        return built

    @cached_property
    def complete(self) -> bool:
        """Whether the table holds every state of its grid (no holes)."""
        return bool(self.built.all())

    @cached_property
    def all_sealed(self) -> bool:
        """Whether every state of the table holds a seal."""
        return bool(self.sealed.all())

    def rows(self, keep: np.ndarray) -> "SuctionTable":
        """The table on the rows of u where `keep` is True."""
        k = np.asarray(keep, dtype=bool)
        return SuctionTable(u_m=self.u_m[k], dp_Pa=self.dp_Pa, **{name: getattr(self, name)[k] for name, _ in _GRIDS.values()},
                            profiles=tuple(row for row, ok in zip(self.profiles, k) if ok), E_Pa=self.E_Pa,
                            provenance=self.provenance, sealed=None if self.sealed[k].all() else self.sealed[k],
                            seal_rings=None if self.seal_rings is None else
                            tuple(row for row, ok in zip(self.seal_rings, k) if ok))

    @property
    def h1_m(self) -> float:
        """The free cup's height [m] the table's u is measured from (provenance ``h1_mm``; nan if
        the table does not record it)."""
        return 1e-3 * float(self.provenance.get("h1_mm", math.nan))

    def to_json(self, path: str | os.PathLike) -> Path:
        """Write the table (atomically: a temporary file renamed into place)."""
        path = Path(path)
        data = {"u_mm": (self.u_m * 1e3).tolist(), "dp_kPa": (self.dp_Pa / 1e3).tolist(),
                **{key: _nulled(getattr(self, name) / scale) for key, (name, scale) in _GRIDS.items()},
                "E_Pa": self.E_Pa,
                "profiles": [[None if p is None else {"r_mm": (p.r_m * 1e3).tolist(),
                                                      "p_kPa": (p.p_Pa / 1e3).tolist()} for p in row]
                             for row in self.profiles],
                **({} if self.all_sealed else {"sealed": self.sealed.tolist()}),
                **({} if self.seal_rings is None else {"seal_rings": [
                    [None if x is None else {"r_mm": (x[0] * 1e3).tolist(), "F_N": x[1].tolist()} for x in row]
                    for row in self.seal_rings]}),
                "provenance": self.provenance}
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(json.dumps(data))
        os.replace(tmp, path)
        return path

    @classmethod
    def from_json(cls, path: str | os.PathLike) -> "SuctionTable":
        """Read a table written by `to_json`; any defect (not JSON, a missing key, a wrong type or
        shape) is a one-line ValueError naming the file and the key."""
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
            raise ValueError(f"suction table: cannot read {path}: {err}") from None
        if not isinstance(data, dict):
            raise ValueError(f"suction table: {path} must hold a JSON object, got a {type(data).__name__}")
        missing = [k for k in ("u_mm", "dp_kPa", "E_Pa", "profiles", *_GRIDS) if k not in data]
        if missing:
            raise ValueError(f"suction table: {path} lacks {', '.join(missing)}")
        where = f"suction table {path}"
        provenance = data.get("provenance", {})
        if not isinstance(provenance, dict) or not isinstance(provenance.get("h1_mm", 0.0), (int, float)):
            raise ValueError(f"{where}: provenance must be an object whose h1_mm is a number")
        if not isinstance(data["profiles"], list) or not all(isinstance(row, list) for row in data["profiles"]):
            raise ValueError(f"{where}: profiles must be a list of rows (lists), one per u")
        try:
            profiles = tuple(tuple(_profile(p, f"profiles[{i}][{j}]") for j, p in enumerate(row))
                             for i, row in enumerate(data["profiles"]))
            grids = {name: _numbers(data[key], key) * scale for key, (name, scale) in _GRIDS.items()}
            sealed = data.get("sealed")
            if sealed is not None and not (isinstance(sealed, list) and all(
                    isinstance(row, list) and all(isinstance(x, bool) for x in row) for row in sealed)):
                raise ValueError("sealed: expected rows (lists) of true/false")
            rings = data.get("seal_rings")
            if rings is not None:
                if not (isinstance(rings, list) and all(isinstance(row, list) for row in rings)):
                    raise ValueError("seal_rings: expected rows (lists), one per u")
                rings = tuple(tuple(_ring(x, f"seal_rings[{i}][{j}]") for j, x in enumerate(row))
                              for i, row in enumerate(rings))
            return cls(u_m=_numbers(data["u_mm"], "u_mm") * 1e-3, dp_Pa=_numbers(data["dp_kPa"], "dp_kPa") * 1e3,
                       **grids, profiles=profiles, E_Pa=float(_numbers(data["E_Pa"], "E_Pa", scalar=True)),
                       provenance=provenance,
                       sealed=None if sealed is None else np.array(sealed, dtype=bool).reshape(len(sealed), -1),
                       seal_rings=rings)
        except ValueError as err:
            field_, _, rest = str(err).partition(": ")
            spelled = {name: key for key, (name, _) in _GRIDS.items()}.get(field_, field_)   # as the file spells it
            raise ValueError(f"{where}: {spelled}: {rest}") from None


def _nulled(a: np.ndarray) -> list:
    """Nested lists of `a` with None (JSON null) for its nan (a hole)."""
    return [[None if math.isnan(x) else x for x in row] for row in a.tolist()]


def _numbers(value: Any, key: str, scalar: bool = False) -> np.ndarray:
    """`value` as floats (a number with `scalar`, else nested lists); ValueError naming `key`."""
    if scalar and (isinstance(value, bool) or not isinstance(value, (int, float))):
        raise ValueError(f"{key}: expected a number, got {value!r:.40}")
    if isinstance(value, (str, bytes, dict)) or (not scalar and not isinstance(value, list)):
        raise ValueError(f"{key}: expected a list of numbers, got {type(value).__name__}")
    try:
        return np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{key}: expected numbers in a regular grid") from None


def _profile(value: Any, key: str) -> ContactProfile | None:
    """One profile of the JSON form ({"r_mm": [...], "p_kPa": [...]} or null)."""
    if value is None:
        return None
    if not isinstance(value, dict) or set(value) != {"r_mm", "p_kPa"}:
        raise ValueError(f"{key}: expected null or an object with exactly the keys r_mm, p_kPa")
    r_m, p_Pa = _numbers(value["r_mm"], f"{key}.r_mm") * 1e-3, _numbers(value["p_kPa"], f"{key}.p_kPa") * 1e3
    try:
        return ContactProfile(r_m, p_Pa)
    except ValueError as err:
        raise ValueError(f"{key}: {err}") from None


def _ring(value: Any, key: str) -> tuple[np.ndarray, np.ndarray] | None:
    """One state's ring loads of the JSON form ({"r_mm": [...], "F_N": [...]} or null)."""
    if value is None:
        return None
    if not isinstance(value, dict) or set(value) != {"r_mm", "F_N"}:
        raise ValueError(f"{key}: expected null or an object with exactly the keys r_mm, F_N")
    return _numbers(value["r_mm"], f"{key}.r_mm") * 1e-3, _numbers(value["F_N"], f"{key}.F_N")


_NO_RINGS = (np.zeros(0), np.zeros(0))
for _a in _NO_RINGS:
    _a.flags.writeable = False


def _checked_rings(rings, profiles) -> tuple:
    """`rings` as read-only arrays, checked against the profiles: one entry per state, None where
    the profile is, forces finite and >= 0, each radius one of its profile's."""
    if len(rings) != len(profiles) or any(len(a) != len(b) for a, b in zip(rings, profiles)):
        raise ValueError(f"seal_rings: expected {len(profiles)} rows of {len(profiles[0]) if profiles else 0} entries")
    out = []
    for i, (row, prow) in enumerate(zip(rings, profiles)):
        if row.count(None) == len(row) == prow.count(None):      # an unbuilt row: nothing to check
            out.append(tuple(row))
            continue
        cells = []
        for j, (x, prof) in enumerate(zip(row, prow)):
            if (x is None) != (prof is None):
                raise ValueError(f"seal_rings[{i}][{j}]: expected null exactly where the profile is null")
            if x is not None and len(x[0]) == len(x[1]) == 0:        # no lone node (most states)
                x = _NO_RINGS
            elif x is not None:
                r, F = (np.array(a, dtype=float).reshape(-1) for a in x)
                if r.size != F.size or not (np.all(np.isfinite(F)) and np.all(F >= 0)) \
                        or int(np.isin(r, prof.r_m).sum()) != r.size:
                    raise ValueError(f"seal_rings[{i}][{j}]: expected one force >= 0 per ring, each ring at "
                                     f"a radius of the state's profile")
                r.flags.writeable = F.flags.writeable = False
                x = (r, F)
            cells.append(x)
        out.append(tuple(cells))
    return tuple(out)
