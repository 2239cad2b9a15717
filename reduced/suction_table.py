"""The hand-off for the coupled cavity: the cup's response on a grid of plate displacement u and
cavity pressure difference dp = p_a - p_b, as plain data (a `SuctionTable`).

For every (u_i, dp_j): the pull on the handle F1 (eq. 5's F1 with the suction acting on the
deformed cup), the cavity volume V, the seal radius r_k (the cavity's edge), the outer edge r_cut
of the contact zone next to it, and the contact-pressure profile p(r) across that zone, the
pressure the plane carries with the interface gas at p_b. It comes from the FEM
(`fem.suction.suction_grid`, converted in `validation`) or from a formula (tests build one from
the paper's own eqs 3-7); the reduced model does not know which.

JSON (one file; units in the key names)::

    {"u_mm": [...], "dp_kPa": [...], "F1_N": [[...]], "V_mm3": [[...]], "seal_r_mm": [[...]],
     "cut_r_mm": [[...]], "E_Pa": 4e6, "profiles": [[{"r_mm": [...], "p_kPa": [...]}, ...]],
     "provenance": {...}}
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from reduced.profile_leak import ContactProfile

__all__ = ["SuctionTable"]

_GRIDS = {"F1_N": ("F1_N", 1.0), "V_mm3": ("V_m3", 1e-9), "seal_r_mm": ("seal_r_m", 1e-3),
          "cut_r_mm": ("cut_r_m", 1e-3)}


@dataclass(frozen=True, eq=False)
class SuctionTable:
    """The cup's states on the (u, dp) grid (module docstring); grids are [len(u), len(dp)]."""

    u_m: np.ndarray
    dp_Pa: np.ndarray
    F1_N: np.ndarray
    V_m3: np.ndarray
    seal_r_m: np.ndarray
    cut_r_m: np.ndarray
    profiles: tuple[tuple[ContactProfile | None, ...], ...]
    E_Pa: float
    provenance: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        u, dp = (np.array(a, dtype=float) for a in (self.u_m, self.dp_Pa))
        if u.ndim != 1 or u.size < 2 or np.any(np.diff(u) <= 0) or u[0] < 0:
            raise ValueError("u_mm: the plate displacements must be >= 0 and strictly increasing (>= 2)")
        if dp.ndim != 1 or dp.size < 2 or np.any(np.diff(dp) <= 0) or dp[0] != 0.0:
            raise ValueError("dp_kPa: the pressure differences must start at 0 and strictly increase (>= 2)")
        for name in ("F1_N", "V_m3", "seal_r_m", "cut_r_m"):
            a = np.array(getattr(self, name), dtype=float)
            if a.shape != (u.size, dp.size) or not np.all(np.isfinite(a)):
                raise ValueError(f"{name}: expected finite values on the {u.size} x {dp.size} grid, "
                                 f"got shape {a.shape}")
            a.flags.writeable = False
            object.__setattr__(self, name, a)
        if np.any(self.V_m3 <= 0):
            raise ValueError("V_mm3: cavity volumes must be > 0")
        if len(self.profiles) != u.size or any(len(row) != dp.size for row in self.profiles):
            raise ValueError(f"profiles: expected {u.size} rows of {dp.size} profiles")
        if not (np.isfinite(self.E_Pa) and self.E_Pa > 0):
            raise ValueError(f"E_Pa: the modulus of the table must be > 0 Pa, got {self.E_Pa}")
        u.flags.writeable = dp.flags.writeable = False
        object.__setattr__(self, "u_m", u)
        object.__setattr__(self, "dp_Pa", dp)

    @property
    def h1_m(self) -> float:
        """The free cup's height [m] the table's u is measured from (provenance ``h1_mm``; nan if
        the table does not record it)."""
        return 1e-3 * float(self.provenance.get("h1_mm", math.nan))

    def to_json(self, path: str | os.PathLike) -> Path:
        """Write the table (atomically: a temporary file renamed into place)."""
        path = Path(path)
        data = {"u_mm": (self.u_m * 1e3).tolist(), "dp_kPa": (self.dp_Pa / 1e3).tolist(),
                **{key: (getattr(self, name) / scale).tolist() for key, (name, scale) in _GRIDS.items()},
                "E_Pa": self.E_Pa,
                "profiles": [[None if p is None else {"r_mm": (p.r_m * 1e3).tolist(),
                                                      "p_kPa": (p.p_Pa / 1e3).tolist()} for p in row]
                             for row in self.profiles],
                "provenance": self.provenance}
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(json.dumps(data))
        os.replace(tmp, path)
        return path

    @classmethod
    def from_json(cls, path: str | os.PathLike) -> "SuctionTable":
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
            raise ValueError(f"suction table: cannot read {path}: {err}") from None
        missing = [k for k in ("u_mm", "dp_kPa", "E_Pa", "profiles", *_GRIDS) if k not in data]
        if missing:
            raise ValueError(f"suction table: {path} lacks {', '.join(missing)}")
        profiles = tuple(tuple(None if p is None else ContactProfile(np.array(p["r_mm"]) * 1e-3,
                                                                     np.array(p["p_kPa"]) * 1e3)
                               for p in row) for row in data["profiles"])
        return cls(u_m=np.array(data["u_mm"]) * 1e-3, dp_Pa=np.array(data["dp_kPa"]) * 1e3,
                   **{name: np.array(data[key], dtype=float) * scale for key, (name, scale) in _GRIDS.items()},
                   profiles=profiles, E_Pa=float(data["E_Pa"]), provenance=data.get("provenance", {}))
