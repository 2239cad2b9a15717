"""Surface-roughness power spectra in Persson's convention, and the isotropic 1D <-> 2D relation.

Convention (the only one used inside cupcheck; everything else is converted on input)
---------------------------------------------------------------------------------------
* ``C(q)`` [m^4] is the isotropic 2D spectrum, ``<h^2> = 2 pi int_0^inf q C(q) dq``.
* ``C_1D(q)`` [m^3] is the 1D (line-scan) spectrum of the paper, Sec. 5.1,
  ``C_1D(q) = (1/2pi) int <h(x)h(0)> e^{iqx} dx``, so ``<h^2> = 2 int_0^inf C_1D(q) dq``.
* For isotropic roughness ``C_1D(q) = int_{-inf}^{inf} C(sqrt(q^2 + q_y^2)) dq_y``, i.e. with
  ``q_y = t``: ``C_1D(q) = 2 int_0^inf C(sqrt(q^2 + t^2)) dt`` (forward Abel transform), inverted by
  ``C(q) = -(1/pi) int_q^inf C_1D'(k) (k^2 - q^2)^(-1/2) dk = -(1/pi) int_0^inf C_1D'(k)/k dt``
  with ``k = sqrt(q^2 + t^2)``. Both are evaluated in the variable ``t``, where they are regular.
* Other conventions (``CONVENTIONS``): SurfaceTopography's 1D and 2D PSDs are ``2 pi`` and
  ``(2 pi)^2`` times Persson's; a one-sided 1D PSD with ``<h^2> = int_0^inf S dq`` is ``2 C_1D``.
"""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass, field

import numpy as np

#: factor f with C_persson = C_other / f, per (dimension, convention)
CONVENTIONS: dict[str, tuple[int, float]] = {
    "persson-2d": (2, 1.0),
    "persson-1d": (1, 1.0),
    "surfacetopography-2d": (2, (2 * np.pi) ** 2),   # <h^2> = (1/2pi) int q C dq
    "surfacetopography-1d": (1, 2 * np.pi),          # <h^2> = (1/pi) int_0^inf C dq
    "one-sided-1d": (1, 2.0),                        # <h^2> = int_0^inf S dq
}


def to_persson(C: np.ndarray, convention: str) -> np.ndarray:
    """Convert a PSD given in `convention` (a key of ``CONVENTIONS``) to Persson's convention."""
    if convention not in CONVENTIONS:
        raise ValueError(f"convention: must be one of {sorted(CONVENTIONS)}, got {convention!r}")
    return np.asarray(C, float) / CONVENTIONS[convention][1]


def _trapz(y: np.ndarray, x: np.ndarray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def cumulative_trapezoid(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """int_{x[0]}^{x[i]} y dx by the trapezoid rule, same length as `x` (starts at 0)."""
    out = np.zeros(np.shape(y)[-1])
    out[1:] = np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))
    return out


