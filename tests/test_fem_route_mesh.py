"""The fem route's default mesh level against the next finer level (mesh convergence of the
lifetime, benchmarks/bench_fem_route.py --mesh-study): cup A pressed to r_start, frictionless,
pmma-1.89, the route's default plate step. Independent check: the same cup and path on a mesh with
twice the elements in each direction (the levels nest), the lifetime within 1 %."""

from __future__ import annotations

import pytest

import reduced
from fem.mesh import FIDELITIES
from validation.bridge.fem_route import FemCup
from validation.bridge.pipeline import surface_uc_table


def next_finer(level: str):
    """The fidelity level after `level`, or its spec refined by 2 past the finest."""
    names = list(FIDELITIES)
    k = names.index(level)
    return names[k + 1] if k + 1 < len(names) else FIDELITIES[level].refined()


@pytest.mark.slow
def test_default_mesh_lifetime_within_one_percent_of_the_next_finer_level():
    model = reduced.reference_model(reduced.CUP_A, surface_uc_table())
    default = FemCup("A").fidelity
    F = 10.0
    coarse, finer = (reduced.solve_lifetime(model, F, route="fem", cup=FemCup("A", level))
                     for level in (default, next_finer(default)))
    assert coarse.reason == finer.reason == "reached_r1"
    assert coarse.lifetime_s == pytest.approx(finer.lifetime_s, rel=0.01)
