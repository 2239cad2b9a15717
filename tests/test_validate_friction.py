"""The friction section of `cupcheck validate` (validation/crosscheck/friction.py): the search for
the mu matching the paper's 2.5 N/mm on a known k(mu). The quick section end to end (coarse) is in
tests/test_validate.py, on the shared quick report."""

import math

import numpy as np
import pytest

from validation.crosscheck import friction
from validation.crosscheck.runs import FemResult, FemRun


class _FakeContext:
    """A Context whose FEM runs to u = 1 mm return F0(1 mm) = k(mu) * 1 mm for a given k(mu)."""

    def __init__(self, k_of_mu):
        self.k_of_mu, self.asked = k_of_mu, []

    def fem(self, request: FemRun) -> FemResult:
        mu = math.inf if request.friction is None else request.friction
        self.asked.append(mu)
        h1 = FemRun(cup="A").geometry().h1_m
        u = np.array([0.0, request.u_max_over_h1 * h1])
        z = np.zeros(2)
        return FemResult(request=request, h1_m=h1, u_m=u, F0_N=self.k_of_mu(mu) * 1e3 * u,
                         F0_contact_N=z, r_c_m=z, l_m=z, V_m3=z, energy_J=z, penetration_m=z,
                         wall_s=0.0, steps=1, newton_iterations=1, dofs=1, outline_r_m=z,
                         outline_z_m=z, outline_p_Pa=z)


def test_a_jump_across_the_target_is_reported_as_a_jump_not_a_match():
    ctx = _FakeContext(lambda mu: 0.7 + 0.9 * min(mu, 1.0) if mu < 1.176 else 4.0)
    m = friction.matching_mu(ctx, (0.0, 0.5, 1.0, 2.0), "coarse", rel_tol=1e-3)
    assert m["found"] and m["jump"] and math.isnan(m["mu"])
    assert m["lo"] < 1.176 <= m["hi"] and m["hi"] - m["lo"] <= 1e-3 * m["hi"]
    assert m["k_lo"] == pytest.approx(1.6) and m["k_hi"] == pytest.approx(4.0)
    # the grid is read once, then only bisection points inside the bracket [1, 2]
    assert ctx.asked[:4] == [0.0, 0.5, 1.0, 2.0] and all(1.0 < mu < 2.0 for mu in ctx.asked[4:])


def test_a_continuous_k_gives_the_crossing():
    ctx = _FakeContext(lambda mu: 0.7 + 2.0 * mu)           # 2.5 N/mm at mu = 0.9
    m = friction.matching_mu(ctx, (0.0, 0.5, 1.0, 2.0), "coarse", rel_tol=1e-2)
    assert m["found"] and not m["jump"]
    assert m["mu"] == pytest.approx(0.9, rel=1e-9)           # linear k: the interpolation is exact


def test_no_bracket_says_so():
    m = friction.matching_mu(_FakeContext(lambda mu: 1.0), (0.0, 1.0), "coarse", rel_tol=1e-2)
    assert m["found"] is False and len(m["grid"]) == 2


def test_sticking_law_is_mu_infinity_and_friction_only_with_coulomb():
    assert friction.law_run("A", None, "coarse").contact == "sticking"
    assert friction.law_run("A", 0.3, "coarse").friction == 0.3
    with pytest.raises(ValueError, match="friction"):
        FemRun(contact="frictionless", friction=0.3)
    with pytest.raises(ValueError, match="friction"):
        FemRun(contact="coulomb")


def test_the_reasons_named_under_the_lifetimes_table():
    """A curve whose F0 falls by more than half in one step folds with the cone laws (said, with
    where), a fold without such a drop is not explained by it, and a 'sealed' own-geometry cell
    under a sub-element strip says the width is the mesh's."""
    from types import SimpleNamespace

    import numpy as np

    from validation.crosscheck.friction import _why_not_reached

    r = SimpleNamespace(u_m=np.array([0.0, 1.0, 2.0, 3.0]) * 1e-3, F0_N=np.array([0.0, 5.0, 1.3, 4.0]),
                        l_m=np.array([0.0, 0.01, 0.5, 1.0]) * 1e-3)
    notes = _why_not_reached("mu 1.2", r, {"fold"}, {"sealed"})
    assert len(notes) == 2
    assert "from 5 to 1.3 N at u = 2 mm" in notes[0] and "0.01-0.01 mm wide at u = 1-1 mm" in notes[1]
    assert _why_not_reached("mu 1.2", r, {"reached_r1"}, {"reached_r1"}) == []
    smooth = SimpleNamespace(u_m=r.u_m, F0_N=np.array([0.0, 1.0, 2.0, 3.0]), l_m=r.l_m)
    assert _why_not_reached("mu 1.2", smooth, {"fold"}, set()) == []
