"""No silent clipping (issue 26): the 1D -> isotropic 2D inversion of a line spectrum with a hump
(a quasi-periodic profile) has no isotropic solution below the hump; how much of the line's
roughness the isotropic C(q) does not represent is measured, carried and said."""

import warnings

import numpy as np
import pytest

from reduced.roughness.line_scan import REFUSE_SHARE, SpectrumWarning, spectrum_from_line_scan
from reduced.roughness.spectrum import _trapz, isotropic_misfit, isotropic_to_line, line_to_isotropic
from tests.cli import run_cli

Q = np.geomspace(1e3, 1e7, 200)
POWER_LAW = 1e-20 * (Q / 1e3) ** -2.6              # C_1D of an isotropic self-affine surface


def with_hump(C1, q, fraction, q_h=1e5, width=0.1):
    """`C1` plus a Gaussian hump in ln q carrying `fraction` of the line's <h^2> = 2 int C_1D dq."""
    bump = np.exp(-np.log(q / q_h) ** 2 / (2 * width ** 2))
    return C1 + bump * fraction / (1 - fraction) * _trapz(C1, q) / _trapz(bump, q)


def test_a_power_law_is_represented_exactly():
    C = line_to_isotropic(Q, POWER_LAW)
    misfit = isotropic_misfit(Q, POWER_LAW, C)
    assert np.all(C[:-1] > 0) and misfit.share < 1e-4 and misfit.decades == 0


def test_a_hump_is_not_represented_and_says_how_much():
    """A 5 % Gaussian hump: the inverted C(q) is clipped below the hump, and its forward transform
    (the independent check) misses C_1D by more than 2x there, which the misfit reports."""
    C1 = with_hump(POWER_LAW, Q, 0.05)
    C = line_to_isotropic(Q, C1)
    below = (Q > 3e4) & (Q < 1e5)
    assert np.any(C[below] == 0)                                  # clipped: no isotropic C there
    band = Q <= Q[-1] / 2
    back = isotropic_to_line(Q[C > 0], C[C > 0], Q[band])
    ratio = back / C1[band]
    assert np.max(np.abs(np.log(ratio))) > np.log(2)               # the round trip is off > 2x
    misfit = isotropic_misfit(Q, C1, C)
    assert 0.03 < misfit.share < 0.1 and misfit.decades > 0.3
    # larger humps lose more
    C20 = with_hump(POWER_LAW, Q, 0.2)
    assert isotropic_misfit(Q, C20, line_to_isotropic(Q, C20)).share > misfit.share


def _scan(fraction, seed=1, L=25e-3, N=2 ** 14, h_rms=1e-6):
    """A random-phase profile whose 1D spectrum is a roll-off power law with a hump near q = 1e5."""
    q = 2 * np.pi * np.arange(1, N // 2) / L
    C1 = np.where(q < 1e4, 1.0, (q / 1e4) ** -2.6)
    C1 = with_hump(C1, q, fraction) if fraction else C1
    C1 *= h_rms ** 2 / (2 * _trapz(C1, q))
    H = np.zeros(N // 2 + 1, complex)
    H[1:N // 2] = np.sqrt(C1 * 2 * np.pi * L) / (L / N) * np.exp(2j * np.pi * np.random.default_rng(seed).random(q.size))
    return np.arange(N) * L / N, np.fft.irfft(H, N)


def test_a_line_scan_with_a_hump_warns_and_carries_the_misfit():
    with pytest.warns(SpectrumWarning, match="not represented"):
        spec = spectrum_from_line_scan(*_scan(0.1))
    assert spec.misfit.decades > 0 and "not represented" in spec.provenance
    with warnings.catch_warnings():
        warnings.simplefilter("error")                             # no warning without the hump
        plain = spectrum_from_line_scan(*_scan(0.0))
    assert plain.misfit.decades == 0 and plain.misfit.share < spec.misfit.share


def test_a_line_scan_beyond_the_threshold_is_refused():
    with pytest.raises(ValueError, match=f"refusing above {100 * REFUSE_SHARE:g} %"):
        spectrum_from_line_scan(*_scan(0.6))


def test_the_command_line_says_it_in_one_line(tmp_path, capsys):
    x, z = _scan(0.1)
    path = tmp_path / "scan.csv"
    np.savetxt(path, np.c_[x * 1e3, z * 1e6], delimiter=",", header="x_mm,z_um", comments="")
    code, _, err = run_cli(capsys, "uc", "--line-scan", path, "--E-MPa", "4", "--p-kPa", "10")
    assert code == 0 and len(err.splitlines()) == 1 and err.startswith("note: the isotropic C(q)"), err