@dataclass(frozen=True)
class PowerSpectrum:
    """Isotropic 2D power spectrum ``C(q)`` (Persson convention, see module docstring).

    ``q_per_m`` strictly increasing and positive; ``C_m4`` non-negative. Outside
    ``[q_per_m[0], q_per_m[-1]]`` the spectrum is zero: ``q0 = q_per_m[0]`` is the smallest
    wavevector of the contact theory (magnification zeta = q/q0) and ``q1 = q_per_m[-1]`` the cutoff.
    """

    q_per_m: np.ndarray
    C_m4: np.ndarray
    provenance: str = ""
    #: how much of its source this spectrum does not represent (None: exact; a line scan's
    #: quasi-periodic hump has no isotropic equivalent, `isotropic_misfit`)
    misfit: IsotropicMisfit | None = field(default=None, compare=False)
    _moments: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        q = np.asarray(self.q_per_m, float)
        C = np.asarray(self.C_m4, float)
        if q.ndim != 1 or q.size < 3 or q.shape != C.shape:
            raise ValueError(f"q_per_m, C_m4: need two 1D arrays of equal length >= 3, "
                             f"got shapes {q.shape} and {C.shape}")
        if not np.all(np.isfinite(q)) or q[0] <= 0 or np.any(np.diff(q) <= 0):
            raise ValueError("q_per_m: must be finite, positive and strictly increasing")
        if not np.all(np.isfinite(C)) or np.any(C < 0) or not np.any(C > 0):
            raise ValueError("C_m4: must be finite, non-negative and not all zero")
        q.setflags(write=False)
        C.setflags(write=False)
        object.__setattr__(self, "q_per_m", q)
        object.__setattr__(self, "C_m4", C)

    @property
    def q0_per_m(self) -> float:
        return float(self.q_per_m[0])

    @property
    def q1_per_m(self) -> float:
        return float(self.q_per_m[-1])

    def moment(self, n: int) -> np.ndarray:
        """Cumulative ``2 pi int_{q0}^{q} q^(n+1) C dq`` on the grid (n=0: <h^2>, n=2: <|grad h|^2>)."""
        if n not in self._moments:
            # trapezoid in ln q: the integrands are smooth power laws there
            lnq = np.log(self.q_per_m)
            self._moments[n] = 2 * np.pi * cumulative_trapezoid(
                self.q_per_m ** (n + 2) * self.C_m4, lnq)
        return self._moments[n]

    def rolloff_wavelength_m(self) -> float:
        """2 pi / q* [m], q* the wavevector where q^2 C(q) is largest: the wavelength that carries the
        most mean-square height per logarithmic band (d<h^2> / d ln q = 2 pi q^2 C). For
        `self_affine` with a roll-off it is 2 pi / q_r (C flat below q_r, q^2 C rising as q^2, and
        falling as q^(-2H) above), the longest wavelength of the self-affine roughness."""
        return float(2 * np.pi / self.q_per_m[int(np.argmax(self.q_per_m ** 2 * self.C_m4))])

    def h_rms_m(self) -> float:
        """rms height, ``sqrt(2 pi int q C dq)``."""
        return float(np.sqrt(self.moment(0)[-1]))

    def slope_rms(self) -> float:
        """rms slope h'_rms, ``sqrt(2 pi int q^3 C dq)`` (dimensionless)."""
        return float(np.sqrt(self.moment(2)[-1]))

    def line_spectrum(self, q_per_m: np.ndarray | None = None) -> np.ndarray:
        """C_1D(q) [m^3] of this isotropic surface (forward Abel transform, module docstring)."""
        q = self.q_per_m if q_per_m is None else np.asarray(q_per_m, float)
        return isotropic_to_line(self.q_per_m, self.C_m4, q)

    def to_csv(self, path: str | os.PathLike) -> None:
        """Write columns ``q_per_m,C_m4``."""
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["q_per_m", "C_m4"])
            for q, C in zip(self.q_per_m, self.C_m4):
                w.writerow([f"{q:.10g}", f"{C:.10g}"])


def read_psd_csv(path: str | os.PathLike, convention: str = "persson-2d") -> PowerSpectrum:
    """Read a tabulated isotropic C(q) from a CSV with columns ``q_per_m,C_m4``.

    `convention` converts from another normalisation (``CONVENTIONS``; 2D conventions only).
    Rows with C = 0 at the ends are kept (they define the band); rows must be sorted by q.
    """
    if CONVENTIONS.get(convention, (0,))[0] != 2:
        raise ValueError(f"convention: a C(q) table needs a 2D convention, got {convention!r}")
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
    except UnicodeDecodeError:
        raise ValueError(f"psd file {path}: not a UTF-8 text file") from None
    if not rows or [c.strip() for c in rows[0][:2]] != ["q_per_m", "C_m4"]:
        raise ValueError(f"psd file {path}: first line must be the header 'q_per_m,C_m4'")
    try:
        data = np.array([[float(r[0]), float(r[1])] for r in rows[1:] if r], float)
    except (ValueError, IndexError) as exc:
        raise ValueError(f"psd file {path}: every row needs two numbers ({exc})") from None
    if data.shape[0] < 3:
        raise ValueError(f"psd file {path}: need at least 3 rows, got {data.shape[0]}")
    return PowerSpectrum(data[:, 0], to_persson(data[:, 1], convention),
                         provenance=f"psd:{os.fspath(path)}")


# --------------------------------------------------------------------------------------------
# parametric spectra
# --------------------------------------------------------------------------------------------

def log_grid(q0: float, q1: float, n: int) -> np.ndarray:
    """`n` log-spaced wavevectors from `q0` to `q1` [1/m]."""
    return np.geomspace(q0, q1, n)


