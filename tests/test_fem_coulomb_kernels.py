"""The linear-algebra kernels of Coulomb's Newton step and its stop on a creeping residual:
the condensation's scatter as a sparse product (bit for bit the bincount it replaces), the
contact rows of the gas tangent kept as sparse rows plus the rank-one term (against the whole
tangent's product with the identity), and `fem.newton.creeping` on the residual histories of a
converging and a creeping iteration."""

import numpy as np
import pytest
import scipy.sparse as sp

from fem.condensation import _scatter_matrix
from fem.friction import _rows
from fem.newton import creeping
from fem.trapped_gas import GasTangent


def _bincount_scatter(index, values, size):
    """The sums of values [index.size, m] into `size` slots by `index`, column by column."""
    flat = index.ravel()
    m = values.shape[1]
    return np.bincount((flat[:, None] * m + np.arange(m)).ravel(), weights=values.ravel(),
                       minlength=size * m).reshape(size, m)


@pytest.mark.parametrize("m", [1, 3, 40])
def test_scatter_matrix_sums_like_bincount_bit_for_bit(m):
    """Values spanning 16 decades, so that any other summation order would show in the last bits."""
    rng = np.random.default_rng(7)
    index = rng.integers(0, 50, size=(30, 16))
    values = rng.standard_normal((index.size, m)) * 10.0 ** rng.integers(-8, 8, size=(index.size, m))
    P = _scatter_matrix(index, 50)
    assert np.array_equal(P @ values, _bincount_scatter(index, values, 50))
    assert np.array_equal(P @ values[:, 0], _bincount_scatter(index, values[:, :1], 50)[:, 0])


def test_rank_one_rows_equal_the_rows_of_the_whole_gas_tangent():
    """`fem.friction._rows` of a gas tangent K_s + c g g^T: its dense rows and its products with
    columns equal those of the whole tangent (its product with the identity); a plain tangent's
    rows are its slices."""
    rng = np.random.default_rng(3)
    A = sp.random(14, 14, density=0.3, random_state=4, format="csr")
    Ks = (A + A.T + 14 * sp.identity(14)).tocsr()
    g = np.zeros(14)
    g[[1, 4, 5, 9, 13]] = rng.normal(size=5)
    K = GasTangent.of(Ks, Ks.data, 2.5, g)
    dofs = np.array([9, 0, 4, 13])
    whole = K @ np.eye(14)
    rows = _rows(K, dofs)
    X = rng.normal(size=(14, 3))
    assert np.allclose(rows.toarray(), whole[dofs], rtol=0, atol=1e-12)
    assert np.allclose(rows @ X, whole[dofs] @ X, rtol=0, atol=1e-12)
    assert np.allclose(rows @ X[:, 0], whole[dofs] @ X[:, 0], rtol=0, atol=1e-12)
    assert np.array_equal(_rows(Ks, dofs).toarray(), Ks[dofs].toarray())


def test_creeping_tells_a_creep_from_a_slow_convergence():
    """A creep (the residual falls by a tenth per iteration towards a floor of 2.5e-3, as the
    medium cup's largest pull did for 200 iterations) is caught once 20 iterations have not halved
    it; Newton's quadratic fall, a steady linear fall by 0.95 per iteration, and a short history
    are not."""
    floor = 2.5e-3
    creep = [2e-11, 0.19] + [floor + 0.02 * 0.9**k for k in range(60)]
    first = next(n for n in range(len(creep) + 1) if creeping(creep[:n]))
    assert 25 < first < len(creep)
    assert not any(creeping(creep[:n]) for n in range(first))
    newton = [2e-11, 0.19] + [0.19 * 1e-2**(2**k - 1) for k in range(4)]
    linear = [2e-11, 0.19] + [0.19 * 0.95**k for k in range(80)]
    for history in (newton, linear, creep[:21]):
        assert not any(creeping(history[:n]) for n in range(len(history) + 1))
