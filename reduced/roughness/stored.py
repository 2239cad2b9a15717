"""The calibrated presets' u_c tables, stored with the package: `uc_table` returns a stored table
instead of computing it when the request is one it holds, so that a command on a preset surface
spends no time in Persson theory (~0.1 s of CPU a table) and imports no scipy.special.

A stored table is found by the hash of everything it is computed from: the spectrum's q, C and
provenance, nu, method, gamma, a_c, the p/E grid, whether it carries its patch length, and the
sources of the theory (`THEORY`: the modules that compute a table from a spectrum). Any edit of
those makes every stored table stale: it is then computed as before, until ``python -m reduced.roughness.surfaces --tables``
writes them anew (tests/test_uc_stored.py fails meanwhile, and checks each stored table against a fresh
computation bit for bit). The floats are stored as their shortest repr, which reads back exactly.
"""

from __future__ import annotations

import hashlib
import json
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

from reduced.critical_gap import UcTable

from .spectrum import PowerSpectrum

__all__ = ["request_key", "stored_table", "STORED_NU", "REPRODUCE"]

#: the Poisson ratio of the stored tables: the paper's rubber, `cupcheck lifetime`'s and the
#: scenes' default (`validation.bridge.pipeline.surface_uc_table`)
STORED_NU = 0.5
_FILE = "data/uc_tables.json"
#: the modules of this package whose code computes a u_c table from a spectrum
THEORY = ("persson.py", "separation.py", "effective_medium.py", "spectrum.py")
REPRODUCE = "python -m reduced.roughness.surfaces --tables"


@lru_cache(maxsize=1)
def _source_hash() -> str:
    """A hash of the sources that compute a u_c table (`THEORY`)."""
    h = hashlib.sha256()
    for name in THEORY:
        h.update(name.encode())
        h.update((Path(__file__).parent / name).read_bytes())
    return h.hexdigest()


def request_key(spectrum: PowerSpectrum, nu: float, method: str, gamma: float, a_c: float,
                p_over_E: np.ndarray, with_patch_length: bool) -> str:
    """The content key of a `uc_table` request (module docstring)."""
    h = hashlib.sha256(_source_hash().encode())
    for array in (spectrum.q_per_m, spectrum.C_m4, p_over_E):
        h.update(np.ascontiguousarray(array, dtype=np.float64).tobytes())
    h.update(json.dumps([spectrum.provenance, float(nu), method, float(gamma), float(a_c),
                         bool(with_patch_length)]).encode())
    return h.hexdigest()[:32]


@lru_cache(maxsize=1)
def _stored() -> dict:
    try:
        text = resources.files("reduced.roughness").joinpath(_FILE).read_text()
    except FileNotFoundError:
        return {}
    return json.loads(text)["tables"]


def stored_table(key: str, p_over_E: np.ndarray) -> UcTable | None:
    """The stored table of request `key` (on its grid `p_over_E`), or None."""
    entry = _stored().get(key)
    if entry is None:
        return None
    return UcTable(np.array(p_over_E, float), entry["u_c_m"], provenance=entry["provenance"],
                   patch_length_m=entry["patch_length_m"], u_mean_m=entry["u_mean_m"],
                   contact_area_ratio=entry["contact_area_ratio"], sealed=entry["sealed"],
                   theory=entry["theory"])


def entry(name: str, table: UcTable) -> dict:
    """What the store keeps of preset `name`'s table (its grid is the request's)."""
    return {"preset": name, "provenance": table.provenance, "patch_length_m": table.patch_length_m,
            "theory": dict(table.theory), "u_c_m": table.u_c_m.tolist(), "u_mean_m": table.u_mean_m.tolist(),
            "contact_area_ratio": table.contact_area_ratio.tolist(), "sealed": table.sealed.tolist()}


def write(tables: dict[str, dict]) -> Path:
    """Replace the store by `tables` (key -> `entry`), one table a line."""
    path = Path(__file__).parent / _FILE
    rows = ",\n".join(f"{json.dumps(k)}: {json.dumps(v, separators=(',', ':'))}" for k, v in tables.items())
    path.write_text(f'{{"reproduce": "{REPRODUCE}", "tables": {{\n{rows}\n}}}}\n')
    _stored.cache_clear()
    return path