def self_affine(*, H: float, q0_per_m: float, q1_per_m: float, qr_per_m: float | None = None,
                h_rms_m: float | None = None, C0_m4: float | None = None, n: int = 2000,
                hump: tuple[float, float, float] | None = None) -> PowerSpectrum:
    """Self-affine spectrum with roll-off, optionally with a log-normal hump.

    ``C(q) = C0`` for ``q0 <= q < qr`` and ``C0 (q/qr)^(-2(1+H))`` for ``qr <= q <= q1``
    (Persson's standard form; ``qr = q0`` means no roll-off). Give either `C0_m4` or `h_rms_m`
    (then C0 is scaled so that ``2 pi int q C dq = h_rms^2`` on the grid).
    ``hump = (fraction, q_h, width)`` adds a term ``A exp(-ln(q/q_h)^2 / (2 width^2))`` that carries
    `fraction` of ``<h^2>`` (the table surface of Sec. 5.1 has its hump near q = 1e5 1/m).
    """
    if not 0.0 < H < 1.0:
        raise ValueError(f"H: Hurst exponent must be in (0, 1), got {H}")
    qr = q0_per_m if qr_per_m is None else qr_per_m
    if not 0 < q0_per_m <= qr < q1_per_m:
        raise ValueError(f"q0_per_m <= qr_per_m < q1_per_m required, got "
                         f"{q0_per_m:g}, {qr:g}, {q1_per_m:g}")
    if (h_rms_m is None) == (C0_m4 is None):
        raise ValueError("self_affine: give exactly one of h_rms_m and C0_m4")
    q = log_grid(q0_per_m, q1_per_m, n)
    shape = np.where(q < qr, 1.0, (q / qr) ** (-2 * (1 + H)))
    spec = PowerSpectrum(q, shape)
    base = spec.moment(0)[-1]
    if hump is not None:
        frac, qh, width = hump
        if not 0 <= frac < 1 or qh <= 0 or width <= 0:
            raise ValueError(f"hump: need fraction in [0, 1), q_h > 0, width > 0, got {hump}")
        bump = np.exp(-np.log(q / qh) ** 2 / (2 * width ** 2))
        bump_ms = PowerSpectrum(q, bump).moment(0)[-1]
        # scale the bump so that it carries `frac` of the total mean-square height
        shape = shape + bump * (frac / (1 - frac)) * base / bump_ms
    scale = C0_m4 if C0_m4 is not None else h_rms_m ** 2 / PowerSpectrum(q, shape).moment(0)[-1]
    prov = (f"self-affine H={H:g} q0={q0_per_m:g} qr={qr:g} q1={q1_per_m:g}"
            + (f" hump={hump}" if hump else ""))
    return PowerSpectrum(q, scale * shape, provenance=prov)


# --------------------------------------------------------------------------------------------
# isotropic 1D <-> 2D (Abel pair, module docstring)
# --------------------------------------------------------------------------------------------

