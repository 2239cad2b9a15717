"""The cavity load's jump where the contact's outer end moves (`fem.chain_cut.ChainCut`), against the
gas mechanics' own residual, and the Coulomb Newton iteration that carries it: the outer end of
the seal peels (or lands) in one iteration instead of one node per iteration."""

from __future__ import annotations

import numpy as np
import pytest

import fem.gas_pull as gas_pull
from fem.chain_cut import ChainCut
from fem.interface import ContactLaw
from fem.trapped_gas import GasMechanics, TrappedGas
from reduced.cup import CUPS
from validation.bridge.fem_route import FemCup


def _sealed(fidelity: str, contact: ContactLaw):
    cup = FemCup("A", fidelity, contact=contact).build(293.15, 1e5)
    return cup, cup.press_to(r_start_m=CUPS["A"].r_start_m)[-1]


def test_load_change_is_the_residual_jump_of_a_lifted_outer_node():
    """Lift the outermost held node by eps: the residual of the gas mechanics (the cut found from
    the geometry) jumps by ChainCut.load_change of the new cut plus O(eps); the Richardson
    combination 2 D(eps) - D(2 eps) removes the O(eps) part."""
    cup, sealed = _sealed("coarse", ContactLaw("frictionless"))
    gas = TrappedGas(0.8 * sealed.N, cup.T_K, cup.p_a_Pa)         # dp > 0 at the sealed shape
    mech = GasMechanics(cup.cup.mech, cup.cavity, gas)
    u0 = sealed.state.u
    x0 = mech.coordinates(u0)
    cut = ChainCut(cup.cavity, x0, mech.dp_Pa(u0))
    k0 = cut.index
    assert cut.dp_Pa > 1e3 and cut.on_plane()[k0]
    lifted = int(cup.cavity.nodes[k0])
    k1 = cut.cut_of(np.r_[cut.on_plane()[:k0], False, cut.on_plane()[k0 + 1:]])
    assert k1 < k0
    jump = cut.load_change(k1)
    assert np.linalg.norm(jump) > 1e-3                             # N: a real jump

    def D(eps):
        u = u0.copy()
        u[2 * lifted + 1] += eps
        assert cup.cavity.cut_index(mech.coordinates(u)) == k1
        return mech.internal_force(u) - mech.internal_force(u0)

    eps = 1e-9 * cup.h1_m
    limit = 2.0 * D(eps) - D(2.0 * eps)
    assert np.linalg.norm(limit - jump) <= 1e-5 * np.linalg.norm(jump)


class _Stop(Exception):
    pass


def _pull_iterations(cup, sealed, u_stop_m: float) -> list[int]:
    """The Newton iterations of each step of the largest pull's path (`fem.gas_pull`) up to a plate
    raised by u_stop_m from the sealed state."""
    pull, its = gas_pull._Pull(cup, sealed, 0.02), []

    def step(s):
        if s.t > 0:
            its.append(s.iterations)
        if s.t >= u_stop_m:
            raise _Stop
    try:
        gas_pull.follow_gas_path(pull.mech, pull.plate(0.0), pull.span, plane=cup.cup.plane,
                                 start=sealed.state, options=pull.options, on_step=step)
    except _Stop:
        pass
    return its


@pytest.fixture(scope="module")
def coulomb_medium():
    return _sealed("medium", ContactLaw("coulomb", 0.5))


def test_the_outer_end_peels_in_one_iteration(coulomb_medium, monkeypatch):
    """Cup A, medium, Coulomb 0.5, the largest pull's first 3.5 mm: without the jump in the
    condensed problem (load_change zero: the iterate's cut only) the outer end peels one node per
    Newton iteration (steps of 9 and 12 iterations); with it no step takes more than 6."""
    cup, sealed = coulomb_medium
    carried = _pull_iterations(cup, sealed, 3.5e-3)
    monkeypatch.setattr(ChainCut, "load_change", lambda self, k: np.zeros(self.x.size))
    late = _pull_iterations(cup, sealed, 3.5e-3)
    print(carried, late)
    assert len(carried) >= 20 and len(late) >= 20
    peels = lambda its: sum(n >= 8 for n in its)          # noqa: E731
    assert peels(late) >= 2 and max(late) >= 9
    assert peels(carried) == 0 and max(carried) <= 6
    assert sum(carried) < sum(late)
