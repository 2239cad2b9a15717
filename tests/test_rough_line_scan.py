"""Line scan -> C_1D -> C(q): normalisation and recovery of a known isotropic spectrum."""

import numpy as np
import pytest

from reduced.roughness.line_scan import line_periodogram, read_line_scan, spectrum_from_line_scan
from reduced.roughness.spectrum import self_affine

L, N = 25e-3, 2 ** 15          # the paper's 25 mm scans; dx = 0.76 um


def synthetic_scan(seed=1, h_rms=1e-6):
    """A profile whose 1D spectrum is exactly that of an isotropic self-affine C(q) (random phases)."""
    iso = self_affine(H=0.8, q0_per_m=2 * np.pi / L, qr_per_m=1e4, q1_per_m=1.01 * np.pi * N / L,
                      h_rms_m=h_rms, n=800)
    q = 2 * np.pi * np.arange(1, N // 2) / L
    coarse = np.geomspace(q[0], q[-1], 400)          # C_1D is smooth: power-law interpolation
    C1 = np.exp(np.interp(np.log(q), np.log(coarse), np.log(iso.line_spectrum(coarse))))
    H = np.zeros(N // 2 + 1, complex)
    H[1:N // 2] = np.sqrt(C1 * 2 * np.pi * L) / (L / N) * np.exp(
        2j * np.pi * np.random.default_rng(seed).random(q.size))
    return np.arange(N) * L / N, np.fft.irfft(H, N), iso, q, C1


def test_periodogram_normalisation():
    x = np.arange(4096) * 1e-6
    z = 1e-6 * np.sin(2 * np.pi * 200 * x / x[-1] * (4095 / 4096))   # exactly periodic, k = 200
    q, C1 = line_periodogram(x, z)
    dq = q[1] - q[0]
    # paper's convention: <h^2> = 2 int C_1D dq; Hann with mean(w^2) = 1 keeps the power
    assert 2 * C1.sum() * dq == pytest.approx(np.mean(z ** 2), rel=1e-6)


def test_line_scan_round_trip(tmp_path):
    x, z, iso, q, C1 = synthetic_scan()
    path = tmp_path / "scan.csv"
    np.savetxt(path, np.c_[x * 1e3, z * 1e6], delimiter=",", header="x_mm,z_um", comments="")
    xs, zs = read_line_scan(path)
    spec = spectrum_from_line_scan(xs, zs, tip_radius_m=1e-6)
    # rms: the 2D spectrum from one scan against the profile's own rms. Lost: the lowest modes
    # (window lobe) and the top octave; gained: noise of the single-scan inversion at low q.
    assert spec.h_rms_m() == pytest.approx(np.std(z), rel=0.1)
    # shape where each bin averages many modes (q in [5e4, 5e5]): band mean within 10 %, each
    # bin within 40 % (one scan; the windowed periodogram of random phases scatters bin to bin)
    band = (spec.q_per_m > 5e4) & (spec.q_per_m < 5e5)
    truth = np.exp(np.interp(np.log(spec.q_per_m[band]), np.log(iso.q_per_m), np.log(iso.C_m4)))
    ratio = spec.C_m4[band] / truth
    assert np.exp(np.mean(np.log(ratio))) == pytest.approx(1.0, abs=0.1)
    assert np.all((ratio > 0.6) & (ratio < 1.4)), ratio


def test_tip_radius_cuts_the_band():
    x, z, *_ = synthetic_scan(h_rms=20e-6)
    sharp = spectrum_from_line_scan(x, z, tip_radius_m=1e-7)
    blunt = spectrum_from_line_scan(x, z, tip_radius_m=50e-6)
    assert blunt.q1_per_m < 0.5 * sharp.q1_per_m


def test_bad_scans(tmp_path):
    p = tmp_path / "s.csv"
    p.write_text("x,z\n" + "\n".join(f"{i},{i}" for i in range(100)))
    with pytest.raises(ValueError, match="header"):
        read_line_scan(p)
    x = np.sort(np.random.default_rng(0).random(200))
    with pytest.raises(ValueError, match="uniformly"):
        line_periodogram(x, x)


def test_uc_from_scan_matches_uc_from_true_spectrum():
    """End to end: u_c computed from one synthetic 25 mm scan vs from the spectrum that made it."""
    from reduced.roughness.persson import critical_gap_table
    x, z, iso, *_ = synthetic_scan(h_rms=1.5e-6)
    scan = spectrum_from_line_scan(x, z, tip_radius_m=1e-6)
    pe = np.array([0.3e3, 3e3, 30e3]) / 4e6
    # measured 2-4 %: single-scan noise at low q and the band lost above half-Nyquist
    np.testing.assert_allclose(critical_gap_table(scan, 4e6, 0.5, pe).u_c_m,
                               critical_gap_table(iso, 4e6, 0.5, pe).u_c_m, rtol=0.1)
