"""The contact step's LCP (`fem.contact_step.lcp`) is solved by Lawson and Hanson's active-set
method written in the module (scipy.optimize's import costs about half a coarse curve's process):
checked against scipy's nnls on the same problem (the LCP as least squares on the Cholesky factor,
as the step solved it before), on random problems and on every LCP of cup A's coarse curve,
frictionless and sticking (1 to 10 nodes each): the same pressed set and the same multipliers to
round-off; also on every LCP of the sticking fem-route branch at 10 N, whose walk chooses its
first move's unknown (N or the plate) by a comparison of the tangent's components that round-off
decides (that tangent is diagonal by construction): a different branch there is not a different
LCP answer. Also its own conditions."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import nnls

import fem.contact_step
from fem.contact_step import lawson_hanson, lcp
from fem.cup import compress_cup
from fem.geometry import cup_geometry
from fem.interface import ContactLaw
from fem.mesh import cup_mesh


def _by_scipy(S: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The LCP by scipy's nnls on the Cholesky factor of the unit-diagonal S."""
    scale = np.sqrt(np.diag(S))
    L = np.linalg.cholesky(S / np.outer(scale, scale))
    return nnls(L.T, -np.linalg.solve(L, q / scale))[0] / scale


def _agree(S: np.ndarray, q: np.ndarray, rtol: float) -> None:
    lam, ref = lcp(S, q), _by_scipy(S, q)
    assert np.array_equal(lam > 0, ref > 0), (lam, ref)
    assert np.max(np.abs(lam - ref)) <= rtol * max(np.max(np.abs(ref)), 1e-300)
    w = q + S @ lam                                       # its own conditions
    assert lam.min() >= 0 and w.min() >= -1e-10 * np.max(np.abs(q))
    assert abs(lam @ w) <= 1e-10 * np.max(np.abs(q)) * max(np.max(lam), 1e-300)


def test_random_problems_agree_with_scipys_nnls():
    rng = np.random.default_rng(11)
    mixed = 0
    for _ in range(400):
        n = int(rng.integers(1, 40))
        A = rng.normal(size=(n, n)) * rng.lognormal(size=n)
        S = A @ A.T + 1e-2 * np.eye(n)
        q = rng.normal(size=n) * 10.0 ** rng.uniform(-8, 3)
        _agree(S, q, 1e-9)
        mixed += 0 < np.count_nonzero(lcp(S, q)) < n
    assert mixed > 100                      # the test can fail: most problems have both kinds of node


@pytest.mark.parametrize("law", ["frictionless", "sticking"])
def test_the_cups_own_contact_problems_agree_with_scipys_nnls(law, monkeypatch):
    seen = []
    own = fem.contact_step.lcp

    def record(S, q):
        seen.append((S.copy(), q.copy()))
        return own(S, q)

    monkeypatch.setattr(fem.contact_step, "lcp", record)
    compress_cup(cup_mesh(cup_geometry("A"), "coarse"), contact=law)
    assert len(seen) > 10 and max(len(q) for _, q in seen) >= 3
    for S, q in seen:
        _agree(S, q, 1e-9)


def test_the_sticking_branchs_contact_problems_agree_with_scipys_nnls(monkeypatch):
    """The sticking cup A pressed to r_start, sealed, pulled to 10 N and walked to 4.4 mm (as in
    tests/test_fem_route_branch.py, built here so that no shared sealed state is made with scipy's
    answers), scipy's answers driving: on every LCP on the way, the same pressed set and
    multipliers to 1e-9."""
    import reduced
    from fem.gas_branch import equilibrium_branch
    from validation.bridge.fem_route import DEFAULT_DU_M, FemCup
    from validation.bridge.pipeline import surface_uc_table

    seen = []

    def record(S, q):
        seen.append((S.copy(), q.copy()))
        return _by_scipy(S, q)

    monkeypatch.setattr(fem.contact_step, "lcp", record)
    model = reduced.reference_model(reduced.CUP_A, surface_uc_table())
    cup = FemCup("A", "coarse", contact=ContactLaw("sticking"))
    cup = cup.build(model.gas.T_K, model.p_a_Pa, model.fluid)
    sealed = cup.press_to(r_start_m=model.cup.r_start_m)[-1]
    branch = equilibrium_branch(cup, sealed, 10.0, du_m=DEFAULT_DU_M, u_min_m=4.4e-3)
    assert branch.reason == "u_min" and len(branch.states) >= 3
    assert len(seen) > 50 and max(len(q) for _, q in seen) >= 3
    for S, q in seen:
        _agree(S, q, 1e-9)


def test_the_unconstrained_minimum_is_returned_when_it_is_feasible():
    """H x = c with x > 0 needs no constraint: Lawson-Hanson returns the plain solution."""
    H = np.array([[2.0, 0.5], [0.5, 1.0]])
    x = np.array([0.3, 1.7])
    assert np.allclose(lawson_hanson(H, H @ x), x, rtol=1e-14)
    assert lawson_hanson(H, -H @ x).tolist() == [0.0, 0.0]
    assert lawson_hanson(np.zeros((0, 0)), np.zeros(0)).size == 0
