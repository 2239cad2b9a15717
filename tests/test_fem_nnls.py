"""`fem.nnls` is scipy's NNLS called without importing scipy.optimize: the same numbers, bit for bit,
on random and degenerate problems (the contact step's LCP solves one per Newton iteration)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fem import nnls as fem_nnls


@settings(max_examples=200, deadline=None)
@given(m=st.integers(1, 12), n=st.integers(1, 12), seed=st.integers(0, 2**32 - 1),
       rank=st.integers(0, 12))
def test_the_same_solution_bit_for_bit_as_scipy(m, n, seed, rank):
    from scipy.optimize import nnls

    rng = np.random.default_rng(seed)
    A = rng.standard_normal((m, n))
    if rank < min(m, n):                      # rank-deficient: columns repeated or zero
        A[:, rank:] = A[:, :1] if rank else 0.0
    b = rng.standard_normal(m)
    x = fem_nnls.nnls(A, b)
    assert np.array_equal(x, nnls(A, b)[0])
    assert (x >= 0).all()


def test_the_kkt_conditions_hold():
    """An independent check of the solution: x >= 0, the gradient A^T (A x - b) >= 0 where x = 0
    and = 0 where x > 0 (to round-off)."""
    rng = np.random.default_rng(7)
    A, b = rng.standard_normal((9, 6)), rng.standard_normal(9)
    x = fem_nnls.nnls(A, b)
    g = A.T @ (A @ x - b)
    assert (x >= 0).all() and (x > 0).any() and (x == 0).any()
    assert np.all(g[x == 0] >= -1e-12) and np.allclose(g[x > 0], 0.0, atol=1e-12)


def ships_the_kernel() -> bool:
    """Whether this scipy has the compiled module `fem.nnls` loads (1.15 on; 1.11 has another)."""
    from pathlib import Path

    import scipy
    return any((Path(scipy.__file__).parent / "optimize").glob("_slsqplib*"))


def test_the_compiled_kernel_is_scipys_own_and_bad_input_is_refused():
    import sys

    import scipy.optimize  # noqa: F401  (imported after fem.nnls may have loaded its module)

    kernel = fem_nnls._compiled()
    assert (kernel is not None) == ships_the_kernel()                 # shipped: the fast path is taken
    if kernel is not None:                                            # one module, not a second copy
        assert kernel is sys.modules["scipy.optimize._slsqplib"].nnls
    with pytest.raises(ValueError):
        fem_nnls.nnls(np.array([[1.0, np.nan]]), np.array([1.0]))


def test_without_the_compiled_kernel_it_is_scipy_optimize_nnls(monkeypatch):
    from scipy.optimize import nnls

    monkeypatch.setattr(fem_nnls, "_compiled", lambda: None)
    rng = np.random.default_rng(3)
    A, b = rng.standard_normal((7, 5)), rng.standard_normal(7)
    assert np.array_equal(fem_nnls.nnls(A, b), nnls(A, b)[0])
    assert not fem_nnls._answers(lambda A, b, maxiter: (np.zeros(2), 0.0, 0))   # a kernel that answers wrongly
