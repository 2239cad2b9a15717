"""Material point: the neo-Hookean law against closed-form principal stresses (round-off)."""

import numpy as np
import pytest

from fem.material import NeoHookean, cauchy_stress, jacobian

MAT = NeoHookean(E_Pa=4e6, nu=0.45)


def principal_cauchy(mat, stretches):
    """sigma_i = (mu (lambda_i^2 - 1) + lambda ln J) / J for a diagonal F (textbook closed form)."""
    l = np.asarray(stretches, float)
    J = np.prod(l)
    return (mat.mu * (l**2 - 1.0) + mat.lam * np.log(J)) / J


def f_of(F2, Ftt):
    return np.array([F2[0, 0], F2[0, 1], F2[1, 0], F2[1, 1], Ftt])[:, None]


@pytest.mark.parametrize("stretches", [(1.3, 0.8, 1.3),      # equibiaxial in r-theta, with hoop
                                       (0.9, 1.4, 0.9),      # uniaxial-type along z
                                       (1.1, 0.7, 1.25),     # general triaxial
                                       (1.0, 1.0, 1.0)])
@pytest.mark.parametrize("angle", [0.0, 0.7])
def test_cauchy_stress_matches_closed_form(stretches, angle):
    """F = Q diag(l_r, l_z) in the (r, z) plane, l_t in hoop: sigma = Q diag(sigma_i) Q^T.
    Tolerance 1e-12 relative to mu: round-off of a few dozen flops."""
    lr, lz, lt = stretches
    c, s = np.cos(angle), np.sin(angle)
    Q = np.array([[c, -s], [s, c]])
    f = f_of(Q @ np.diag([lr, lz]), lt)
    sig = cauchy_stress(f, MAT.stress(f))[:, 0]
    sr, sz, st = principal_cauchy(MAT, stretches)
    expected2 = Q @ np.diag([sr, sz]) @ Q.T
    got2 = np.array([[sig[0], sig[3]], [sig[3], sig[1]]])
    assert np.allclose(got2, expected2, rtol=0, atol=1e-12 * MAT.mu)
    assert sig[2] == pytest.approx(st, abs=1e-12 * MAT.mu)


def test_stress_is_energy_gradient_and_tangent_is_stress_gradient():
    """Central differences (h = 1e-6): truncation O(h^2) ~ 1e-12, round-off ~ 1e-16/h; 1e-7 relative."""
    rng = np.random.default_rng(1)
    f = np.array([1.1, 0.2, -0.1, 0.9, 1.2])[:, None] + 0.05 * rng.standard_normal((5, 4))
    h = 1e-6
    P, A = MAT.stress(f), MAT.tangent(f)
    for k in range(5):
        e = np.zeros((5, 1))
        e[k] = h
        dW = (MAT.energy(f + e) - MAT.energy(f - e)) / (2 * h)
        dP = (MAT.stress(f + e) - MAT.stress(f - e)) / (2 * h)
        assert np.allclose(dW, P[k], rtol=1e-7, atol=1e-7 * MAT.mu)
        assert np.allclose(dP, A[:, k], rtol=1e-7, atol=1e-7 * MAT.mu)
    assert np.allclose(A, np.swapaxes(A, 0, 1))


def test_small_strain_limit_is_hooke():
    """eps = 1e-7: sigma = lambda tr(eps) + 2 mu eps to O(eps^2), i.e. relative 1e-6."""
    eps = np.array([1e-7, -3e-7, 2e-7])   # rr, zz, tt
    f = f_of(np.diag(1 + eps[:2]), 1 + eps[2])
    sig = cauchy_stress(f, MAT.stress(f))[:, 0]
    hooke = MAT.lam * eps.sum() + 2 * MAT.mu * eps
    assert np.allclose(sig[:3], hooke, rtol=1e-5)
    assert MAT.mu == pytest.approx(4e6 / 2.9)
    assert jacobian(f)[0] == pytest.approx(np.prod(1 + eps))


@pytest.mark.parametrize("kwargs, field", [({"E_Pa": -1.0}, "E_Pa"), ({"nu": 0.5}, "nu"),
                                            ({"formulation": "u-p"}, "formulation")])
def test_bad_material_input_names_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field):
        NeoHookean(**kwargs)
