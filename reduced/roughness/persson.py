"""Persson contact mechanics without adhesion: the critical junction and the u_c table.

Notation (Persson convention, see `reduced.roughness.spectrum`): ``E* = E/(1 - nu^2)``,
``p* = p/E*``, ``m(q) = int_{q0}^{q} q'^3 C(q') dq'`` (so ``h'_rms^2 = 2 pi m(q1)``).

* Contact area and mean separation: `reduced.roughness.separation`.
* Critical junction (Lorenz & Persson, Eur. Phys. J. E 31, 159 (2010); percolation threshold
  ``a_c = 0.42`` from Dapp et al., PRL 108, 244301 (2012)): ``zeta_c`` solves ``A(zeta_c)/A0 = a_c``
  (closed form: ``m(zeta_c q0) = (p*/erfinv(a_c))^2/pi``), and ``u_c = u1(zeta_c)`` with
  ``u1(zeta) = u(zeta) + u'(zeta) A(zeta)/A'(zeta)``, where ``u(zeta)`` is the mean separation in the
  apparent contact area at magnification zeta: the same formula applied to the roughness between
  ``zeta q0`` and ``q1`` under the pressure ``p(zeta) = p A0/A(zeta)``. (Derivation: the gap volume
  ``u(zeta) A(zeta)`` of the apparent contact at zeta equals that at zeta + dzeta plus the newly
  resolved non-contact area ``-dA`` at separation u1.) Derivatives are central differences in
  ln zeta (step ``delta = 0.01``).
* If ``A/A0 >= a_c`` at full magnification the contact percolates: the interface is sealed and
  ``u_c = 0`` (reported, never NaN).

"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from reduced.critical_gap import UcTable

from .effective_medium import effective_medium_gap
from .separation import (Moments, contact_area_ratio, effective_modulus, mean_separation,  # noqa: F401
                         noncontact_separation, separation_kernel, small_pressure_slope)
from .spectrum import PowerSpectrum


# --------------------------------------------------------------------------------------------
# the critical junction and the public table
# --------------------------------------------------------------------------------------------

def critical_magnification(mom: Moments, pstar: np.ndarray, a_c: float) -> tuple[np.ndarray, np.ndarray]:
    """(ln q_c, sealed): A(q_c)/A0 = a_c in closed form; sealed where A/A0 >= a_c at q1."""
    from scipy.special import erfinv     # here: scipy.special costs ~0.3 s to import
    m_c = (np.asarray(pstar, float) / erfinv(a_c)) ** 2 / np.pi
    sealed = m_c >= mom.m[-1]
    return mom.lnq_at_m(np.minimum(m_c, mom.m[-1])), sealed


def critical_junction_gap(mom: Moments, pstar: np.ndarray, gamma: float = 0.45,
                          a_c: float = 0.42) -> tuple[np.ndarray, np.ndarray]:
    """(u_c [m], sealed) by the critical-junction route: u_c = u1(zeta_c), 0 where sealed."""
    lnq_c, sealed = critical_magnification(mom, pstar, a_c)
    u_c = np.zeros(np.shape(pstar))
    open_ = ~sealed
    if np.any(open_):
        # u1 -> 0 as zeta_c -> zeta1 (no roughness left); clamp the round-off below 0 there
        u_c[open_] = np.maximum(noncontact_separation(mom, np.asarray(pstar)[open_], lnq_c[open_],
                                                      gamma), 0.0)
    return u_c, sealed


METHODS = ("emt", "critical-junction")



def check_gap_parameters(p_over_E: np.ndarray, method: str, gamma: float, a_c: float) -> None:
    """Raise ValueError naming the field if a table request is out of range (cheap; call first)."""
    if p_over_E.ndim != 1 or p_over_E.size == 0:
        raise ValueError("p_over_E: need a non-empty 1D array of pressures over E")
    if not np.all(np.isfinite(p_over_E)) or np.any(p_over_E <= 0):
        raise ValueError(f"p_over_E: pressures must be finite and > 0, got min {p_over_E.min():g}")
    if method not in METHODS:
        raise ValueError(f"method: must be one of {METHODS}, got {method!r}")
    if not 0.0 <= gamma <= 1.0:
        raise ValueError(f"gamma: Yang-Persson gamma must be in [0, 1], got {gamma}")
    if not 0.0 < a_c < 1.0:
        raise ValueError(f"a_c: percolation threshold A/A0 must be in (0, 1), got {a_c}")


def critical_gap_table(spectrum: PowerSpectrum, E_Pa: float, nu: float, p_over_E,
                       *, method: str = "emt", gamma: float = 0.45, a_c: float = 0.42,
                       n_q: int | None = None,
                       progress: Callable[[float, str], None] | None = None) -> UcTable:
    """u_c(p/E) of `spectrum` pressed by an elastic half-space (E_Pa, nu) against it, at the
    pressures asked for (in their order), with the mean separation, the contact area ratio and
    where the contact percolates (sealed) as the table's theory columns.

    `method`: ``"emt"`` (default; the route the paper used, Sec. 5.1: Bruggeman effective-medium leak
    rate identified with the critical-junction expression, see `effective_medium`) or
    ``"critical-junction"``. Both use the same contact area, threshold `a_c` and `gamma`.
    """
    p_over_E = np.atleast_1d(np.asarray(p_over_E, float))
    check_gap_parameters(p_over_E, method, gamma, a_c)
    Estar = effective_modulus(E_Pa, nu)
    pstar = p_over_E * E_Pa / Estar
    mom = Moments.of(spectrum, n_q)
    if method == "emt":
        u_c, sealed = effective_medium_gap(mom, pstar, gamma, a_c, progress=progress)
    else:
        u_c, sealed = critical_junction_gap(mom, pstar, gamma, a_c)
    u_mean = mean_separation(mom, pstar, None, gamma)
    area = contact_area_ratio(mom.m[-1], pstar)
    return UcTable(p_over_E, u_c, provenance=spectrum.provenance, u_mean_m=u_mean, contact_area_ratio=area,
                   sealed=sealed, theory={"E_Pa": float(E_Pa), "nu": float(nu), "method": method,
                                          "gamma": float(gamma), "a_c": float(a_c)})


#: reference pressure and tolerance of `patch_length`: 1 atm on E = 4 MPa (the presets' calibration
#: point, Sec. 5.1), and u_c kept to 2 %
PATCH_P_OVER_E, PATCH_TOL = 0.025, 0.02


def patch_length(spectrum: PowerSpectrum, nu: float, *, p_over_E: float = PATCH_P_OVER_E,
                 tol: float = PATCH_TOL, method: str = "emt", gamma: float = 0.45,
                 a_c: float = 0.42) -> float:
    """The smallest patch [m] on which u_c(p) is the whole spectrum's: 2 pi / q_cut for the largest
    lower cutoff q_cut (a wavevector of the spectrum's grid) at which u_c at `p_over_E` of the
    spectrum restricted to q >= q_cut is still >= (1 - tol) times the full one.

    The nominal pressure of the theory must be uniform on patches that hold every wavelength u_c
    depends on; longer ones do not change it (they only tilt and lift the patch), so a pressure
    averaged over such a patch is a nominal pressure, and one varying on shorter scales is not. u_c
    falls monotonically as long wavelengths are removed (bisection over the grid). The length grows
    at lower pressure (fewer long wavelengths are flattened): pmma-1.89 202 um at p/E = 0.025 and
    235 um at 0.01 (roll-off wavelength 120 um); the table preset 140 um and 2.4 mm. If u_c is 0
    (sealed) at `p_over_E`, the wavelength with the most mean-square height per logarithmic band
    (`PowerSpectrum.rolloff_wavelength_m`).
    """
    if not (0.0 < tol < 1.0 and p_over_E > 0.0):
        raise ValueError(f"tol, p_over_E: need 0 < tol < 1 and p_over_E > 0, got {tol}, {p_over_E}")
    q, C = spectrum.q_per_m, spectrum.C_m4

    def gap(i: int) -> float:
        part = spectrum if i == 0 else PowerSpectrum(q[i:], C[i:])
        return float(critical_gap_table(part, 1e6, nu, [p_over_E], method=method, gamma=gamma,
                                        a_c=a_c).u_c_m[0])

    full = gap(0)
    if full <= 0.0:
        return spectrum.rolloff_wavelength_m()
    lo, hi = 0, q.size - 10                 # u_c(lo) keeps the tolerance; keep >= 10 wavevectors
    if gap(hi) >= (1.0 - tol) * full:
        return float(2 * np.pi / q[hi])
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if gap(mid) >= (1.0 - tol) * full:
            lo = mid
        else:
            hi = mid
    return float(2 * np.pi / q[lo])


#: p/E grid of the u_c tables handed to the reduced model: 40 points per decade over [1e-6, 1]
UC_TABLE_P_OVER_E = np.geomspace(1e-6, 1.0, 241)


def uc_table(spectrum: PowerSpectrum, nu: float, *, method: str = "emt", gamma: float = 0.45,
             a_c: float = 0.42, p_over_E: np.ndarray | None = None, with_patch_length: bool = True,
             stored: bool = True):
    """u_c(p/E) of `spectrum` as the reduced model's `UcTable` (log-log interpolated).

    Without adhesion the theory is linear elastic: u_c depends on p and E only through p/E*, so
    one table serves every modulus at this Poisson ratio, the relaxed E_eff(phi) included.

    With `with_patch_length` the table carries `patch_length` (at its defaults, with this method,
    gamma and a_c) as `patch_length_m`: the theory's nominal pressure is an average over a patch that
    holds every wavelength u_c depends on, and the profile route then averages the FEM's contact
    pressure over it (`reduced.profile_leak`, `reduced.seal`; it makes that route converge under mesh
    refinement; eq (10)'s strip is then at least one patch wide, `reduced.seal.ProfileSeal.width`).
    On by default; False: the raw FEM profile (mesh-dependent where the rim corner alone touches).

    With `stored`, a request the package stores the answer to (a calibrated preset at the defaults,
    `reduced.roughness.stored`) is read, not computed: the same table, bit for bit.
    """
    grid = UC_TABLE_P_OVER_E if p_over_E is None else np.asarray(p_over_E, float)
    if stored:
        from .stored import request_key, stored_table
        table = stored_table(request_key(spectrum, nu, method, gamma, a_c, grid, with_patch_length), grid)
        if table is not None:
            return table
    table = critical_gap_table(spectrum, 1e6, nu, grid, method=method, gamma=gamma, a_c=a_c)
    note = (f"Persson theory ({method}, gamma {gamma:g}, a_c {a_c:g}, nu {nu:g}) of "
            f"{spectrum.provenance}")
    length = patch_length(spectrum, nu, method=method, gamma=gamma, a_c=a_c) if with_patch_length else None
    return replace(table, provenance=note, patch_length_m=length)