def _loglog_interp(x: np.ndarray, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """Power-law interpolation of positive `fp`; zero outside [xp[0], xp[-1]] and where fp = 0."""
    pos = fp > 0
    lf = np.interp(np.log(x), np.log(xp[pos]), np.log(fp[pos]), left=-np.inf, right=-np.inf)
    out = np.exp(lf)
    out[(x < xp[0]) | (x > xp[-1])] = 0.0
    return out


def _abel_nodes(qo: float, q1: float, n_t: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodes for int_0^sqrt(q1^2-qo^2) dt: t = qo sinh(u), u uniform; returns (u, t, k=sqrt(qo^2+t^2)).

    In u the Abel integrands are smooth and decay like power laws of t = exp(u), so the trapezoid
    rule in u converges fast; it is uniform in t near t = 0 and logarithmic for t >> qo.
    """
    u = np.linspace(0.0, np.arcsinh(np.sqrt(q1 ** 2 - qo ** 2) / qo), n_t)
    t = qo * np.sinh(u)
    return u, t, qo * np.cosh(u)


def isotropic_to_line(q: np.ndarray, C: np.ndarray, q_out: np.ndarray,
                      n_t: int = 600) -> np.ndarray:
    """C_1D(q_out) = 2 int_0^sqrt(q1^2 - q_out^2) C(sqrt(q_out^2 + t^2)) dt  (isotropic C).

    Trapezoid rule in u with t = q_out sinh u (``_abel_nodes``); C is interpolated as a power law
    between its grid nodes and is zero outside [q0, q1].
    """
    q = np.asarray(q, float)
    C = np.asarray(C, float)
    q_out = np.atleast_1d(np.asarray(q_out, float))
    out = np.zeros_like(q_out)
    for i, qo in enumerate(q_out):
        if qo >= q[-1]:
            continue
        u, t, k = _abel_nodes(qo, q[-1], n_t)
        out[i] = 2 * _trapz(_loglog_interp(k, q, C) * qo * np.cosh(u), u)
    return out


def line_to_isotropic(q: np.ndarray, C1D: np.ndarray, q_out: np.ndarray | None = None,
                      n_t: int = 600) -> np.ndarray:
    """Invert the isotropic Abel relation: C(q) = -(1/pi) int_0^inf [dC_1D/dk / k] dt, k = sqrt(q^2+t^2).

    ``dC_1D/dk`` is taken in log-log form, ``(C_1D/k) dln C_1D/dln k`` (central differences on
    the given grid), so positive power laws are differentiated exactly. C_1D is zero beyond
    ``q[-1]``, which truncates the integral there (an error confined to the last few % of the band).
    Where the inversion is negative (a C_1D that falls faster than any isotropic surface allows,
    e.g. below a hump) no isotropic C exists: C is set to 0 there, and `isotropic_misfit`
    says how much of the line's roughness that loses.
    """
    q = np.asarray(q, float)
    C1D = np.asarray(C1D, float)
    if np.any(C1D <= 0):
        raise ValueError("C1D: the 1D spectrum must be positive on its grid for the inversion")
    q_out = q if q_out is None else np.atleast_1d(np.asarray(q_out, float))
    slope = np.gradient(np.log(C1D), np.log(q))          # d ln C_1D / d ln q
    out = np.zeros_like(q_out)
    for i, qo in enumerate(q_out):
        if qo >= q[-1]:
            continue
        u, t, k = _abel_nodes(qo, q[-1], n_t)
        dC_over_k = _loglog_interp(k, q, C1D) * np.interp(np.log(k), np.log(q), slope) / k ** 2
        out[i] = -_trapz(dC_over_k * qo * np.cosh(u), u) / np.pi
    return np.maximum(out, 0.0)



@dataclass(frozen=True)
class IsotropicMisfit:
    """How far an isotropic C(q) falls short of the line spectrum C_1D it was inverted from
    (`isotropic_misfit`): `share` of the line's mean-square height not reproduced, and the width
    in decades of q where the round trip misses C_1D by more than a factor of 2."""

    share: float
    decades: float

    def describe(self) -> str:
        return (f"{100 * self.share:.2g} % of <h^2> not represented, C_1D missed by > 2x over "
                f"{self.decades:.2g} decades")


def isotropic_misfit(q: np.ndarray, C1D: np.ndarray, C: np.ndarray) -> IsotropicMisfit:
    """Round trip of `C` (on the grid `q`, e.g. from `line_to_isotropic`) back to C_1D, compared
    with `C1D` over ``q <= q[-1]/2`` (the top octave carries the truncation at ``q[-1]``):
    ``share = int |C_1D,back - C_1D| dq / int C_1D dq``. A power law: share ~1e-6, 0 decades; a
    Gaussian hump carrying 5 % of <h^2>: 6 %, 0.6 decades below the hump."""
    q, C1D, C = (np.asarray(a, float) for a in (q, C1D, C))
    band = q <= q[-1] / 2
    if band.sum() < 2 or not np.any(C > 0):
        return IsotropicMisfit(1.0, float(np.log10(q[-1] / q[0])))
    good = C > 0
    back = isotropic_to_line(q[good], C[good], q[band])
    share = _trapz(np.abs(back - C1D[band]), q[band]) / _trapz(C1D[band], q[band])
    off = np.abs(np.log(np.maximum(back, 1e-300) / C1D[band])) > np.log(2.0)
    width = np.gradient(np.log10(q[band]))
    return IsotropicMisfit(float(share), float(np.sum(width * off)))
