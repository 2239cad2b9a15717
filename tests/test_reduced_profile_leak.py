"""Leakage through a contact-pressure profile (issue 12, section 1) against the paper's strip
formulas, a series composition solved independently, and a refinement study."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from reduced.critical_gap import UcTable
from reduced.gas import AIR, interpolated_leak_rate, liquid_volume_rate
from reduced.profile_leak import ContactProfile, profile_leak_rate, profile_liquid_rate, ring_gaps

P_A, P_B = 1e5, 3e4
R0, L = 12e-3, 2e-3


@pytest.mark.parametrize("u_c", [5e-9, 0.2e-6, 20e-6])          # ballistic, mixed, diffusive
def test_a_uniform_strip_is_eq_19_with_the_papers_aspect_ratio(u_c):
    r = np.linspace(R0, R0 + L, 41)                               # 40 rings of the same gap
    strip = profile_leak_rate(AIR, P_A, P_B, r, np.full(40, u_c), radial="strip")
    assert strip == pytest.approx(interpolated_leak_rate(AIR, P_A, P_B, u_c, 2 * math.pi * R0 / L), rel=1e-12)
    annulus = profile_leak_rate(AIR, P_A, P_B, r, np.full(40, u_c))
    assert annulus == pytest.approx(interpolated_leak_rate(AIR, P_A, P_B, u_c, 2 * math.pi / math.log(1 + L / R0)),
                                    rel=1e-12)


def test_annulus_and_strip_differ_by_half_the_width_over_the_radius():
    """2 pi / ln(1 + l/r) = (2 pi r / l)(1 + l / 2r - l^2 / 12 r^2 + ...): the flat strip of eq (9)
    is the annulus to first order in l / r."""
    for x in (0.2, 0.05, 0.01):
        r = np.array([R0, R0 * (1 + x)])
        ratio = profile_leak_rate(AIR, P_A, P_B, r, [1e-7]) / profile_leak_rate(AIR, P_A, P_B, r, [1e-7], "strip")
        assert ratio - 1 == pytest.approx(x / 2 - x * x / 12, abs=x ** 3)


def test_two_steps_are_two_strips_in_series():
    """Inner ring (gap u1) and outer ring (u2): the flow through each, by the closed form eq (19)
    between the intermediate pressure P_m and its ends, is the same; P_m found independently."""
    r = np.array([R0, R0 + 0.7 * L, R0 + L])
    u1, u2 = 0.15e-6, 0.6e-6
    q = profile_leak_rate(AIR, P_A, P_B, r, [u1, u2])
    inner = lambda pm: interpolated_leak_rate(AIR, pm, P_B, u1, 2 * math.pi / math.log(r[1] / r[0]))  # noqa: E731
    outer = lambda pm: interpolated_leak_rate(AIR, P_A, pm, u2, 2 * math.pi / math.log(r[2] / r[1]))  # noqa: E731
    p_m = brentq(lambda pm: inner(pm) - outer(pm), P_B, P_A, xtol=1e-9)
    assert q == pytest.approx(inner(p_m), rel=1e-10)
    # and the narrow ring dominates: less flow than either ring alone would pass
    assert q < min(inner(P_A), outer(P_B))


def test_a_sealed_ring_stops_the_flow_and_an_open_ring_costs_nothing():
    r = np.array([R0, R0 + 1e-3, R0 + 2e-3, R0 + 3e-3])
    assert profile_leak_rate(AIR, P_A, P_B, r, [1e-7, 0.0, 1e-7]) == 0.0
    with_gap = profile_leak_rate(AIR, P_A, P_B, r, [1e-7, math.inf, 1e-7])
    direct = profile_leak_rate(AIR, P_A, P_B, r[[0, 1, 2, 3]], [1e-7, 1e3, 1e-7])   # a wide-open ring
    assert with_gap == pytest.approx(direct, rel=1e-9)
    assert profile_leak_rate(AIR, P_A, P_A, r, [1e-7, 1e-7, 1e-7]) == 0.0


def test_liquid_rings_are_eq_24_in_series():
    r = np.array([R0, R0 + 0.5 * L, R0 + L])
    mu = 1.002e-3
    uniform = profile_liquid_rate(mu, P_A, P_B, r, [0.3e-6, 0.3e-6], radial="strip")
    assert uniform == pytest.approx(liquid_volume_rate(mu, P_A, P_B, 0.3e-6, 2 * math.pi * R0 / L), rel=1e-12)
    q = profile_liquid_rate(mu, P_A, P_B, r, [0.2e-6, 0.5e-6])
    # the same flow through each ring: the pressure drops add up to p_a - p_b
    drops = [q * 12 * mu * math.log(r[i + 1] / r[i]) / (2 * math.pi * u ** 3) for i, u in enumerate((0.2e-6, 0.5e-6))]
    assert sum(drops) == pytest.approx(P_A - P_B, rel=1e-12)


def _hertz_like(n: int) -> ContactProfile:
    """A smooth strip 2 mm wide peaking at 150 kPa, sampled at n + 1 radii."""
    r = np.linspace(R0, R0 + L, n + 1)
    return ContactProfile(r, 150e3 * np.sin(np.pi * (r - R0) / L) ** 0.5 + 1e3)


def test_the_flow_converges_with_the_radial_sampling_at_second_order():
    uc = UcTable(np.geomspace(1e-4, 1.0, 60), 0.68e-6 * (np.geomspace(1e-4, 1.0, 60) / 0.025) ** -0.8)
    q = []
    for n in (20, 40, 80, 160, 320):
        prof = _hertz_like(n)
        q.append(profile_leak_rate(AIR, P_A, P_B, prof.r_m, ring_gaps(prof, uc, 4e6)))
    d = np.abs(np.diff(q))
    orders = np.log2(d[:-1] / d[1:])
    assert np.all(orders > 1.7), orders          # measured 1.86-1.88 (the sqrt edge of the profile)
    assert d[-1] / q[-1] < 1e-3


def test_contact_profile_refuses_bad_input():
    with pytest.raises(ValueError, match="r_m: profile radii must be > 0 and strictly increasing"):
        ContactProfile([2e-3, 1e-3], [1.0, 2.0])
    with pytest.raises(ValueError, match="p_Pa: contact pressure must be >= 0"):
        ContactProfile([1e-3, 2e-3], [1.0, -2.0])
    assert ContactProfile([1.0, 2.0], [3.0, 3.0]).force_N == pytest.approx(math.pi * 3.0 * 3.0)
