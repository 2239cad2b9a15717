"""Non-negative least squares, scipy's: `scipy.optimize.nnls` (Lawson-Hanson) without the import of
scipy.optimize.

Importing scipy.optimize pulls in linprog, scipy.fft and scipy.special: about 0.17 s of CPU, a
quarter of a whole coarse stiffness-curve process, for one compiled function. `nnls` calls that
function, scipy's own compiled module, loaded on its own when this scipy ships it where 1.15-1.17
do (`scipy/optimize/_slsqplib`), with the arguments scipy's wrapper gives it; otherwise it calls
`scipy.optimize.nnls`. Either way it is the same computation, bit for bit.
"""

from __future__ import annotations

import functools

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
def _compiled():
    """scipy's compiled NNLS (`_slsqplib.nnls(A, b, maxiter) -> (x, rnorm, info)`), or None when this
    scipy has no such module or function."""
    import importlib.machinery
    import importlib.util
    import sys
    from pathlib import Path

    name = "scipy.optimize._slsqplib"
    if name in sys.modules:
        return getattr(sys.modules[name], "nnls", None)
    import scipy

    folder = Path(scipy.__file__).parent / "optimize"
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = folder / f"_slsqplib{suffix}"
        if path.is_file():
            spec = importlib.util.spec_from_file_location(name, path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            return getattr(module, "nnls", None)
    return None
