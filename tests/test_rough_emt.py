"""Effective-medium (Bruggeman) leak rate: closed-form mixtures, threshold, agreement with the junction."""

import numpy as np
import pytest

from reduced.roughness.effective_medium import bruggeman_conductance, gap_distribution
from reduced.roughness.persson import Moments, critical_gap_table
from reduced.roughness.spectrum import self_affine


def test_bruggeman_two_phase_closed_forms():
    # open fraction (1 - A1) with u^3 = 1 and contact A1: S = 1 - A1/a_c (linear to the threshold)
    for a_c in (0.42, 0.5):
        A1 = np.array([0.0, 0.1, 0.3, 0.41])
        S = bruggeman_conductance(np.ones((4, 1)), (1 - A1)[:, None], A1, a_c)
        np.testing.assert_allclose(S, np.where(A1 < a_c, 1 - A1 / a_c, 0.0), rtol=1e-10)
    # classic 2D Bruggeman (a_c = 1/2): a 50/50 mix of two conductances gives their geometric mean
    S = bruggeman_conductance(np.array([[1.0, 16.0]]), np.array([[0.5, 0.5]]), np.array([0.0]), 0.5)
    assert S[0] == pytest.approx(4.0, rel=1e-10)


def spec():
    return self_affine(H=0.8, q0_per_m=251.0, qr_per_m=6e4, q1_per_m=1e7, h_rms_m=1.5e-6)


def test_gap_distribution_is_normalised_and_centred():
    mom = Moments.of(spec())
    u, w, A1 = gap_distribution(mom, np.array([1e-3, 2e-2]))
    np.testing.assert_allclose(w.sum(axis=1) + A1, 1.0, rtol=1e-9)
    assert np.all(w >= 0) and np.all(u > 0)


def test_emt_and_junction_agree_far_from_threshold():
    pe = np.array([1e-7, 1e-6])
    cj = critical_gap_table(spec(), 4e6, 0.5, pe, method="critical-junction")
    emt = critical_gap_table(spec(), 4e6, 0.5, pe, method="emt")
    # at A/A0 ~ 1e-4..1e-5 nearly all the open area sits at u ~ u1(zeta ~ 1); the two routes then
    # differ only by the spread of P(u) (the Bruggeman mean of u^3 vs u1 at zeta_c): measured 3-4 %
    np.testing.assert_allclose(emt.u_c_m, cj.u_c_m, rtol=0.05)
    assert np.all(emt.contact_area_ratio < 1e-3)


def test_emt_goes_continuously_to_zero_at_threshold():
    s = spec()
    from scipy.special import erfinv
    pstar_seal = erfinv(0.42) * s.slope_rms() / np.sqrt(2)
    pe = pstar_seal / 0.75 * np.array([0.5, 0.99, 0.999, 1.001])      # p/E = p*/(1 - nu^2)
    emt = critical_gap_table(s, 4e6, 0.5, pe, method="emt")
    assert list(emt.sealed) == [False, False, False, True]
    assert emt.u_c_m[3] == 0.0
    # sigma_eff ~ (1 - A1/a_c) near the threshold, so u_c ~ (distance)^(1/3) -> 0
    assert emt.u_c_m[2] < emt.u_c_m[1] < 0.5 * emt.u_c_m[0]
    cj = critical_gap_table(s, 4e6, 0.5, pe, method="critical-junction")
    assert np.all(cj.u_c_m >= 0) and list(cj.sealed) == list(emt.sealed)


def test_emt_discretisation_converged():
    mom = Moments.of(spec())
    pstar = np.array([1e-4, 3e-3, 0.02])
    from reduced.roughness.effective_medium import effective_medium_gap
    default = effective_medium_gap(mom, pstar)[0]
    fine = effective_medium_gap(mom, pstar, n_zeta=64, n_u=480)[0]
    # 16 graded area cells and 120 u bins against 4x both (measured < 0.1 %): within 1 % (the table interpolates
    # log-log between pressures anyway; u_c^3 enters the leak rate, so 1 % is 3 % in the rate)
    np.testing.assert_allclose(default, fine, rtol=1e-2)
    from reduced.roughness import effective_medium as em
    u, w, a1 = em.gap_distribution(mom, pstar, n_sub=512)
    finer = np.cbrt(em.bruggeman_conductance(u ** 3, w, a1, 0.42))
    # 128 nodes per separation integral against 512: measured 0.1 %, second order in the spacing
    np.testing.assert_allclose(default, finer, rtol=2e-3)
