"""Geometry of the deformed cup from plain arrays: cavity volume, contact radius, strip widths.

Pure functions of node coordinates and nodal contact pressures (SI units), independent of the
solver, each checked against closed forms in ``tests/test_fem_postprocess.py``.

- `enclosed_volume`: the cavity volume V of eq. (4), by the divergence theorem on the deformed
  cavity-facing polyline.
- `inner_contact_radius`: r_c, the inner edge of the contact (cf. eq. 3); `outer_contact_radius`:
  the outer edge of a contact whose pressure falls to zero outwards (a square-root edge fitted
  through the samples near it; the verification against Hertz).
- `pressure_weighted_width`, `half_maximum_width`, `median_force_width` and `quartile_width`:
  four definitions of the contact-strip width l of eqs. (5)-(6), all exact for the paper's
  uniform strip. The median-force and the force-quartile widths rest on the cumulative line
  force int p dr alone, over the innermost contact zone (the first of `contact_zones`: the
  sealing strip next to r_c, without a separate rim-corner contact); the quartile width also does
  without the contact edge r_c, which jumps from node to node, and is the one that converges with
  the mesh (for frictionless contact; benchmarks/bench_mesh_levels.py).
  The other two react to a singular rim-corner pressure (benchmarks/bench_strip_width.py).

Pressure profiles p(r) are sampled at increasing radii and taken piecewise-linear between the
samples; integrals of such profiles are exact (no quadrature error beyond the interpolation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["enclosed_volume", "inner_contact_radius", "outer_contact_radius", "pressure_weighted_width",
           "weighted_width", "half_maximum_width", "median_force_width", "quartile_width",
           "contact_zones", "contact_force", "Richardson", "richardson", "smallest_stretch",
           "BIOT_STRETCH", "CREASE_STRETCH"]

#: the smallest principal stretch at which a compressed neo-Hookean surface stays smooth: Biot's
#: wrinkling bifurcation of an incompressible half-space in plane strain (M. A. Biot, Appl. Sci.
#: Res. A 12, 168 (1963): lambda = 0.544); creases nucleate earlier, near 0.65 (Hohlfeld &
#: Mahadevan, PRL 106, 105702 (2011)). Beyond them a compressed free surface folds on a length
#: scale the model does not fix, so the refined mesh follows folds the coarser ones cannot.
BIOT_STRETCH = 0.544
CREASE_STRETCH = 0.65


def smallest_stretch(f: np.ndarray) -> np.ndarray:
    """The smallest principal stretch at each point of the axisymmetric deformation gradient
    f = (F_rR, F_rZ, F_zR, F_zZ, F_tt) [5, ...]: min(sqrt(smallest eigenvalue of the in-plane
    C = F^T F), |F_tt|)."""
    c11 = f[0] ** 2 + f[2] ** 2
    c22 = f[1] ** 2 + f[3] ** 2
    c12 = f[0] * f[1] + f[2] * f[3]
    half_trace = 0.5 * (c11 + c22)
    radius = np.sqrt(0.25 * (c11 - c22) ** 2 + c12**2)
    det = (f[0] * f[3] - f[1] * f[2]) ** 2
    smallest = det / (half_trace + radius)          # the small eigenvalue without cancellation
    return np.minimum(np.sqrt(smallest), np.abs(f[4]))


def enclosed_volume(r_m: np.ndarray, z_m: np.ndarray, in_contact: np.ndarray | None = None) -> float:
    """Volume of revolution of the cavity [m^3] (the region of eq. 4).

    Parameters
    ----------
    r_m, z_m : the deformed cavity-facing surface, ordered from the top-plate edge (index 0) to
        the rim (shape (n,)), e.g. the nodes of `fem.mesh.boundary_path(mesh, "cavity")`.
    in_contact : boolean mask of the points touching the plane z = 0; by default the points with
        z <= 0. The surface is followed down to its first contact point.

    The region is bounded by the plate roof z = z_m[0] from the axis to r_m[0], the surface down
    to the innermost contact point k, the vertical drop from (r_k, z_k) to z = 0 (zero length
    unless the point penetrates or hovers), and the plane z = 0 back to the axis. By the
    divergence theorem (Green's theorem in the meridian plane), V = 2 pi int r dA =
    pi oint r^2 dz (counter-clockwise), which for straight segments is exactly

        V = (pi / 3) sum_i (z_i - z_{i+1}) (r_i^2 + r_i r_{i+1} + r_{i+1}^2)

    (horizontal and axial segments contribute nothing). An undeformed cone gives the frustum.
    """
    r, z = _profile(r_m, z_m)
    contact = (z <= 0.0) if in_contact is None else np.asarray(in_contact, dtype=bool)
    if contact.shape != r.shape:
        raise ValueError(f"in_contact: expected {r.size} flags, got {contact.size}")
    if not contact.any():
        raise ValueError("in_contact: the cavity is not closed, no point of the surface touches z = 0")
    k = int(np.argmax(contact))
    rr = np.append(r[:k + 1], r[k])
    zz = np.append(z[:k + 1], 0.0)
    dz = zz[:-1] - zz[1:]
    return float(math.pi / 3.0 * np.sum(dz * (rr[:-1] ** 2 + rr[:-1] * rr[1:] + rr[1:] ** 2)))


def inner_contact_radius(r_m: np.ndarray, p_Pa: np.ndarray, threshold_Pa: float = 0.0) -> float:
    """Inner edge r_c [m] of the contact, from nodal pressures at increasing radii.

    Let k be the first sample with p > threshold. If k > 0 the edge lies in (r_{k-1}, r_k]; it is
    placed where a square-root edge p ~ sqrt(r - r_c), the shape at the edge of a smooth
    (Hertz-like) contact, through the samples k and k+1 vanishes, i.e. where p^2 extrapolates
    linearly to zero, clamped to [r_{k-1}, r_k]. A pressure falling away from the edge (p_{k+1}
    <= p_k) or a contact reaching the first sample gives r_c = r_k.
    """
    r, p = _profile(r_m, p_Pa, increasing=True)
    k = _first_loaded(p, threshold_Pa)
    if k == 0 or k + 1 >= r.size or p[k + 1] <= p[k]:
        return float(r[k])
    q0, q1 = p[k] ** 2, p[k + 1] ** 2
    edge = r[k] - (r[k + 1] - r[k]) * q0 / (q1 - q0)
    return float(np.clip(edge, r[k - 1], r[k]))


def outer_contact_radius(r_m: np.ndarray, p_Pa: np.ndarray, band_m: float) -> float:
    """Outer edge a [m] of a contact whose pressure falls to zero outwards (Hertz's, say), from
    nodal pressures at increasing radii, without assuming the shape of the profile inside.

    Near a smooth contact edge the pressure is a square root, p^2 = (a - r) g(r) with g smooth,
    so p^2 is a quadratic in r up to O((a - r)^3). The quadratic is fitted (least squares) to p^2
    of the loaded samples (p > 0) within `band_m` of the outermost one, and a is its root
    nearest that sample. The fit averages the sample-to-sample scatter of a lumped nodal
    pressure, so a is resolved to a fraction of the sample spacing; for Hertz's profile p^2 is
    exactly quadratic in r and the fit has no model error. Needs >= 4 samples in the band.
    """
    r, p = _profile(r_m, p_Pa, increasing=True)
    loaded = np.flatnonzero(p > 0)
    if loaded.size == 0:
        raise ValueError("p_Pa: no positive contact pressure, the contact edge is undefined")
    edge = r[loaded[-1]]
    band = loaded[r[loaded] >= edge - band_m]
    if band.size < 4:
        raise ValueError(f"band_m: {band_m:.3g} m holds {band.size} loaded samples, the fit needs "
                         ">= 4 (widen the band)")
    x, y = r[band] / edge - 1.0, (p[band] / p[band].max()) ** 2     # scaled: a well-posed fit
    roots = np.roots(np.polyfit(x, y, 2))
    real = roots[np.abs(roots.imag) <= 1e-12 * np.abs(roots).max()].real
    if real.size == 0:
        raise ValueError("p_Pa: the pressure does not fall to zero at the edge (no real root)")
    return float(edge * (1.0 + real[np.argmin(np.abs(real))]))


def contact_force(r_m: np.ndarray, p_Pa: np.ndarray) -> float:
    """Total normal force 2 pi int p r dr [N] of the piecewise-linear pressure profile."""
    r, p = _profile(r_m, p_Pa, increasing=True)
    return float(2 * math.pi * _integral_pr(r, p, p * 0 + 1))


def pressure_weighted_width(r_m: np.ndarray, p_Pa: np.ndarray, r_c_m: float | None = None) -> float:
    """Strip width l_w = (int p dA)^2 / (2 pi r_c int p^2 dA) [m], dA = 2 pi r dr.

    The width that makes eq. (6), p = F0 / (2 pi r_c l), give the load-weighted mean contact
    pressure <p> = int p^2 dA / int p dA when F0 = int p dA. For a
    uniform pressure on r_c < r < r_c + l it is l (1 + l / (2 r_c)), i.e. l for a strip narrow
    compared with its radius; for a linear fall from the edge to zero over l (a triangle) it is
    3 l / 4 in that limit. Insensitive to the exact position of the contact edge, but int p^2
    weights a singular pressure (a sharp rim corner) heavily, so it scatters 10-30 % between mesh
    levels there (benchmarks/bench_strip_width.py). `r_c_m` defaults to `inner_contact_radius`.
    """
    r, p = _profile(r_m, p_Pa, increasing=True)
    if not np.any(p > 0):
        raise ValueError("p_Pa: no positive contact pressure, the strip width is undefined")
    r_c = inner_contact_radius(r, p) if r_c_m is None else float(r_c_m)
    one = np.ones_like(p)
    return weighted_width(2 * math.pi * _integral_pr(r, p, one),      # int p dA
                          2 * math.pi * _integral_pr(r, p, p), r_c)     # int p^2 dA


def weighted_width(force_N: float, p2_integral: float, r_c_m: float) -> float:
    """l_w = F^2 / (2 pi r_c int p^2 dA) [m] from the two integrals F = int p dA and int p^2 dA
    (0 when there is no pressure): the one formula behind `pressure_weighted_width`."""
    return float(force_N**2 / (2 * math.pi * r_c_m * p2_integral)) if p2_integral > 0 else 0.0


def half_maximum_width(r_m: np.ndarray, p_Pa: np.ndarray, r_c_m: float | None = None) -> float:
    """Full width at half maximum [m] of the piecewise-linear pressure profile.

    The interval around the largest pressure on which p >= max(p)/2, its ends found by linear
    interpolation between samples; the inner end is not taken inside the contact edge r_c
    (`r_c_m`, default `inner_contact_radius`), so a pressure peaking at the edge gives exactly
    the half-maximum distance from the edge. A uniform strip of width l gives l, a triangle
    falling from the edge l/2, a Hertz-like ellipse of half-width a gives sqrt(3) a.
    """
    r, p = _profile(r_m, p_Pa, increasing=True)
    if not np.any(p > 0):
        raise ValueError("p_Pa: no positive contact pressure, the strip width is undefined")
    r_c = inner_contact_radius(r, p) if r_c_m is None else float(r_c_m)
    peak = int(np.argmax(p))
    half = 0.5 * p[peak]
    lo = peak
    while lo > 0 and p[lo - 1] >= half:
        lo -= 1
    hi = peak
    while hi < r.size - 1 and p[hi + 1] >= half:
        hi += 1
    left = r[lo] if lo == 0 else _crossing(r[lo - 1], p[lo - 1], r[lo], p[lo], half)
    right = r[hi] if hi == r.size - 1 else _crossing(r[hi], p[hi], r[hi + 1], p[hi + 1], half)
    return float(right - max(left, r_c))


def median_force_width(r_m: np.ndarray, p_Pa: np.ndarray, r_c_m: float | None = None,
                       innermost: bool = True) -> float:
    """Median-force strip width l_m = 2 (r_half - r_c) [m] of the sealing strip next to r_c.

    r_half is where the radial line force int_{r_c}^{r} p dr (trapezoid rule on the samples, p
    interpolated at r_c; nothing inside r_c counts) reaches half of its total over the strip: half the load of the strip acts within l_m / 2 of its inner
    edge. For the paper's uniform strip (eq. 6) it is exactly l; for a triangle falling from the
    edge to zero over w it is (2 - sqrt 2) w. It rests on a cumulative integral of p only, so a
    concentrated (even singular) pressure moves it by what it carries and no more: unlike int p^2
    in `pressure_weighted_width`, it converges with the mesh. `r_c_m` defaults to
    `inner_contact_radius`.

    The strip is the innermost contact zone (`innermost=True`): the samples from r_c up to the
    first one beyond it where the pressure is back to zero. A wall pressed onto the plane can
    touch it in two places, the rim corner and, from the mid-wall touchdown on, an inner strip
    that grows inwards; the zones are separated by a gap (free nodes, p = 0). The paper's l is
    the width of the sealing strip next to r_c (eqs. 5-6: the strip at the cavity's edge through
    which the air leaks), so the outer zone is left out: its load sits at a sharp corner over a
    width the mesh does not resolve, and counted with the strip it made l_m scatter between mesh
    levels by its load times its distance from the strip. `innermost=False` integrates over all
    zones outwards of r_c.
    """
    r, p = _profile(r_m, p_Pa, increasing=True)
    if not np.any(p > 0):
        raise ValueError("p_Pa: no positive contact pressure, the strip width is undefined")
    r_c = inner_contact_radius(r, p) if r_c_m is None else float(r_c_m)
    p = np.clip(p, 0.0, None)
    if innermost:
        r, p = _innermost_zone(r, p)
    beyond = r > r_c                 # the profile from the edge on: p interpolated at r_c
    r, p = np.concatenate([[r_c], r[beyond]]), np.concatenate([[np.interp(r_c, r, p)], p[beyond]])
    if r.size < 2 or not np.any(p > 0):
        return 0.0
    return float(2.0 * (_load_quantile(r, p, 0.5) - r_c))


def quartile_width(r_m: np.ndarray, p_Pa: np.ndarray, innermost: bool = True) -> float:
    """Force-quartile strip width l_q = 2 (r_75 - r_25) [m] of the sealing strip.

    r_25 and r_75 are where the radial line force int p dr (trapezoid rule on the samples), taken
    from the inner end of the strip outwards, reaches a quarter and three quarters of its total:
    the middle half of the strip's load lies within l_q / 2. For the paper's uniform strip
    (eq. 6) it is exactly l, for a triangle falling from the edge to zero over w it is
    (sqrt 3 - 1) w. Unlike `median_force_width` it does not use the contact edge r_c: where the
    pressure peaks at the edge (a wall pressed flat onto the plane), r_c jumps by a node spacing
    each time the contact front passes a node, and 2 (r_half - r_c) jumps by twice that, while
    the quartiles of the cumulative load move continuously. The strip is the innermost contact
    zone (see `median_force_width`) unless `innermost=False`.
    """
    r, p = _profile(r_m, p_Pa, increasing=True)
    if not np.any(p > 0):
        raise ValueError("p_Pa: no positive contact pressure, the strip width is undefined")
    p = np.clip(p, 0.0, None)
    if innermost:
        r, p = _innermost_zone(r, p)
    return float(2.0 * (_load_quantile(r, p, 0.75) - _load_quantile(r, p, 0.25)))


def _load_quantile(r: np.ndarray, p: np.ndarray, fraction: float) -> float:
    """The radius where the trapezoidal line force int_{r_0}^{r} p dr reaches `fraction` of its total."""
    cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(r))])
    target = fraction * cumulative[-1]
    i = max(int(np.searchsorted(cumulative, target)), 1)     # first sample at or past the target
    return float(r[i]) if cumulative[i] == target else \
        _crossing_cumulative(r[i - 1], r[i], p[i - 1], p[i], target - cumulative[i - 1])


def contact_zones(r_m: np.ndarray, p_Pa: np.ndarray) -> list[tuple[float, float]]:
    """The contact zones [(r_in, r_out), ...] [m] of a sampled pressure profile, inner first.

    A zone is a maximal run of samples with p > 0; it extends to the zero-pressure samples on
    either side (where the piecewise-linear p returns to zero), or ends at the first or last
    sample if it is loaded."""
    r, p = _profile(r_m, p_Pa, increasing=True)
    loaded = p > 0
    starts = np.flatnonzero(loaded & ~np.concatenate([[False], loaded[:-1]]))
    ends = np.flatnonzero(loaded & ~np.concatenate([loaded[1:], [False]]))
    return [(float(r[max(a - 1, 0)]), float(r[min(b + 1, r.size - 1)])) for a, b in zip(starts, ends)]


def _innermost_zone(r: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The samples up to the first zero after the first loaded one (the innermost contact zone)."""
    k = _first_loaded(p, 0.0)
    free = np.flatnonzero(p[k:] <= 0.0)
    end = r.size if free.size == 0 else k + int(free[0]) + 1
    return r[:end], p[:end]


def _crossing_cumulative(r0: float, r1: float, p0: float, p1: float, target: float) -> float:
    """The x in [r0, r1] where the integral of the linear p from r0 reaches `target`."""
    h = r1 - r0
    a, b = 0.5 * (p1 - p0) / h, p0            # int_0^x (p0 + (p1-p0) s/h) ds = b x + a x^2
    if abs(a) * h < 1e-12 * max(abs(b), 1e-300):
        return r0 + target / b
    return r0 + (-b + math.sqrt(max(b * b + 4 * a * target, 0.0))) / (2 * a)


@dataclass(frozen=True)
class Richardson:
    """Richardson extrapolation of a quantity from three meshes with a constant refinement ratio.

    order : observed order p (NaN where the three values do not converge monotonically with an
        order inside `order_range`: not in the asymptotic range, so no extrapolation);
    extrapolated : f_fine + (f_fine - f_medium) / (ratio^p - 1) (f_fine where p is NaN);
    fine_error : |extrapolated - f_fine| (|f_fine - f_medium| where p is NaN), the estimated
        discretisation error of the finest mesh.
    """

    order: np.ndarray
    extrapolated: np.ndarray
    fine_error: np.ndarray


def richardson(f_coarse: np.ndarray, f_medium: np.ndarray, f_fine: np.ndarray,
               ratio: float = 2.0, order_range: tuple[float, float] = (0.5, 6.0)) -> Richardson:
    """Observed order and extrapolated value from meshes of sizes h, h/ratio, h/ratio^2.

    If f_h = f* + C h^p exactly, p = log((f_c - f_m)/(f_m - f_f)) / log(ratio) and f* are
    recovered to round-off. An observed order outside `order_range` means the values are not in
    the asymptotic range (a tiny p extrapolates far beyond the data): such samples are not
    extrapolated (order NaN, the finest value is the reference). Works elementwise on arrays.
    """
    fc, fm, ff = (np.asarray(f, dtype=float) for f in (f_coarse, f_medium, f_fine))
    d1, d2 = fc - fm, fm - ff
    q_lo, q_hi = ratio ** order_range[0], ratio ** order_range[1]
    with np.errstate(divide="ignore", invalid="ignore"):
        q = d1 / d2
        monotone = (q >= q_lo) & (q <= q_hi) & np.isfinite(q)
        p = np.where(monotone, np.log(np.where(monotone, q, 2.0)) / math.log(ratio), np.nan)
        extrapolated = np.where(monotone, ff - d2 / (q - 1.0), ff)   # ratio^p - 1 = q - 1
    fine_error = np.where(monotone, np.abs(extrapolated - ff), np.abs(d2))
    return Richardson(order=p, extrapolated=extrapolated, fine_error=fine_error)


def _crossing(r0: float, p0: float, r1: float, p1: float, level: float) -> float:
    return r0 + (r1 - r0) * (level - p0) / (p1 - p0)


def _integral_pr(r: np.ndarray, f: np.ndarray, g: np.ndarray) -> float:
    """int f g r dr for f, g piecewise linear on the samples: Simpson's rule, exact for cubics."""
    rm = 0.5 * (r[1:] + r[:-1])
    fm, gm = 0.5 * (f[1:] + f[:-1]), 0.5 * (g[1:] + g[:-1])
    h = np.diff(r)
    ends = f[:-1] * g[:-1] * r[:-1] + f[1:] * g[1:] * r[1:]
    return float(np.sum(h / 6.0 * (ends + 4.0 * fm * gm * rm)))


def _first_loaded(p: np.ndarray, threshold: float) -> int:
    loaded = p > threshold
    if not loaded.any():
        raise ValueError(f"p_Pa: no sample exceeds the contact threshold {threshold:g} Pa")
    return int(np.argmax(loaded))


def _profile(a: np.ndarray, b: np.ndarray, increasing: bool = False) -> tuple[np.ndarray, np.ndarray]:
    a, b = np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel()
    if a.size != b.size or a.size < 2:
        raise ValueError(f"profile: need >= 2 matching samples, got {a.size} and {b.size}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("profile: contains NaN or infinite values")
    if increasing and np.any(np.diff(a) <= 0):
        raise ValueError("r_m: radii must be strictly increasing")
    return a, b
