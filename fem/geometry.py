"""The cup's cross-section: a truncated-cone wall in the (r, z) half-plane (Sec. 3, Table 1).

The cavity-facing (lower) surface is the straight line from the top-plate edge (r0, h1) down to
the rim (r1, 0), with h1 = (r1 - r0) tan(alpha). The wall thickness d(r) is a profile in the radius
r of the lower-surface point (linear by default; tabulated or any callable too). The upper
surface is the lower one offset by d, either along the lower surface's unit normal
n = (sin alpha, cos alpha) (``thickness_convention="normal"``, the default) or vertically
(``"vertical"``). The end edges join corresponding points: the top-plate edge at s = 0, the rim
edge at s = 1.

Every point of the wall is the image of (s, t) in [0, 1]^2 under the map (`CupGeometry.point`)::

    x(s, t) = P(s) + t d(r(s)) e,   P(s) = (r0, h1) + s (r1 - r0, -h1),   r(s) = r0 + s (r1 - r0),

with e = n or e_z. Its Jacobian determinant is L d (normal) or L d cos(alpha) (vertical), L the
length of the lower surface, so with d > 0 the map never folds; the self-intersection check in
`CupGeometry.__post_init__` is a safety net for the boundary polygon as a whole.

Presets (`cup_geometry`): cups A and B of the paper (Table 1 and Sec. 5.5), r0 = 5 mm, r1 = 19 mm,
alpha = 33 and 21 degrees, and the thickness falling linearly from 2.5 mm (A) or 1.5 mm (B) at
r = 5 mm to 0.3 mm at r = 20 mm. The paper specifies the thickness at r = 20 mm, beyond the rim
r1 = 19 mm: the line through those two points is evaluated on [r0, r1], which gives a rim
thickness of 0.447 mm (A) and 0.38 mm (B).

A design file (TOML or JSON, keys in mm and degrees) is read by `fem.design_file`.

SI units inside (metres, degrees only for the cone angle, as its field name says).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

__all__ = ["CupGeometry", "LinearThickness", "TabulatedThickness", "ThicknessProfile", "cup_geometry", "PRESETS",
           "polygon_self_intersects"]

ThicknessProfile = Callable[[np.ndarray], np.ndarray]
ThicknessConvention = Literal["normal", "vertical"]
_CONVENTIONS = ("normal", "vertical")
_MM = 1e-3


@dataclass(frozen=True)
class LinearThickness:
    """d(r) on the line through (r_a_m, d_a_m) and (r_b_m, d_b_m), extrapolated beyond them [m]."""

    r_a_m: float
    d_a_m: float
    r_b_m: float
    d_b_m: float

    def __post_init__(self) -> None:
        if not self.r_a_m != self.r_b_m:
            raise ValueError(f"thickness: the two radii of a linear profile must differ, got "
                             f"{self.r_a_m / _MM:g} mm twice")

    def __call__(self, r_m: np.ndarray) -> np.ndarray:
        slope = (self.d_b_m - self.d_a_m) / (self.r_b_m - self.r_a_m)
        return self.d_a_m + slope * (np.asarray(r_m, dtype=float) - self.r_a_m)


@dataclass(frozen=True)
class TabulatedThickness:
    """d(r) interpolated piecewise-linearly in a table (r_m strictly increasing) [m].

    The table must cover the wall's radii [r0, r1]; it is never extrapolated.
    """

    r_m: tuple[float, ...]
    d_m: tuple[float, ...]

    def __post_init__(self) -> None:
        r, d = np.asarray(self.r_m, float), np.asarray(self.d_m, float)
        if r.ndim != 1 or r.size < 2 or r.shape != d.shape:
            raise ValueError(f"thickness: a table needs >= 2 matching (r, d) pairs, got "
                             f"{r.size} radii and {d.size} thicknesses")
        if np.any(np.diff(r) <= 0):
            raise ValueError("thickness: table radii r_mm must be strictly increasing")
        object.__setattr__(self, "r_m", tuple(map(float, r)))
        object.__setattr__(self, "d_m", tuple(map(float, d)))

    def __call__(self, r_m: np.ndarray) -> np.ndarray:
        return np.interp(np.asarray(r_m, dtype=float), self.r_m, self.d_m)


@dataclass(frozen=True)
class CupGeometry:
    """A truncated-cone cup wall (Sec. 3, Fig. pic): see the module docstring for the map.

    Parameters
    ----------
    r0_m : radius of the top plate, where the wall is clamped [m], > 0.
    r1_m : rim radius of the cavity-facing surface [m], > r0_m.
    alpha_deg : cone angle between the wall and the substrate plane, in (0, 90) degrees.
    thickness : wall thickness d(r) [m] as a function of the lower-surface radius r [m].
    thickness_convention : "normal" (offset along the lower surface's normal) or "vertical".
    name : a label for provenance.
    """

    r0_m: float
    r1_m: float
    alpha_deg: float
    thickness: ThicknessProfile
    thickness_convention: ThicknessConvention = "normal"
    name: str = "custom"
    _n_check: int = field(default=401, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.r0_m) and self.r0_m > 0):
            raise ValueError(f"r0_mm: top-plate radius must be > 0 mm, got {self.r0_m / _MM:g}")
        if not (math.isfinite(self.r1_m) and self.r1_m > self.r0_m):
            raise ValueError(f"r1_mm: rim radius must be > r0 = {self.r0_m / _MM:g} mm, "
                             f"got {self.r1_m / _MM:g}")
        if not (math.isfinite(self.alpha_deg) and 0 < self.alpha_deg < 90):
            raise ValueError(f"alpha_deg: cone angle must be in (0, 90) degrees, got {self.alpha_deg:g}")
        if self.thickness_convention not in _CONVENTIONS:
            raise ValueError(f"thickness_convention: must be one of {', '.join(_CONVENTIONS)}, "
                             f"got {self.thickness_convention!r}")
        if isinstance(self.thickness, TabulatedThickness):
            lo, hi = self.thickness.r_m[0], self.thickness.r_m[-1]
            if lo > self.r0_m * (1 + 1e-12) or hi < self.r1_m * (1 - 1e-12):
                raise ValueError(f"thickness: the table covers r in [{lo / _MM:g}, {hi / _MM:g}] mm "
                                 f"but the wall spans [{self.r0_m / _MM:g}, {self.r1_m / _MM:g}] mm")
        s = self._check_parameters()
        d = np.asarray(self.thickness(self.lower_radius(s)), dtype=float)
        if d.shape != s.shape or not np.all(np.isfinite(d)):
            raise ValueError("thickness: the profile must return one finite value per radius")
        if np.any(d <= 0):
            r_bad = self.lower_radius(s)[np.argmax(d <= 0)]
            raise ValueError(f"thickness: wall thickness must be > 0 mm on [r0, r1], got "
                             f"{d.min() / _MM:.4g} mm (first at r = {r_bad / _MM:.4g} mm)")
        polygon = self.boundary_polygon(101)
        if np.any(polygon[:, 0] < 0):
            raise ValueError("geometry: the wall crosses the axis r = 0; reduce the thickness near r0 "
                             "or use thickness_convention='vertical'")
        if polygon_self_intersects(polygon):
            raise ValueError("geometry: the wall's cross-section intersects itself; reduce the "
                             "thickness or its gradient, or use thickness_convention='vertical'")

    # ------------------------------------------------------------- the map
    @property
    def alpha_rad(self) -> float:
        return math.radians(self.alpha_deg)

    @property
    def h1_m(self) -> float:
        """Undeformed cup height h1 = (r1 - r0) tan(alpha) of the cavity-facing surface [m]."""
        return (self.r1_m - self.r0_m) * math.tan(self.alpha_rad)

    @property
    def slant_length_m(self) -> float:
        """Length L of the cavity-facing surface [m]."""
        return (self.r1_m - self.r0_m) / math.cos(self.alpha_rad)

    @property
    def offset_direction(self) -> np.ndarray:
        """Unit vector e along which the thickness is measured: n = (sin a, cos a) or e_z."""
        a = self.alpha_rad
        return np.array([math.sin(a), math.cos(a)]) if self.thickness_convention == "normal" \
            else np.array([0.0, 1.0])

    def lower_radius(self, s: np.ndarray) -> np.ndarray:
        """Radius r(s) = r0 + s (r1 - r0) of the lower-surface point at wall coordinate s [m]."""
        return self.r0_m + np.asarray(s, dtype=float) * (self.r1_m - self.r0_m)

    def thickness_at(self, s: np.ndarray) -> np.ndarray:
        """Wall thickness d(r(s)) [m]."""
        return np.asarray(self.thickness(self.lower_radius(s)), dtype=float)

    def point(self, s: np.ndarray, t: np.ndarray) -> np.ndarray:
        """x(s, t) = P(s) + t d(r(s)) e: shape (2, ...) of (r, z) [m]; s along, t through the wall."""
        s, t = np.broadcast_arrays(np.asarray(s, float), np.asarray(t, float))
        r = self.lower_radius(s)
        z = self.h1_m * (1.0 - s)
        offset = t * self.thickness_at(s)
        e = self.offset_direction
        return np.stack([r + offset * e[0], z + offset * e[1]])

    def boundary_polygon(self, n: int = 401) -> np.ndarray:
        """The closed cross-section outline, counter-clockwise, shape (4 (n - 1), 2) [m].

        Cavity surface (top plate -> rim), rim edge, outer surface (rim -> plate), plate edge.
        """
        u = np.linspace(0.0, 1.0, n)[:-1]
        sides = [(u, 0 * u), (1 + 0 * u, u), (1 - u, 1 + 0 * u), (0 * u, 1 - u)]
        return np.concatenate([self.point(s, t).T for s, t in sides])

    def cavity_volume_m3(self) -> float:
        """Undeformed cavity volume, the frustum pi h1 (r0^2 + r0 r1 + r1^2) / 3 (eq. 4 at h = h1)."""
        r0, r1 = self.r0_m, self.r1_m
        return math.pi * self.h1_m * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0

    def describe(self) -> dict[str, Any]:
        """Plain-data description for provenance (mm and degrees)."""
        d = self.thickness_at(np.array([0.0, 1.0])) / _MM
        return {"name": self.name, "r0_mm": self.r0_m / _MM, "r1_mm": self.r1_m / _MM,
                "alpha_deg": self.alpha_deg, "h1_mm": self.h1_m / _MM,
                "thickness_convention": self.thickness_convention,
                "d_at_r0_mm": float(d[0]), "d_at_r1_mm": float(d[1]),
                "thickness_profile": _describe_profile(self.thickness)}

    def _check_parameters(self) -> np.ndarray:
        s = np.linspace(0.0, 1.0, self._n_check)
        if isinstance(self.thickness, TabulatedThickness):   # include the knots inside the wall
            knots = (np.asarray(self.thickness.r_m) - self.r0_m) / (self.r1_m - self.r0_m)
            s = np.union1d(s, knots[(knots > 0) & (knots < 1)])
        return s


def _describe_profile(profile: ThicknessProfile) -> dict[str, Any]:
    if isinstance(profile, LinearThickness):
        return {"kind": "linear", "r_mm": [profile.r_a_m / _MM, profile.r_b_m / _MM],
                "d_mm": [profile.d_a_m / _MM, profile.d_b_m / _MM]}
    if isinstance(profile, TabulatedThickness):
        return {"kind": "table", "r_mm": [r / _MM for r in profile.r_m],
                "d_mm": [d / _MM for d in profile.d_m]}
    return {"kind": "callable", "repr": repr(profile)}


# ------------------------------------------------------------------- presets
#: Table 1 and Sec. 5.5: (alpha_deg, d at r = 5 mm, d at r = 20 mm), r0 = 5 mm, r1 = 19 mm
PRESETS: dict[str, dict[str, float]] = {
    "A": {"alpha_deg": 33.0, "d_inner_mm": 2.5, "d_outer_mm": 0.3},
    "B": {"alpha_deg": 21.0, "d_inner_mm": 1.5, "d_outer_mm": 0.3},
}


def cup_geometry(cup: str = "A", **overrides: Any) -> CupGeometry:
    """The paper's cup A or B (Table 1, Sec. 5.5), with any `CupGeometry` field overridden.

    The thickness line runs through d(5 mm) and d(20 mm) as the paper gives them (its second
    point lies beyond the rim r1 = 19 mm) and is evaluated on [r0, r1] = [5, 19] mm.
    Example: ``cup_geometry("B", thickness_convention="vertical")``.
    """
    key = str(cup).upper()
    if key not in PRESETS:
        raise ValueError(f"cup: must be one of {', '.join(PRESETS)}, got {cup!r}")
    p = PRESETS[key]
    base = dict(r0_m=5 * _MM, r1_m=19 * _MM, alpha_deg=p["alpha_deg"],
                thickness=LinearThickness(5 * _MM, p["d_inner_mm"] * _MM, 20 * _MM, p["d_outer_mm"] * _MM),
                thickness_convention="normal", name=f"cup {key}")
    unknown = set(overrides) - set(base)
    if unknown:
        raise ValueError(f"cup_geometry: unknown field(s) {sorted(unknown)}; allowed: {sorted(base)}")
    return CupGeometry(**{**base, **overrides})


# ------------------------------------------------------------------- checks
def polygon_self_intersects(polygon: np.ndarray) -> bool:
    """True if any two non-adjacent edges of the closed polygon (shape (n, 2)) intersect."""
    a = np.asarray(polygon, dtype=float)
    b = np.roll(a, -1, axis=0)
    n = len(a)

    def orient(p, q, r):
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1])
                       - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))

    i, j = np.triu_indices(n, k=2)
    keep = ~((i == 0) & (j == n - 1))          # the first and last edges share a vertex
    i, j = i[keep], j[keep]
    p1, q1, p2, q2 = a[i], b[i], a[j], b[j]
    o1, o2 = orient(p1, q1, p2), orient(p1, q1, q2)
    o3, o4 = orient(p2, q2, p1), orient(p2, q2, q1)
    proper = (o1 * o2 < 0) & (o3 * o4 < 0)
    return bool(np.any(proper))

