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

Its provenance, the written record, travels in a JSON sidecar of the same name (``curve.json``,
`reduced.curve_files`), among it the cup design the curve was computed for (``geometry``: r0_mm,
r1_mm, alpha_deg, h1_mm, the thickness profile) and, for an FEM curve, its interface with the
plane (``contact``, ``friction``, ``contact_source``); `design` and `contact` return them as typed
values (`reduced.design`), which is what a lifetime compares and takes the cup from.
Optionally the curve carries the contact-pressure profile p(r) of every sample (`profiles`, for
the leak through the profile, `reduced.profile_leak`).

Interpolation is monotone piecewise-cubic (PCHIP): it never overshoots between samples, so
a monotone measured curve stays monotone. Evaluating outside the sampled range is an error,
not an extrapolation.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from reduced.curve_files import (CSV_COLUMNS, OPTIONAL_COLUMNS, profiles_from_lists, read_curve_csv,
                                  read_profiles_csv, write_curve_csv)
from reduced.design import ContactRecord, CupShape, recorded_contact, recorded_design
from reduced.profile_leak import ContactProfile

__all__ = ["StiffnessCurve", "CSV_COLUMNS", "read_profiles_csv", "profiles_from_lists", "non_increasing_fit"]

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
        for name in OPTIONAL_COLUMNS:
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

    @cached_property
    def design(self) -> CupShape | None:
        """The cup design the provenance records (`reduced.design.CupShape`), or None when the
        curve names none (a measured curve, a user's mesh)."""
        return recorded_design(self.provenance)

    @cached_property
    def contact(self) -> ContactRecord | None:
        """The interface the curve was computed with, as the provenance records it
        (`reduced.design.ContactRecord`: law, Coulomb's mu, who chose the law), or None when the
        curve names no law (a measured curve, Appendix A)."""
        return recorded_contact(self.provenance)

    @cached_property
    def contact_edge_m(self) -> np.ndarray | None:
        """The inner contact radius r_c [m] at the samples as the force balance takes it: from the
        first sample with a strip (l > 0) on, the weighted least-squares non-increasing fit of r_c
        (weights: each sample's share of u). Once a strip has formed, pressing the cup only spreads
        its contact inwards; an outward move of the FEM's r_c between two load steps is its edge
        estimator's jump as the contact front passes a node, and an r(h) that falls with h puts
        folds into the equilibrium branch that the cup does not have (their number and place then
        follow the load steps). None without r_c; r_c itself where it is already monotone."""
        if self.r_c_m is None:
            return None
        strip = np.flatnonzero(self.l_m > 0) if self.l_m is not None else np.zeros(0, int)
        if strip.size == 0 or np.all(np.diff(self.r_c_m[strip[0]:]) <= 0):
            return self.r_c_m
        start = int(strip[0])
        edge = self.r_c_m.copy()
        edge[start:] = non_increasing_fit(self.r_c_m[start:], _shares(self.u_m[start:]))
        edge.flags.writeable = False
        return edge

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

    def _interpolant(self, name: str) -> Any:
        interps = self._interpolants
        if name not in interps:
            raise ValueError(f"{name}: this stiffness curve has no such column "
                             f"(provenance: {self.provenance.get('source', 'unknown')})")
        return interps[name]

    @cached_property
    def _interpolants(self) -> dict[str, Any]:
        names = ("F0_N",) + tuple(n for n in OPTIONAL_COLUMNS if self.has(n))
        from scipy.interpolate import PchipInterpolator     # here: scipy.interpolate costs ~0.4 s to import
        return {n: PchipInterpolator(self.u_m, getattr(self, n), extrapolate=False) for n in names}

    # --------------------------------------------------------------------- IO
    def to_csv(self, path: str | os.PathLike, sidecar: bool = True) -> Path:
        """Write the curve as a plain CSV (units in the column names) and, with `sidecar`, its
        provenance to the JSON sidecar ``path.with_suffix('.json')`` (`reduced.curve_files`).

        A caller that writes a richer sidecar itself (`validation.bridge.handoff`) passes
        ``sidecar=False``.
        """
        arrays = {name: getattr(self, name) for name in ("u_m", "F0_N", *OPTIONAL_COLUMNS)}
        return write_curve_csv(path, arrays, self.h1_m, self.provenance, self.profiles, sidecar)

    @classmethod
    def from_csv(cls, path: str | os.PathLike, h1_m: float | None = None) -> StiffnessCurve:
        """Read a curve written by `to_csv`, or a measured one with at least `u_mm,F0_N`
        (`reduced.curve_files.read_curve_csv`: h1 from the `h_mm` column, else `h1_m` must be
        given; the provenance from the JSON sidecar when there is one)."""
        return cls(**read_curve_csv(path, h1_m))


def non_increasing_fit(y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The non-increasing sequence nearest to y in the w-weighted least-squares sense, by pooling
    adjacent violators (each pooled run takes its weighted mean; isotonic regression, as
    scipy.optimize.isotonic_regression(y, weights=w, increasing=False), without its import)."""
    means: list[float] = []
    weights: list[float] = []
    counts: list[int] = []
    for yi, wi in zip(np.asarray(y, dtype=float).tolist(), np.asarray(w, dtype=float).tolist()):
        means.append(yi)
        weights.append(wi)
        counts.append(1)
        while len(means) > 1 and means[-2] < means[-1]:
            m, wt, n = means.pop(), weights.pop(), counts.pop()
            total = weights[-1] + wt
            means[-1] = (means[-1] * weights[-1] + m * wt) / total
            weights[-1], counts[-1] = total, counts[-1] + n
    return np.repeat(means, counts)


def _shares(u: np.ndarray) -> np.ndarray:
    """Each sample's share of the range of u (the trapezoid rule's weights)."""
    if u.size < 2:
        return np.ones(u.size)
    gaps = np.diff(u)
    return 0.5 * (np.concatenate([[0.0], gaps]) + np.concatenate([gaps, [0.0]]))


def _frozen_array(value: Any, name: str, size: int | None = None) -> np.ndarray:
    arr = np.array(value, dtype=float).reshape(-1)
    if size is not None and arr.size != size:
        raise ValueError(f"{name}: expected {size} samples, got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: contains NaN or infinite values")
    arr.flags.writeable = False
    return arr
