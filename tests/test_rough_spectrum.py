"""Power spectra: normalisation, conventions, CSV and the isotropic 1D <-> 2D (Abel) pair."""

import numpy as np
import pytest
from scipy.special import gamma as Gamma

from reduced.roughness.spectrum import (PowerSpectrum, line_to_isotropic, read_psd_csv,
                                        self_affine, to_persson)

H, Q0, C0 = 0.8, 1e3, 1e-20


def analytic_C1D(q, H=H):
    """Pure power law C = C0 (q/q0)^(-2(1+H)) on (0, inf):
    C_1D = 2 int_0^inf C(sqrt(q^2+t^2)) dt = sqrt(pi) Gamma(H+1/2)/Gamma(H+1) C0 q0^(2+2H) q^(-1-2H)."""
    return np.sqrt(np.pi) * Gamma(H + 0.5) / Gamma(H + 1) * C0 * Q0 ** (2 + 2 * H) * q ** (-1 - 2 * H)


@pytest.mark.parametrize("hurst", [0.3, 0.8])
def test_forward_abel_matches_self_affine_closed_form(hurst):
    # band to q1 = 1e9; at q <= 1e6 the truncated tail beyond q1 is ~(q/q1)^(1+2H) <= 2e-5
    spec = self_affine(H=hurst, q0_per_m=Q0, q1_per_m=1e9, C0_m4=C0, n=2000)
    q = np.geomspace(1e3, 1e6, 9)
    np.testing.assert_allclose(spec.line_spectrum(q), analytic_C1D(q, hurst), rtol=2e-4)


def test_inverse_abel_recovers_self_affine_closed_form():
    q = np.geomspace(1e3, 1e9, 2000)
    out = np.geomspace(1e3, 1e7, 9)
    C = line_to_isotropic(q, analytic_C1D(q), out)
    np.testing.assert_allclose(C, C0 * (out / Q0) ** (-2 * (1 + H)), rtol=2e-4)


def test_1d_2d_1d_round_trip_with_rolloff():
    spec = self_affine(H=0.7, q0_per_m=1e3, qr_per_m=2e4, q1_per_m=1e8, h_rms_m=1e-6, n=1500)
    C1 = spec.line_spectrum()
    back = PowerSpectrum(spec.q_per_m, np.maximum(line_to_isotropic(spec.q_per_m, np.maximum(C1, 1e-300)), 0))
    # the inversion truncates at q1: test a decade below it; the first node has only a one-sided
    # log-derivative. The roll-off kink is smeared by the derivative over one grid cell: 1 %.
    inner = (spec.q_per_m > spec.q_per_m[0]) & (spec.q_per_m < 1e7)
    np.testing.assert_allclose(back.C_m4[inner], spec.C_m4[inner], rtol=1e-2)
    assert back.h_rms_m() == pytest.approx(spec.h_rms_m(), rel=2e-3)


def test_rms_round_trip_parametric_and_1d():
    spec = self_affine(H=0.8, q0_per_m=251.0, qr_per_m=5e4, q1_per_m=1e7, h_rms_m=1.3e-6, n=2000,
                       hump=(0.2, 1e5, 0.3))
    assert spec.h_rms_m() == pytest.approx(1.3e-6, rel=1e-12)
    # isotropy: <h^2> = 2 int C_1D dq must equal 2 pi int q C dq (1D from the forward Abel)
    q = np.geomspace(251.0, 1e7, 3000)
    C1 = spec.line_spectrum(q)
    ms_1d = 2 * np.sum(0.5 * (C1[1:] + C1[:-1]) * np.diff(q))
    # C_1D extends below q0 (flat there): add the missing 2 * C_1D(q0) * q0
    ms_1d += 2 * C1[0] * q[0]
    assert np.sqrt(ms_1d) == pytest.approx(1.3e-6, rel=5e-3)


def test_hump_carries_its_share():
    spec = self_affine(H=0.8, q0_per_m=251.0, qr_per_m=1e3, q1_per_m=1e7, h_rms_m=7.7e-6,
                       hump=(0.25, 1e5, 0.3))
    plain = self_affine(H=0.8, q0_per_m=251.0, qr_per_m=1e3, q1_per_m=1e7, h_rms_m=1.0)
    # the non-hump part is the plain shape: its share is C_plain scaled; compare far from the hump
    far = spec.q_per_m < 1e4
    ratio = spec.C_m4[far] / plain.C_m4[far]
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-9)
    assert ratio[0] == pytest.approx(0.75 * 7.7e-6 ** 2, rel=1e-3)
    bump = spec.C_m4 - ratio[0] * plain.C_m4
    assert spec.q_per_m[np.argmax(bump)] == pytest.approx(1e5, rel=0.01)


def test_surfacetopography_conventions():
    spec = self_affine(H=0.8, q0_per_m=1e3, q1_per_m=1e7, h_rms_m=1e-6)
    q, C = spec.q_per_m, spec.C_m4
    st2 = C * (2 * np.pi) ** 2        # SurfaceTopography: <h^2> = (1/2pi) int q C_ST dq
    ms_st = np.sum(0.5 * (q[1:] * st2[1:] + q[:-1] * st2[:-1]) * np.diff(q)) / (2 * np.pi)
    assert np.sqrt(ms_st) == pytest.approx(1e-6, rel=1e-3)
    np.testing.assert_allclose(to_persson(st2, "surfacetopography-2d"), C)
    np.testing.assert_allclose(to_persson(2 * np.pi * C, "surfacetopography-1d"), C)
    with pytest.raises(ValueError, match="convention"):
        to_persson(C, "bogus")


def test_psd_csv_round_trip(tmp_path):
    spec = self_affine(H=0.6, q0_per_m=1e3, qr_per_m=1e4, q1_per_m=1e7, h_rms_m=2e-6, n=500)
    path = tmp_path / "c.csv"
    spec.to_csv(path)
    back = read_psd_csv(path)
    assert back.h_rms_m() == pytest.approx(2e-6, rel=1e-8)
    assert back.slope_rms() == pytest.approx(spec.slope_rms(), rel=1e-8)


@pytest.mark.parametrize("q,C,msg", [
    ([1, 2], [1, 1], "length"),
    ([1, 3, 2], [1, 1, 1], "increasing"),
    ([1, 2, 3], [1, -1, 1], "non-negative"),
])
def test_bad_spectrum(q, C, msg):
    with pytest.raises(ValueError, match=msg):
        PowerSpectrum(np.array(q, float), np.array(C, float))


def test_bad_psd_file(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("q,C\n1,2\n")
    with pytest.raises(ValueError, match="header"):
        read_psd_csv(p)


def test_1d_to_2d_to_1d_round_trip():
    spec = self_affine(H=0.7, q0_per_m=1e3, qr_per_m=2e4, q1_per_m=1e8, h_rms_m=1e-6, n=1500)
    q = spec.q_per_m
    C1 = spec.line_spectrum(q)[:-1]                 # a measured-like C_1D on [q0, q1)
    iso = line_to_isotropic(q[:-1], C1)
    again = PowerSpectrum(q[:-1][iso > 0], iso[iso > 0]).line_spectrum(q[:-1])
    inner = (q[:-1] > 1.5e3) & (q[:-1] < 1e7)       # away from both truncated ends
    # measured 7e-4, at the roll-off kink (the log-derivative smears it over one cell)
    np.testing.assert_allclose(again[inner], C1[inner], rtol=2e-3)
