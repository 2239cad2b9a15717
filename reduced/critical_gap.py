"""The critical gap u_c(p/E): the surface separation at the critical constrictions (Sec. 4, 5.1).

The reduced model takes u_c as any callable `u_c(p_over_E) -> metres`. `UcTable` is the standard
one: a table `p_over_E,u_c_m` (as Fig. 1pressureMPa.2loguc shows it), interpolated in
log-log (a monotone cubic in ln u_c over ln p/E, `reduced.loglog`) and extrapolated as power laws
beyond both ends.

u_c = 0 is legal and means a sealed interface (the contact area percolates): no leak. Zeros may
only form a trailing block (once sealed, a higher pressure stays sealed). Between the last open
row and the first sealed row u_c falls linearly in p/E to 0 (no log of zero is taken); beyond
the first sealed row it stays 0.

A table may carry `patch_length_m`, the radial width of the patch over which the nominal pressure
p of rough-contact theory is defined (from a spectrum: the smallest patch that holds every
wavelength u_c depends on, `reduced.roughness.persson.patch_length`, attached by
`uc_table(..., with_patch_length=True)`; None: not known). The profile route then averages the
contact pressure over it (`reduced.profile_leak.patch_average`, `reduced.seal`). In a CSV it is the
comment line ``# patch_length_m = <metres>``.

`illustrative_uc_table()` is a stand-in until Persson-theory tables exist: a power law through the
paper's 0.68 um at p/E = 0.025 (the 1.89 um rms sandblasted PMMA at 1 atm, E = 4 MPa). It is an
input for examples, not a result and never a test oracle. `python -m reduced.critical_gap`
regenerates `reduced/data/uc_illustrative.csv` from it.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from reduced.loglog import LogLogPchip, elementwise, read_two_columns

__all__ = ["UcTable", "illustrative_uc_table", "ILLUSTRATIVE_UC_CSV"]


def _frozen(values, dtype=float) -> np.ndarray:
    a = np.array(values, dtype=dtype).reshape(-1)
    a.flags.writeable = False
    return a


def _sorted_rows(p: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows by increasing p/E, each pressure once (a repeat must repeat its u_c)."""
    order = np.argsort(p, kind="stable")
    ps, us = p[order], u[order]
    same = np.diff(ps) == 0
    if np.any(same):
        if np.any(us[1:][same] != us[:-1][same]):
            raise ValueError("p_over_E: a repeated pressure with a different u_c")
        keep = np.concatenate([[True], ~same])
        ps, us = ps[keep], us[keep]
    return ps, us

ILLUSTRATIVE_UC_CSV = Path(__file__).parent / "data" / "uc_illustrative.csv"
_HEADER = "p_over_E,u_c_m"
_PATCH = re.compile(r"\s*patch_length_m\s*=\s*(\S+)\s*")


