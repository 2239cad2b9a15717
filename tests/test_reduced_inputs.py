"""Inputs of the reduced model: cone laws (eqs 3-5), Appendix A, u_c tables, relaxation (eq 10)."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from reduced.appendix_a import appendix_a_curve, appendix_a_force, appendix_a_small_u_slope
from reduced.critical_gap import ILLUSTRATIVE_UC_CSV, UcTable, illustrative_uc_table
from reduced.cup import CUP_A, CUP_B, CupParameters, cup_by_name
from reduced.fast_curve import CurveRangeError, ScalarPchip
from reduced.ode import dopri5
from reduced.viscoelastic import (RelaxationModulus, contact_time_rate, default_relaxation,
                                  measurement_contact_time)


# ------------------------------------------------------------------ cone laws, eqs (3)-(5)
@pytest.mark.parametrize("cup", [CUP_A, CUP_B])
def test_cone_volume_eq4_is_the_frustum_volume(cup):
    for r in (cup.r0_m * 1.01, cup.r_start_m, cup.r1_m):
        h = cup.height(r)
        assert cup.radius(h) == pytest.approx(r, rel=1e-14)           # eq (3) both ways
        frustum = math.pi * r ** 2 * (h + cup.h0_m) / 3 - math.pi * cup.r0_m ** 2 * cup.h0_m / 3
        assert cup.volume(r) == pytest.approx(frustum, rel=1e-12)
    assert cup.height(cup.r1_m) == pytest.approx(cup.h1_m, rel=1e-14)
    assert cup.contact_width(cup.r0_m) == pytest.approx(cup.l0_m, rel=1e-14)   # eq (5) ends
    assert cup.contact_width(cup.r1_m) == pytest.approx(cup.l1_m, rel=1e-14)


def test_cup_presets_and_validation():
    assert CUP_A.h1_m == pytest.approx(14e-3 * math.tan(math.radians(33)), rel=1e-14)   # 9.09 mm
    assert cup_by_name("b") is CUP_B
    with pytest.raises(ValueError, match="cup: unknown cup 'C'"):
        cup_by_name("C")
    with pytest.raises(ValueError, match=r"alpha_deg: cone angle must be in \(0, 90\)"):
        CupParameters(5e-3, 19e-3, 95.0, 12e-3, 4e-3, 0.8e-3, 0.8)
    with pytest.raises(ValueError, match="r_start_m"):
        CupParameters(5e-3, 19e-3, 33.0, 20e-3, 4e-3, 0.8e-3, 0.8)


# ------------------------------------------------------------------ Appendix A
def test_appendix_a_small_u_slope_is_2p51_N_per_mm():
    k = appendix_a_small_u_slope(33.0, 4e6, 2e-3, CUP_A.r0_m, CUP_A.r1_m)
    assert k == pytest.approx(2.51e3, abs=0.005e3)       # the paper's "2.5 N/mm", to its 3rd digit
    curve = appendix_a_curve(CUP_A)
    # the sampled curve reproduces it (PCHIP slope at u = 0 of a parabola: O(du) error, du = 23 um)
    assert curve.force_slope(CUP_A.h1_m) == pytest.approx(k, rel=2e-3)
    assert curve.force(CUP_A.h1_m - 1e-4) / 1e-4 == pytest.approx(k, rel=1e-2)


def test_appendix_a_force_is_the_derivative_of_the_elastic_energy():
    """F0 = dU/du with U = E eps^2 V / 2 and V = int_x^x1 2 pi x cos(a) d(x) dx (general d1)."""
    alpha, E, d0, d1, x0, x1 = 33.0, 4e6, 2e-3, 0.4e-3, 5e-3, 19e-3
    a_r = math.radians(alpha)
    eps = 1 - math.cos(a_r)

    def energy(u):
        x = x1 - u / math.sin(a_r)
        d = lambda s: d0 + (d1 - d0) * (s - x0) / (x1 - x0)
        V = quad(lambda s: 2 * math.pi * s * math.cos(a_r) * d(s), x, x1, epsabs=0, epsrel=1e-13)[0]
        return 0.5 * E * eps ** 2 * V

    for u in (0.5e-3, 3e-3, 7e-3):
        du = 1e-6
        dUdu = (energy(u + du) - energy(u - du)) / (2 * du)    # central difference: O(du^2) exact here
        assert appendix_a_force(u, alpha, E, d0, x0, x1, d1) == pytest.approx(dUdu, rel=1e-7)


def test_appendix_a_curve_matches_closed_form():
    c = appendix_a_curve(CUP_A)
    u = np.linspace(0, CUP_A.h1_m, 997)
    exact = appendix_a_force(u, 33.0, 4e6, 2e-3, CUP_A.r0_m, CUP_A.r1_m)
    # PCHIP on 401 samples of a parabola: error ~ du^2 F'' ~ 1e-6 of the peak force
    np.testing.assert_allclose(c.force(CUP_A.h1_m - u), exact, atol=1e-5 * exact.max())
    assert c.provenance["source"] == "appendix-a"


def test_scalar_pchip_is_the_scipy_interpolant_and_never_clamps():
    c = appendix_a_curve(CUP_A, samples=31)
    fast = ScalarPchip(c.u_m, c.F0_N)
    for u in np.linspace(0, CUP_A.h1_m, 77):
        F, dF = fast.value_and_slope(float(u))
        assert F == pytest.approx(float(c.force(CUP_A.h1_m - u)), rel=1e-12, abs=1e-12)
        assert dF == pytest.approx(float(c.force_slope(CUP_A.h1_m - u)), rel=1e-10, abs=1e-9)
    with pytest.raises(CurveRangeError, match="outside the curve's sampled range"):
        fast.value(CUP_A.h1_m * 1.01)


# ------------------------------------------------------------------ u_c tables
def test_uc_table_loglog_interpolation_and_extrapolation_are_exact_for_a_power_law():
    t = illustrative_uc_table(exponent=1.7, rows=7)
    law = lambda x: 0.68e-6 * (x / 0.025) ** -1.7
    for x in (2e-5, 1e-4, 3e-3, 0.0123, 0.2, 0.9):      # below, inside, above the table
        assert t(x) == pytest.approx(law(x), rel=1e-10)


def test_uc_table_sealed_rows():
    t = UcTable([0.01, 0.02, 0.04, 0.08], [1e-6, 0.5e-6, 0.0, 0.0])
    assert t.sealing_p_over_E == 0.04
    assert t(0.02) == pytest.approx(0.5e-6)
    assert t(0.03) == pytest.approx(0.25e-6)       # linear to zero between open and sealed row
    assert t(0.04) == 0.0 and t(0.5) == 0.0        # beyond a sealed row it stays sealed
    with pytest.raises(ValueError, match="sealed"):
        UcTable([0.01, 0.02, 0.04], [1e-6, 0.0, 1e-7])
    with pytest.raises(ValueError, match="p_over_E"):
        t(0.0)


def test_uc_table_csv_round_trip_and_shipped_table(tmp_path):
    t = UcTable([0.01, 0.02, 0.04], [1e-6, 0.5e-6, 0.0], provenance="test table")
    back = UcTable.from_csv(t.to_csv(tmp_path / "uc.csv"))
    np.testing.assert_array_equal(back.u_c_m, t.u_c_m)
    assert "test table" in back.provenance
    # the shipped illustrative table is exactly what its generator writes (provenance is honest)
    shipped, gen = UcTable.from_csv(ILLUSTRATIVE_UC_CSV), illustrative_uc_table()
    np.testing.assert_allclose(shipped.u_c_m, gen.u_c_m, rtol=1e-9)
    np.testing.assert_allclose(shipped.p_over_E, gen.p_over_E, rtol=1e-9)
    assert "ILLUSTRATIVE" in shipped.provenance
    bad = tmp_path / "bad.csv"
    bad.write_text("p,u\n1,2\n")
    with pytest.raises(ValueError, match="header 'p_over_E,u_c_m'"):
        UcTable.from_csv(bad)


# ------------------------------------------------------------------ relaxation, eq (10)
def test_default_relaxation_goes_through_the_papers_two_values_and_has_a_plateau():
    E = default_relaxation()
    assert E(1.0) == pytest.approx(4.4e6, rel=1e-12)
    assert E(3e4) == pytest.approx(1.8e6, rel=1e-12)
    assert E(1e-3) == E(1.0) and E(0.0) == E(1.0)                 # t -> 0: held at the first datum
    assert E.modulus_and_log_slope(0.5)[1] == 0.0
    assert E(3e5) < 1.8e6                                          # log-log extrapolation relaxes on
    with pytest.raises(ValueError, match="t_s"):
        RelaxationModulus([1.0, 1.0], [1e6, 2e6])


def test_measurement_contact_time_cup_A_is_13_s():
    # l(12 mm) = 2.4 mm (eq 5), rdot = 0.12 mm/s / tan 33 deg = 0.1848 mm/s (eq 3)
    assert CUP_A.contact_width(12e-3) == pytest.approx(2.4e-3, rel=1e-12)
    rdot_mm_s = 0.12 / math.tan(math.radians(33))
    assert measurement_contact_time(CUP_A) == pytest.approx(2.4 / rdot_mm_s, rel=1e-12)
    assert measurement_contact_time(CUP_A) == pytest.approx(12.99, abs=0.01)


def test_contact_time_eq10_for_constant_rdot_over_l():
    """phi(t) = tau (1 - exp(-t/tau)), tau = l/rdot (Sec. 3), integrated by the model's integrator."""
    l, rdot = 2e-3, 1e-4
    tau = l / rdot
    sol = dopri5(lambda t, y: [contact_time_rate(y[0], rdot, l)], 0.0, [0.0], 5 * tau, 1e-10, [1e-12])
    for t, y in zip(sol.t, sol.y):
        assert y[0] == pytest.approx(tau * (1 - math.exp(-t / tau)), rel=1e-8, abs=1e-10)
    assert contact_time_rate(7.0, 0.0, l) == 1.0          # stationary contact: phi = t


