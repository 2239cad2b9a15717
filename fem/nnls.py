"""Non-negative least squares, scipy's: `scipy.optimize.nnls` (Lawson-Hanson) without the import of
scipy.optimize.

Importing scipy.optimize pulls in linprog, scipy.fft and scipy.special, for one compiled function.
`nnls` calls that function, scipy's own compiled module (`scipy/optimize/_slsqplib`), loaded on its
own and registered under its name (a later `import scipy.optimize` takes the same module), with the
arguments scipy's wrapper gives it. Where this scipy has no such module, or its `nnls` does not
answer a small problem as (x, rnorm, info), it calls `scipy.optimize.nnls`. Either way it is the
same computation, bit for bit.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

__all__ = ["nnls"]


def nnls(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x >= 0 minimizing |A x - b| (as `scipy.optimize.nnls(A, b)[0]`, at most 3 n iterations)."""
    A = np.asarray_chkfinite(A, dtype=np.float64, order="C")
    b = np.asarray_chkfinite(b, dtype=np.float64)
    kernel = _compiled()
    if kernel is None:
        from scipy.optimize import nnls as scipy_nnls
        return scipy_nnls(A, b)[0]
    x, _, info = kernel(A, b, 3 * A.shape[1])
    if info == 3:
        raise RuntimeError("Maximum number of iterations reached.")
    return x


@functools.cache
def _compiled() -> Callable | None:
    """scipy's compiled NNLS (`_slsqplib.nnls(A, b, maxiter) -> (x, rnorm, info)`), or None when this
    scipy has no such module or its function answers otherwise."""
    import importlib.machinery
    import importlib.util
    import sys
    from pathlib import Path

    name = "scipy.optimize._slsqplib"
    module = sys.modules.get(name)
    if module is None:
        import scipy

        folder = Path(scipy.__file__).parent / "optimize"
        paths = [folder / f"_slsqplib{s}" for s in importlib.machinery.EXTENSION_SUFFIXES]
        path = next((p for p in paths if p.is_file()), None)
        if path is None:
            return None
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    kernel = getattr(module, "nnls", None)
    return kernel if kernel is not None and _answers(kernel) else None


def _answers(kernel: Callable) -> bool:
    """Whether `kernel` solves min |x - (1, -1)|, x >= 0 as scipy's NNLS does: ((1, 0), 1, info)."""
    try:
        x, rnorm, info = kernel(np.eye(2), np.array([1.0, -1.0]), 6)
    except (TypeError, ValueError):
        return False
    return np.array_equal(x, [1.0, 0.0]) and rnorm == 1.0 and info != 3
