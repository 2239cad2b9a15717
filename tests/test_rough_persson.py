"""Persson contact area, Yang-Persson separation, u1 and the critical junction, against closed forms."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import beta, betainc, erf, erfinv

from reduced.roughness.persson import (Moments, contact_area_ratio, critical_gap_table,
                                       mean_separation,
                                       noncontact_separation, separation_kernel,
                                       small_pressure_slope)
from reduced.roughness.spectrum import self_affine

# a pure power law in scaled units: C = C0 (q/q0)^(-2(1+H)) on [q0, q1]
H, Q0, Q1, C0, GAMMA = 0.7, 1.0, 300.0, 1e-3, 0.45
A_EXP = 2 - 2 * H
K = C0 * Q0 ** (2 + 2 * H)


def m_exact(q):
    """int_{q0}^{q} q^3 C dq for the power law."""
    return K * (q ** A_EXP - Q0 ** A_EXP) / A_EXP


@pytest.fixture(scope="module")
def power_law():
    spec = self_affine(H=H, q0_per_m=Q0, q1_per_m=Q1, C0_m4=C0, n=3000)
    return spec, Moments.of(spec)


def test_separation_kernel_against_quadrature():
    for x0 in (1e-6, 1e-2, 0.3, 1.0, 2.5):
        f = lambda x: (GAMMA + 3 * (1 - GAMMA) * erf(x) ** 2) * np.exp(-x * x) / x
        ref = quad(f, x0, np.inf, limit=200, epsabs=0, epsrel=1e-10)[0]
        # linear interpolation in ln x (step 6e-4 where x > 0.05): the relative error is about
        # step^2 (dlnF/dlnx)^2 / 8, which reaches 1e-5 at x = 2.5 where dlnF/dlnx ~ -2x^2
        assert separation_kernel(np.array(x0), GAMMA) == pytest.approx(ref, rel=2e-5)


def test_contact_area_full_magnification_closed_form(power_law):
    spec, mom = power_law
    slope_rms = np.sqrt(2 * np.pi * m_exact(Q1))           # h'_rms^2 = 2 pi int q^3 C dq
    pstar = np.array([1e-3, 1e-2, 5e-2])
    # trapezoid in ln q on 3000 nodes: 1e-6 in m, less in erf
    np.testing.assert_allclose(contact_area_ratio(mom.m[-1], pstar),
                               erf(np.sqrt(2) * pstar / slope_rms), rtol=1e-6)
    # and at magnification zeta via G = (pi/4)(E*/p)^2 int q^3 C dq, P = erf(1/(2 sqrt G))
    q = 17.0
    G = np.pi / 4 / pstar ** 2 * quad(lambda k: k ** 3 * C0 * (k / Q0) ** (-2 - 2 * H), Q0, q)[0]
    np.testing.assert_allclose(contact_area_ratio(mom.m_at(np.log(q)), pstar),
                               erf(1 / (2 * np.sqrt(G))), rtol=1e-5)


def literal_mean_separation(pstar):
    """Yang & Persson (2008) as printed: sqrt(pi) int dq q^2 C w int_p^inf dp'/p' [..] exp(-(w p'/E*)^2)."""
    def inner(q):
        w = (np.pi * m_exact(q)) ** -0.5
        f = lambda x: (GAMMA + 3 * (1 - GAMMA) * erf(x) ** 2) * np.exp(-x * x) / x
        return quad(f, w * pstar, np.inf, limit=200)[0]            # x = w p'/E*
    C = lambda q: C0 * (q / Q0) ** (-2 - 2 * H)
    return np.sqrt(np.pi) * quad(lambda q: q * q * C(q) * (np.pi * m_exact(q)) ** -0.5 * inner(q),
                                 Q0, Q1, limit=400, points=[1.001, 1.1, 2, 10])[0]


@pytest.mark.parametrize("pstar", [1e-4, 1e-3, 1e-2])
def test_mean_separation_matches_literal_formula(power_law, pstar):
    spec, mom = power_law
    # independent quadrature (adaptive, nested) of the printed formula; ours: product integration
    # on 192 log nodes, whose 1/q trapezoid error is ~4e-4
    assert mean_separation(mom, pstar, None, GAMMA) == pytest.approx(
        literal_mean_separation(pstar), rel=1e-3)


def test_small_pressure_asymptote_closed_form(power_law):
    spec, mom = power_law
    # -du/dln p -> sqrt(pi) gamma int q^2 C w dq; for the power law with u = (q0/q)^a:
    # int q^2 C w dq = sqrt(K/(pi a)) q0^(a/2-1) B(1/a - 1/2, 1/2) [1 - I_{(q0/q1)^a}(1/a - 1/2, 1/2)]
    a, b = 1 / A_EXP - 0.5, 0.5
    integral = (np.sqrt(K / (np.pi * A_EXP)) * Q0 ** (A_EXP / 2 - 1) * beta(a, b)
                * (1 - betainc(a, b, (Q0 / Q1) ** A_EXP)))
    closed = np.sqrt(np.pi) * GAMMA * integral
    assert small_pressure_slope(mom, GAMMA) == pytest.approx(closed, rel=2e-4)
    p = np.array([1e-9, 1.1e-9])
    u = mean_separation(mom, p, None, GAMMA)
    # O(x^2) corrections are ~1e-17 here; the rest is the quadrature (~1e-3, see above)
    assert -(u[1] - u[0]) / np.log(1.1) == pytest.approx(closed, rel=1e-3)


def test_u1_volume_identity(power_law):
    """u1 = u + u' A/A' is d(uA) = u1 dA: int_{A1}^{A_a} u1 dA = u(zeta_a) A_a - u(zeta1) A1, u(zeta1) = 0.

    (Not from A = 1: right above zeta = 1 the separation u(zeta) already falls while A stays 1 to
    within 1e-5, the roughness at q ~ q0 being flattened in full contact; there u1 dA is 0 * inf.)
    """
    spec, mom = power_law
    pstar, A_a = 0.02, 0.98
    A1 = float(contact_area_ratio(mom.m[-1], pstar))
    N = 400
    theta = (np.arange(N) + 0.5) / N
    A = A_a - 0.5 * (1 - np.cos(np.pi * theta)) * (A_a - A1)
    dA = (A_a - A1) * np.pi / 2 * np.sin(np.pi * theta) / N
    to_lnq = lambda a: mom.lnq_at_m((pstar / erfinv(a)) ** 2 / np.pi)
    u1 = noncontact_separation(mom, pstar, to_lnq(A), GAMMA)
    V_a = A_a * float(mean_separation(mom, pstar / A_a, to_lnq(A_a), GAMMA))
    # midpoint rule on 400 graded cells and central differences in ln zeta: 0.2 % covers both
    assert np.sum(u1 * dA) == pytest.approx(V_a, rel=2e-3)


def pmma_like(n=2000):
    return self_affine(H=0.8, q0_per_m=251.0, qr_per_m=6e4, q1_per_m=1e7, h_rms_m=1.5e-6, n=n)


@pytest.mark.parametrize("method", ["critical-junction", "emt"])
def test_uc_decreases_with_pressure_and_seals_cleanly(method):
    spec = pmma_like()
    table = critical_gap_table(spec, 4e6, 0.5, np.geomspace(1e-5, 0.5, 80), method=method)
    assert np.all(np.isfinite(table.u_c_m)) and np.all(table.u_c_m >= 0)
    open_ = ~table.sealed
    assert np.all(np.diff(table.u_c_m[open_]) < 0)
    assert np.all(table.u_c_m[table.sealed] == 0)
    assert table.sealed[-1] and not table.sealed[0]
    # sealing threshold: erf(sqrt(2) p*/h'_rms) = a_c in closed form
    pstar_seal = erfinv(0.42) * spec.slope_rms() / np.sqrt(2)
    pstar = table.p_over_E * 4e6 / (4e6 / 0.75)
    np.testing.assert_array_equal(table.sealed, pstar >= pstar_seal)
    assert np.all(np.diff(table.u_mean_m) < 0)


@pytest.mark.parametrize("method", ["critical-junction", "emt"])
def test_grid_convergence_in_q(method):
    pe = np.array([1e-4, 3e-3, 0.025])
    coarse = critical_gap_table(pmma_like(500), 4e6, 0.5, pe, method=method)
    fine = critical_gap_table(pmma_like(4000), 4e6, 0.5, pe, method=method)
    # input grids 500 vs 4000 nodes: the integrals are converged to better than 0.3 %
    np.testing.assert_allclose(coarse.u_c_m, fine.u_c_m, rtol=3e-3)
    np.testing.assert_allclose(coarse.u_mean_m, fine.u_mean_m, rtol=3e-3)
    # per-row nodes of the separation integral: the default 192 against 768
    mom = Moments.of(pmma_like())
    pstar = pe * 0.75
    u_fine = mean_separation(mom, pstar, None, 0.45, n_sub=768)
    np.testing.assert_allclose(mean_separation(mom, pstar, None, 0.45), u_fine, rtol=1e-3)


def test_bad_parameters():
    spec = pmma_like(200)
    with pytest.raises(ValueError, match="a_c"):
        critical_gap_table(spec, 4e6, 0.5, [0.01], a_c=1.2)
    with pytest.raises(ValueError, match="p_over_E"):
        critical_gap_table(spec, 4e6, 0.5, [-0.01])
    with pytest.raises(ValueError, match="nu"):
        critical_gap_table(spec, 4e6, 0.7, [0.01])
    with pytest.raises(ValueError, match="method"):
        critical_gap_table(spec, 4e6, 0.5, [0.01], method="magic")


def test_bem_kernel_on_johnson_wavy_contact():
    """The BEM behind the slow comparison, on Johnson's 1D wavy surface (Contact Mechanics, 13.2):
    h = D cos(2 pi x/lam), full contact at p* = pi E* D/lam, contact fraction (2/pi) asin(sqrt(p/p*))."""
    from reduced.roughness.bem import solve_contact
    n, lam, D = 512, 1.0, 1e-3
    x = (np.arange(n) + 0.5) / n * lam
    h = np.repeat((D * np.cos(2 * np.pi * x / lam))[:, None], 4, axis=1)
    p_full = np.pi * D / lam
    for ratio in (0.25, 0.5):
        state = solve_contact(h, lam, ratio * p_full, 1.0, tol=1e-10)
        # one cell in 512 either side of the contact edge: 2/512 in the fraction
        assert state.contact_area_ratio == pytest.approx(2 / np.pi * np.arcsin(np.sqrt(ratio)), abs=4 / n)