def test_persson_theory_gives_the_one_u_c_table_type(tmp_path):
    """critical_gap_table answers the pressures it was asked for, in their order, as a UcTable
    with the theory's columns; the interpolant is built on the rows sorted, so an unsorted table
    interpolates as the sorted one, and a one-row answer can be read but not interpolated."""
    from reduced.roughness import critical_gap_table, preset, uc_table

    spectrum = preset("pmma-1.89").spectrum()
    asked = np.array([0.05, 0.002, 0.01, 0.0005])
    table = critical_gap_table(spectrum, 4e6, 0.5, asked)
    assert isinstance(table, UcTable)
    np.testing.assert_array_equal(table.p_over_E, asked)
    assert table.u_mean_m.shape == table.contact_area_ratio.shape == table.sealed.shape == (4,)
    assert np.all(table.u_mean_m > table.u_c_m) and table.theory["method"] == "emt"
    order = np.argsort(asked)
    ordered = UcTable(asked[order], table.u_c_m[order])
    for x in (3e-4, 0.001, 0.02, 0.3):
        assert table(x) == ordered(x)
    back = UcTable.from_csv(table.to_csv(tmp_path / "uc.csv"))          # written sorted
    np.testing.assert_array_equal(back.p_over_E, asked[order])
    one = critical_gap_table(spectrum, 4e6, 0.5, [0.025])
    assert one.u_c_m.size == 1 and one.u_c_m[0] > 0
    with pytest.raises(ValueError, match="^u_c_m: need at least 2 open"):
        one(0.025)
    full = uc_table(spectrum, 0.5, with_patch_length=False)
    assert full.u_mean_m is not None and full.patch_length_m is None


def test_u_c_table_rows_are_checked_in_any_order():
    with pytest.raises(ValueError, match="^u_c_m: a sealed"):
        UcTable([0.04, 0.01, 0.02], [1e-7, 1e-6, 0.0])              # sealed below an open row
    with pytest.raises(ValueError, match="^p_over_E: a repeated pressure"):
        UcTable([0.01, 0.02, 0.01], [1e-6, 0.5e-6, 2e-6])
    with pytest.raises(ValueError, match="^sealed: 2 values for 3"):
        UcTable([0.01, 0.02, 0.04], [1e-6, 0.5e-6, 0.0], sealed=[False, False])
