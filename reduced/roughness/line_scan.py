"""From a stylus line scan z(x) to the isotropic 2D power spectrum C(q) (paper Sec. 5.1).

Route: uniform-spacing check -> linear detrend -> Hann window (normalised to mean(w^2) = 1, which
keeps <h^2> of a stationary profile) -> periodogram in the paper's convention
``C_1D(q_k) = |dx sum_n w_n h_n e^(-i q_k x_n)|^2 / (2 pi L)`` at ``q_k = 2 pi k / L``
(so ``2 sum_k C_1D dq = <h^2>``) -> tip-radius cutoff -> log-binning (20 bins per decade) -> smoothing of ln C_1D
(Savitzky-Golay, quadratic, ~1/3 decade: the inversion differentiates C_1D) -> the exact isotropic
Abel inversion `spectrum.line_to_isotropic`. The two lowest periodogram points (inside the Hann
window's main lobe around q = 0, where the detrended mean leaks) are dropped.

Tip-radius cutoff (our choice, stated here): a stylus of tip radius R follows a sinusoid of
amplitude a and wavevector q only if its curvature a q^2 stays below 1/R. The roughness in a band
of unit width in ln q around q has mean square ``2 q C_1D(q)``; a sinusoid with that mean square has
amplitude ``a(q) = sqrt(4 q C_1D(q))``. The spectrum is cut at the first q (after log-binning) with
``a(q) q^2 > 1/R``, and never above half the Nyquist wavevector (the top octave holds window
leakage and aliasing). It is a scale estimate, not a deconvolution of the tip.

No silent clipping: a quasi-periodic profile (a hump in C_1D) has no isotropic equivalent below
its hump (the inversion is negative there and is set to zero). How much of the line spectrum the
isotropic C(q) does not reproduce travels with the spectrum (``misfit``, and its provenance): a
`SpectrumWarning` where the round trip misses C_1D by more than 2x anywhere, a ValueError when
more than ``REFUSE_SHARE`` of the mean-square height is not represented.
"""

from __future__ import annotations

import csv
import os
import warnings
from pathlib import Path

import numpy as np

from .spectrum import PowerSpectrum, isotropic_misfit, line_to_isotropic

#: above this share of <h^2> not represented by the isotropic C(q): refused (the isotropic
#: model would describe another surface)
REFUSE_SHARE = 0.25


class SpectrumWarning(UserWarning):
    """A spectrum that represents its source only in part (the share is in the message)."""

_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "nm": 1e-9}


def _text(path, what: str) -> str:
    """The file's text; a file that is not UTF-8 text is an input error naming `what`."""
    try:
        return Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ValueError(f"{what} {path}: not a UTF-8 text file") from None