@dataclass(frozen=True, eq=False)
class UcTable:
    """u_c(p/E) from a table, log-log interpolation and extrapolation; u_c = 0 = sealed.

    The one u_c table type, whether read from a CSV or computed by Persson theory
    (`reduced.roughness.critical_gap_table`, which also fills the theory's columns: the mean
    separation `u_mean_m`, the contact area ratio `contact_area_ratio` A/A0 at full magnification,
    `sealed` where the contact percolates, and `theory`, its settings E_Pa, nu, method, gamma, a_c).
    Rows keep the order they were given in (the theory answers the pressures it was asked for);
    the interpolant is built on them sorted, and needs at least 2 open (u_c > 0) rows: a table with
    fewer can be built and read, not evaluated. A CSV must be sorted and interpolable (`from_csv`).
    """

    p_over_E: np.ndarray
    u_c_m: np.ndarray
    provenance: str = ""
    patch_length_m: float | None = None
    u_mean_m: np.ndarray | None = None
    contact_area_ratio: np.ndarray | None = None
    sealed: np.ndarray | None = None
    theory: Mapping[str, Any] | None = None
    _rows: tuple = field(init=False, repr=False, compare=False)
    _open: LogLogPchip | None = field(init=False, repr=False, compare=False)
    _seal: float = field(init=False, repr=False, compare=False)
    _vec: tuple | None = field(init=False, repr=False, compare=False)

    def __reduce__(self):
        """Pickle by the constructor's fields, the read-only mappings as plain dicts (a
        MappingProxyType does not pickle; the constructor wraps them again)."""
        import dataclasses
        values = [getattr(self, f.name) for f in dataclasses.fields(self) if f.init]
        return type(self), tuple(dict(v) if isinstance(v, MappingProxyType) else v for v in values)

    def __post_init__(self) -> None:
        p = _frozen(self.p_over_E)
        u = _frozen(self.u_c_m)
        if p.size != u.size:
            raise ValueError(f"u_c_m: {u.size} values for {p.size} pressures")
        if p.size == 0 or not (np.all(np.isfinite(p)) and np.all(p > 0)):
            raise ValueError(f"p_over_E: need at least one pressure, each finite and > 0, got {p.size} rows")
        if not (np.all(np.isfinite(u)) and np.all(u >= 0)):
            raise ValueError("u_c_m: must be finite and >= 0 (0 = sealed)")
        for name in ("u_mean_m", "contact_area_ratio", "sealed"):
            column = getattr(self, name)
            if column is not None:
                column = _frozen(column, bool if name == "sealed" else float)
                if column.size != p.size:
                    raise ValueError(f"{name}: {column.size} values for {p.size} pressures")
                object.__setattr__(self, name, column)
        if self.sealed is None:
            object.__setattr__(self, "sealed", _frozen(u == 0.0, bool))
        if self.patch_length_m is not None:
            L = float(self.patch_length_m)
            if not (math.isfinite(L) and L > 0):
                raise ValueError(f"patch_length_m: must be finite and > 0 (or None), got {self.patch_length_m}")
            object.__setattr__(self, "patch_length_m", L)
        if self.theory is not None:
            object.__setattr__(self, "theory", MappingProxyType(dict(self.theory)))
        object.__setattr__(self, "p_over_E", p)
        object.__setattr__(self, "u_c_m", u)
        ps, us = _sorted_rows(p, u)
        open_rows = int(np.count_nonzero(us > 0))
        if np.any(us[:open_rows] <= 0):
            raise ValueError("u_c_m: a sealed (0) row may only be followed by sealed rows")
        object.__setattr__(self, "_rows", (ps, us))
        object.__setattr__(self, "_seal", float(ps[open_rows]) if open_rows < ps.size else math.inf)
        object.__setattr__(self, "_vec", None)         # built by the first `values` call
        if open_rows < 2:
            object.__setattr__(self, "_open", None)
            return
        object.__setattr__(self, "_open", LogLogPchip(ps[:open_rows], us[:open_rows]))

    def _vectorised(self) -> tuple:
        """The interpolant for arrays (`values`): ln u_c PCHIP in ln p/E (the scalar path's, evaluated
        on arrays as scipy's PchipInterpolator does, `reduced.fast_curve`), power laws beyond."""
        if self._vec is None:
            n = self._open.n
            lx, ly = np.log(self._rows[0][:n]), np.log(self._rows[1][:n])
            pchip = self._open.cubic
            slopes = pchip.values_and_slopes(np.array([lx[0], lx[-1]]))[1]
            object.__setattr__(self, "_vec", (lambda t: pchip.values_and_slopes(t)[0], lx[0], ly[0],
                                              float(slopes[0]), lx[-1], ly[-1], float(slopes[1])))
        return self._vec

    def _interpolable(self) -> None:
        if self._open is None:
            raise ValueError("u_c_m: need at least 2 open (u_c > 0) rows to interpolate in log-log")

    @property
    def sealing_p_over_E(self) -> float:
        """Smallest tabulated p/E that is sealed (inf if none)."""
        return self._seal

    def __call__(self, p_over_E):
        """u_c [m] at p/E (float -> float, array -> array)."""
        return elementwise(self.scalar, p_over_E)

    def scalar(self, x: float) -> float:
        if not x > 0:
            raise ValueError(f"p_over_E: contact pressure over modulus must be > 0, got {x}")
        self._interpolable()
        seal = self._seal
        n = self._open.n
        ps, us = self._rows
        if seal < math.inf and x > ps[n - 1]:
            if x >= seal:
                return 0.0
            # between the last open row and the first sealed row: linear in p/E down to 0
            p_last = float(ps[n - 1])
            return float(us[n - 1]) * (seal - x) / (seal - p_last)
        return self._open.value_and_slope(x)[0]

    def values(self, p_over_E: np.ndarray) -> np.ndarray:
        """u_c [m] at an array of p/E, vectorised (`scalar` element by element, to round-off)."""
        x = np.asarray(p_over_E, dtype=float)
        if x.size and not np.all(x > 0):
            raise ValueError(f"p_over_E: contact pressure over modulus must be > 0, got {x[~(x > 0)][0]}")
        self._interpolable()
        cubic, t_lo, y_lo, s_lo, t_hi, y_hi, s_hi = self._vectorised()
        t = np.log(x)
        inside = np.clip(t, t_lo, t_hi)
        ln_u = np.where(t < t_lo, y_lo + s_lo * (t - t_lo), np.where(t > t_hi, y_hi + s_hi * (t - t_hi), cubic(inside)))
        out = np.exp(ln_u)
        if self._seal < math.inf:
            n = self._open.n
            p_last, u_last = float(self._rows[0][n - 1]), float(self._rows[1][n - 1])
            ramp = u_last * (self._seal - x) / (self._seal - p_last)
            out = np.where(x > p_last, np.where(x >= self._seal, 0.0, ramp), out)
        return out

    # --------------------------------------------------------------------- IO
    @classmethod
    def from_csv(cls, path: str | os.PathLike) -> UcTable:
        p, u, comments = read_two_columns(path, _HEADER, "uc-table")
        patch = _PATCH.search(comments)
        length = None
        if patch is not None:
            try:
                length = float(patch.group(1))
            except ValueError:
                raise ValueError(f"uc-table: '{path}': patch_length_m = {patch.group(1)!r} is not a number") from None
            comments = (comments[:patch.start()] + " " + comments[patch.end():]).strip()
        if p.size != u.size:
            raise ValueError(f"u_c_m: {u.size} values for {p.size} pressures")
        if p.size < 2:
            raise ValueError(f"p_over_E: a u_c table needs at least 2 rows, got {p.size}")
        if not (np.all(np.isfinite(p)) and np.all(p > 0) and np.all(np.diff(p) > 0)):
            raise ValueError("p_over_E: must be finite, > 0 and strictly increasing")
        table = cls(p, u, provenance=comments or f"csv:{Path(path).name}", patch_length_m=length)
        table._interpolable()
        return table

    def to_csv(self, path: str | os.PathLike) -> Path:
        """Write the table atomically (rows by increasing p/E), provenance as '#' comment lines."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.tmp")
        with open(tmp, "w") as f:
            if self.patch_length_m is not None:
                f.write(f"# patch_length_m = {self.patch_length_m:.10g}\n")
            for line in self.provenance.splitlines():
                f.write(f"# {line}\n")
            f.write(_HEADER + "\n")
            for p, u in zip(*self._rows):
                f.write(f"{p:.10g},{u:.10g}\n")
        os.replace(tmp, path)
        return path


def illustrative_uc_table(u_ref_m: float = 0.68e-6, p_ref_over_E: float = 0.025,
                          exponent: float = 1.0, p_min: float = 1e-4, p_max: float = 0.3,
                          rows: int = 25) -> UcTable:
    """ILLUSTRATIVE u_c = u_ref (p/E / p_ref)^(-exponent), tabulated log-spaced (not Persson theory)."""
    p = np.geomspace(p_min, p_max, rows)
    u = u_ref_m * (p / p_ref_over_E) ** (-exponent)
    provenance = (f"ILLUSTRATIVE u_c table, not a rough-contact result: power law "
                  f"u_c = {u_ref_m:g} m * (p/E / {p_ref_over_E:g})^(-{exponent:g}),\n"
                  f"through the paper's u_c = 0.68 um at 1 atm (p/E = 0.025, E = 4 MPa) for the "
                  f"1.89 um rms sandblasted PMMA (Sec. 5.1).\n"
                  f"Generated by reduced.critical_gap.illustrative_uc_table(); "
                  f"regenerate with `python -m reduced.critical_gap`.")
    return UcTable(p, u, provenance=provenance)


if __name__ == "__main__":
    print(illustrative_uc_table().to_csv(ILLUSTRATIVE_UC_CSV))
