"""The presets' u_c tables stored with the package (`reduced.roughness.stored`) are the ones Persson
theory computes now, bit for bit, and `uc_table` returns them for exactly the requests they answer.

If this fails after an edit of reduced/roughness, regenerate: ``python -m reduced.roughness.surfaces --tables``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from reduced.roughness import preset, uc_table
from reduced.roughness.persson import UC_TABLE_P_OVER_E
from reduced.roughness.stored import STORED_NU, request_key, stored_table
from reduced.roughness.surfaces import load_presets


def _same(a, b) -> None:
    for f in dataclasses.fields(a):
        if not f.init:
            continue
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and np.array_equal(x, y), f.name
        else:
            assert (dict(x) if f.name == "theory" else x) == (dict(y) if f.name == "theory" else y), f.name


@pytest.mark.parametrize("name", sorted(load_presets()))
def test_each_presets_stored_table_is_the_fresh_computation_bit_for_bit(name):
    spectrum = preset(name).spectrum()
    key = request_key(spectrum, STORED_NU, "emt", 0.45, 0.42, UC_TABLE_P_OVER_E, True)
    stored = stored_table(key, UC_TABLE_P_OVER_E)
    assert stored is not None, "stale or missing: run `python -m reduced.roughness.surfaces --tables`"
    fresh = uc_table(spectrum, STORED_NU, stored=False)
    _same(stored, fresh)
    _same(uc_table(spectrum, STORED_NU), fresh)                    # what callers get
    assert np.array_equal(stored(np.geomspace(1e-5, 0.5, 40)), fresh(np.geomspace(1e-5, 0.5, 40)))


@pytest.mark.parametrize("change", [{"nu": 0.49}, {"gamma": 0.4}, {"method": "critical-junction"},
                                    {"p_over_E": np.geomspace(1e-4, 1.0, 50)}, {"with_patch_length": False}])
def test_any_other_request_is_computed(change):
    """A request differing in any input is not answered from the store: `uc_table` gives the
    theory's table for it."""
    spectrum = preset("pmma-1.89").spectrum()
    args = {"nu": STORED_NU, **{k: v for k, v in change.items() if k == "nu"}}
    options = {k: v for k, v in change.items() if k != "nu"}
    grid = options.get("p_over_E", UC_TABLE_P_OVER_E)
    key = request_key(spectrum, args["nu"], options.get("method", "emt"), options.get("gamma", 0.45), 0.42,
                      grid, options.get("with_patch_length", True))
    assert stored_table(key, grid) is None
    _same(uc_table(spectrum, args["nu"], **options), uc_table(spectrum, args["nu"], stored=False, **options))


def test_the_key_follows_the_spectrum():
    """The same preset's spectrum on another grid of wavevectors is another request."""
    p = preset("pmma-1.89")
    key = lambda s: request_key(s, STORED_NU, "emt", 0.45, 0.42, UC_TABLE_P_OVER_E, True)  # noqa: E731
    assert key(p.spectrum()) == key(p.spectrum())
    assert key(p.spectrum(n=1999)) != key(p.spectrum())
