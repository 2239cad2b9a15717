"""The hand-off type: CSV round trip, monotone interpolation, explicit range errors."""

import numpy as np
import pytest

from reduced.stiffness_curve import StiffnessCurve


def _curve(**kw):
    u = np.linspace(0.0, 8e-3, 9)
    F0 = np.array([0, 2.5, 4.8, 6.0, 6.2, 6.3, 9.0, 20.0, 60.0])
    return StiffnessCurve(u_m=u, F0_N=F0, h1_m=9.09e-3, provenance={"source": "test"}, **kw)


def test_csv_round_trip_preserves_every_column(tmp_path):
    u = np.linspace(0.0, 8e-3, 9)
    c = _curve(r_c_m=5e-3 + u, l_m=4e-3 - 0.2 * u, V_m3=1e-6 * (1 + u / 8e-3))
    path = c.to_csv(tmp_path / "curve.csv")
    header = [line for line in path.read_text().splitlines() if not line.startswith("#")][0]
    assert header == "u_mm,h_mm,F0_N,r_c_mm,l_mm,V_mm3"
    back = StiffnessCurve.from_csv(path)
    for name in ("u_m", "F0_N", "r_c_m", "l_m", "V_m3"):
        np.testing.assert_allclose(getattr(back, name), getattr(c, name), rtol=1e-9, atol=1e-15)
    assert back.h1_m == pytest.approx(c.h1_m, rel=1e-9)
    assert back.provenance["source"] == "test"


def test_measured_csv_without_h_needs_h1(tmp_path):
    path = tmp_path / "measured.csv"
    path.write_text("u_mm,F0_N\n0,0\n1,2.5\n2,4.9\n")
    with pytest.raises(ValueError, match="h1_mm"):
        StiffnessCurve.from_csv(path)
    c = StiffnessCurve.from_csv(path, h1_m=9e-3)
    assert c.force(9e-3 - 1e-3) == pytest.approx(2.5)
    assert not c.has("l_m")
    with pytest.raises(ValueError, match="l_m"):
        c.contact_width(8e-3)


def test_interpolation_reproduces_samples_and_does_not_overshoot():
    c = _curve()
    np.testing.assert_allclose(c.force(c.h_m), c.F0_N, atol=1e-12)
    h = np.linspace(*c.h_range_m, 2001)
    F = c.force(h)
    u = c.h1_m - h
    order = np.argsort(u)
    # the data are monotone in u, so must be the interpolant (PCHIP), with no overshoot
    assert np.all(np.diff(F[order]) >= -1e-12)
    assert F.min() >= c.F0_N.min() - 1e-12 and F.max() <= c.F0_N.max() + 1e-12


def test_outside_range_is_an_error_naming_the_range():
    c = _curve()
    with pytest.raises(ValueError, match=r"h_mm: .* outside .*range"):
        c.force(c.h1_m + 1e-4)
    with pytest.raises(ValueError, match="outside"):
        c.force(c.h1_m - 9e-3)


@pytest.mark.parametrize("field,value,match", [
    ("u_m", [0.0, 0.0, 1e-3], "strictly increasing"),
    ("F0_N", [0.0, np.nan, 1.0], "NaN"),
    ("h1_m", -1.0, "h1_m"),
])
def test_invalid_data_is_rejected(field, value, match):
    kw = dict(u_m=[0.0, 1e-3, 2e-3], F0_N=[0.0, 1.0, 2.0], h1_m=9e-3)
    kw[field] = value
    with pytest.raises(ValueError, match=match):
        StiffnessCurve(**kw)


def test_csv_with_unknown_column_names_allowed_ones(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("u_mm,F0_kN\n0,0\n1,2\n")
    with pytest.raises(ValueError, match="allowed: u_mm"):
        StiffnessCurve.from_csv(path, h1_m=9e-3)
