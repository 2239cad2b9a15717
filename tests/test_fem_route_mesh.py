"""The fem route's default mesh level against the next finer level (benchmarks/bench_fem_route.py
--mesh-study): cup A pressed to r_start, frictionless, pmma-1.89, the route's default plate step.
Independent check: the same cup and path on the nested mesh with twice the elements each way.

The largest holdable force is mesh-converged (coarse, medium, fine within 0.03 %). The lifetime
is within 1 % of the next finer level at the default (medium) since a node touching the plane
alone enters the leak by its reaction (validation.bridge.fem_leak): medium against fine 0.15,
0.38, 0.44 % at 5, 10, 20 N (benchmarks/fem_route_mesh_study.md); the coarse level is not
(1.2-4.6 %)."""

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


@pytest.fixture(scope="module")
def model():
    return reduced.reference_model(reduced.CUP_A, surface_uc_table())


@pytest.mark.slow
def test_default_mesh_largest_holdable_force_is_converged(model):
    default = FemCup("A").fidelity
    largest = [reduced.largest_holdable_force(model, "fem", cup=FemCup("A", level))
               for level in (default, next_finer(default))]
    assert largest[0] == pytest.approx(largest[1], rel=1e-3)


@pytest.mark.slow
def test_default_mesh_lifetime_within_one_percent_of_the_next_finer_level(model):
    default = FemCup("A").fidelity
    F = 10.0
    lives = [reduced.solve_lifetime(model, F, route="fem", cup=FemCup("A", level))
             for level in (default, next_finer(default))]
    assert lives[0].reason == lives[1].reason == "reached_r1"
    assert lives[0].lifetime_s == pytest.approx(lives[1].lifetime_s, rel=0.01)