def read_line_scan(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """(x [m], z [m]) from a CSV whose header is ``x_<unit>,z_<unit>``, unit in m, mm, um, nm."""
    rows = [r for r in csv.reader(_text(path, "line scan").splitlines()) if r]
    if not rows:
        raise ValueError(f"line scan {path}: file is empty")
    head = [c.strip() for c in rows[0][:2]]
    try:
        (xn, xu), (zn, zu) = (h.split("_", 1) for h in head)
        sx, sz = _UNITS[xu], _UNITS[zu]
        assert (xn, zn) == ("x", "z")
    except (ValueError, KeyError, AssertionError):
        raise ValueError(f"line scan {path}: header must be x_<unit>,z_<unit> with unit in "
                         f"{sorted(_UNITS)}, got {','.join(head)!r}") from None
    try:
        data = np.array([[float(r[0]), float(r[1])] for r in rows[1:]], float)
    except (ValueError, IndexError) as exc:
        raise ValueError(f"line scan {path}: every row needs two numbers ({exc})") from None
    bad = np.flatnonzero(~np.all(np.isfinite(data), axis=1)) if data.size else []
    if len(bad):
        raise ValueError(f"line scan {path}: row {int(bad[0]) + 2}: x and z must be finite")
    if data.shape[0] < 64:
        raise ValueError(f"line scan {path}: need at least 64 points, got {data.shape[0]}")
    return data[:, 0] * sx, data[:, 1] * sz


def line_periodogram(x_m: np.ndarray, z_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(q [1/m], C_1D [m^3]) for k = 1 .. N/2 of a detrended, Hann-windowed uniform profile."""
    x = np.asarray(x_m, float)
    z = np.asarray(z_m, float)
    if x.shape != z.shape or x.ndim != 1 or x.size < 64:
        raise ValueError("line scan: x and z must be 1D arrays of equal length >= 64")
    dx = np.diff(x)
    if np.any(dx <= 0) or np.ptp(dx) > 1e-3 * dx.mean():
        raise ValueError("line scan: x must be increasing and uniformly spaced (to 0.1 %)")
    n, step = x.size, dx.mean()
    h = z - np.polyval(np.polyfit(x - x.mean(), z, 1), x - x.mean())
    w = np.hanning(n)
    w /= np.sqrt(np.mean(w ** 2))
    L = n * step
    Hk = step * np.fft.rfft(w * h)
    k = np.arange(1, n // 2 + 1)
    return 2 * np.pi * k / L, np.abs(Hk[k]) ** 2 / (2 * np.pi * L)


def log_bin(q: np.ndarray, C: np.ndarray, per_decade: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """Average C in log-spaced bins of q (geometric-mean q); empty bins dropped."""
    edges = np.geomspace(q[0], q[-1] * (1 + 1e-12), int(np.ceil(per_decade * np.log10(q[-1] / q[0]))) + 1)
    idx = np.digitize(q, edges) - 1
    keep = np.bincount(idx, minlength=edges.size - 1) > 0
    cnt = np.bincount(idx, minlength=edges.size - 1)[keep]
    qb = np.exp(np.bincount(idx, np.log(q), minlength=edges.size - 1)[keep] / cnt)
    Cb = np.bincount(idx, C, minlength=edges.size - 1)[keep] / cnt
    return qb, Cb


def tip_cutoff(q: np.ndarray, C1D: np.ndarray, tip_radius_m: float) -> float:
    """Largest q [1/m] the stylus resolves: first q with sqrt(4 q C_1D) q^2 > 1/R (module doc)."""
    bad = np.sqrt(4 * q * C1D) * q ** 2 > 1.0 / tip_radius_m
    return float(q[np.argmax(bad)] if np.any(bad) else q[-1])


def spectrum_from_line_scan(x_m: np.ndarray, z_m: np.ndarray, tip_radius_m: float = 1e-6,
                            per_decade: int = 20) -> PowerSpectrum:
    """Isotropic C(q) from one line scan (assumes isotropic roughness; module doc for each step)."""
    if not tip_radius_m > 0:
        raise ValueError(f"tip_radius_m: stylus tip radius must be > 0, got {tip_radius_m}")
    q, C1 = line_periodogram(x_m, z_m)
    q, C1 = q[2: max(len(q) // 2, 8)], C1[2: max(len(q) // 2, 8)]   # window lobe; top octave
    qb, Cb = log_bin(q, C1, per_decade)
    keep = qb <= tip_cutoff(qb, Cb, tip_radius_m)
    qb, Cb = qb[keep & (Cb > 0)], Cb[keep & (Cb > 0)]
    if qb.size < 8:
        raise ValueError("line scan: fewer than 8 usable spectral bins after the tip cutoff")
    # the Abel inversion differentiates C_1D: smooth ln C_1D over ~1/3 decade first
    win = min(2 * (per_decade // 6) + 1, qb.size - (1 - qb.size % 2))
    from scipy.signal import savgol_filter   # here: scipy.signal costs 0.3 s to import
    Cs = np.exp(savgol_filter(np.log(Cb), max(win, 3), 2)) if win >= 3 else Cb
    C = line_to_isotropic(qb, Cs)
    misfit = isotropic_misfit(qb, Cs, C)
    what = (f"the isotropic C(q) of this line scan: {misfit.describe()} (a quasi-periodic profile, a "
            f"hump in C_1D, has no isotropic equivalent below it)")
    if misfit.share > REFUSE_SHARE:
        raise ValueError(f"line scan: {what}; refusing above {100 * REFUSE_SHARE:g} %")
    if misfit.decades > 0:
        warnings.warn(what, SpectrumWarning, stacklevel=2)
    good = C > 0
    return PowerSpectrum(qb[good], C[good], misfit=misfit,
                         provenance=f"line scan, tip radius {tip_radius_m:g} m, {qb.size} bins, {misfit.describe()}")
