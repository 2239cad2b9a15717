"""The held branch of the route "fem" (`fem.gas_branch.equilibrium_branch`) across slips: the
sticking cup pressed to r_start, sealed and held at F1 slips as gas enters at the held plate
(its pull falls across F1 by a jump: 10.87 -> 8.50 N at u = 4.95 mm, N = 1.256 N0), and the
plate rises at that N until the pull is F1 again (`fem.branch_jumps`); the frictionless branch
for its work balance.

Physics checks, on every state and on the branch: the pull is F1; plate, contact pressure and
suction balance; N rises; the work balance (the stored energy of body and gas against the
plate's work and the work of the gas let in) closes for the frictionless branch to the
quadrature between its states, and leaves a dissipation >= 0 across the sticking slip."""

from __future__ import annotations

import math

import numpy as np
import pytest

import reduced
from fem.gas_branch import equilibrium_branch
from fem.interface import ContactLaw
from fem.trapped_gas import K_B
from validation.bridge.fem_route import DEFAULT_DU_M, FemCup, register
from validation.bridge.pipeline import surface_uc_table

F1 = 10.0           # N
U_END = 4.4e-3      # m: the sticking branch is followed to here: across its first slips (from 4.95 mm)


@pytest.fixture(scope="module")
def model():
    return reduced.reference_model(reduced.CUP_A, surface_uc_table())


def _branch(model, law, **kw):
    route = register()
    sealed = route.seal(model, {**route.options, "cup": FemCup("A", "coarse", contact=law)})
    return sealed.cup, equilibrium_branch(sealed.cup, sealed.state, F1, du_m=DEFAULT_DU_M, **kw)


@pytest.fixture(scope="module")
def sticking(model):
    return _branch(model, ContactLaw("sticking"), u_min_m=U_END)


@pytest.fixture(scope="module")
def frictionless(model):
    return _branch(model, ContactLaw())


def work_balance(cup, branch) -> tuple[float, float]:
    """(D, scale) [J]: D = plate work + work of the gas let in - change of the stored energy
    (body W(u) + p_a V - N k_B T ln V) from the first state to the last, by the trapezoid over the
    states; scale = the largest of the terms."""
    s = branch.states
    W = np.array([cup.cup.mech.energy(x.state.u) + cup.p_a_Pa * x.V_m3
                  - x.N * K_B * cup.T_K * math.log(x.V_m3) for x in s])
    u, F, N = branch.column("u_m"), branch.column("F1_N"), branch.column("N")
    lnV = np.log(branch.column("V_m3"))
    plate = float(np.sum(0.5 * (F[1:] + F[:-1]) * -np.diff(u)))         # u_z = -u on the plate
    gas = float(np.sum(-K_B * cup.T_K * 0.5 * (lnV[1:] + lnV[:-1]) * np.diff(N)))
    return plate + gas - (W[-1] - W[0]), max(abs(plate), abs(gas), abs(W[-1] - W[0]))


def test_frictionless_branch_holds_the_pull_and_its_work_balance_closes(frictionless):
    """No dissipation on a frictionless path: the balance closes to the trapezoid's error."""
    cup, b = frictionless
    assert b.reason in ("fold", "seal opened") and b.detachment is b.states[-1]
    _holds_and_balances(cup, b)
    D, scale = work_balance(cup, b)
    print(f"frictionless: D = {D:.4g} J of {scale:.4g} J")
    assert abs(D) <= 1e-4 * scale           # measured: 6e-6 (coarse, 10 N)


def test_sticking_crosses_its_slip_and_dissipates(sticking, frictionless):
    """The sticking branch's pull falls across F1 by its slips as gas enters at the held plate;
    the states after them hold F1 again, higher (the plate raised), with more gas, and the slips
    dissipate: the branch's work balance leaves D > 0, beyond the frictionless branch's
    quadrature error per unit of work, and so does the solver's own count."""
    cup, b = sticking
    assert b.reason == "u_min" and len(b.states) >= 3
    assert np.all(np.diff(b.column("u_m")) < 0)
    _holds_and_balances(cup, b)
    D, scale = work_balance(cup, b)
    D0, scale0 = work_balance(*frictionless)
    print(f"sticking: D = {D:.4g} J of {scale:.4g} J, {b.snaps} slips; solver {b.stats.dissipated_J:.4g} J")
    assert D > 2 * abs(D0) / scale0 * scale
    assert b.stats.dissipated_J > 0.0


def _holds_and_balances(cup, b) -> None:
    """Every state pulls F1 and balances plate, contact pressure and suction; N rises."""
    N = b.column("N")
    assert np.all(np.diff(N) > 0)
    for s in b.states:
        scale = cup.p_a_Pa * math.pi * s.seal_r_m**2
        assert abs(s.F1_N - F1) <= cup.options.rtol * scale
        contact = float(np.sum(s.profile.p_gauss_Pa * s.profile.w_m2))
        assert abs(s.F1_N + contact - s.dp_Pa * math.pi * s.cut_r_m**2) <= 1e-7 * scale


def test_tangent_rows_carry_the_gas_rank_one_term():
    """`fem.trapped_gas.tangent_rows`: the rows of the whole gas tangent K_s + c g g^T, as the
    condensed contact rows of `fem.friction` need them, equal the rows of its product with the
    identity (the product includes the rank-one term, slicing does not)."""
    import scipy.sparse as sp

    from fem.trapped_gas import GasTangent, tangent_rows

    rng = np.random.default_rng(3)
    A = sp.random(12, 12, density=0.3, random_state=4, format="csr")
    Ks = (A + A.T + 12 * sp.identity(12)).tocsr()
    g = np.zeros(12)
    g[[1, 4, 5, 9]] = rng.normal(size=4)
    K = GasTangent.of(Ks, Ks.data, 2.5, g)
    dofs = np.array([9, 0, 4])
    whole = K @ np.eye(12)
    assert np.allclose(tangent_rows(K, dofs).toarray(), whole[dofs], rtol=0, atol=1e-12)
    assert np.allclose(K.rows(dofs).toarray(), whole[dofs], rtol=0, atol=1e-12)
    assert np.array_equal(tangent_rows(Ks, dofs).toarray(), Ks[dofs].toarray())


def test_a_branch_that_stops_says_where_and_why(model):
    """A branch whose solver cannot go on ends with reason "stopped ...", never a number: the
    reason names the last state it holds (plate position, N / N0) and the solver's cause. Here
    with two Newton iterations allowed per load step (frictionless, 10 N: a few states, then a
    move that does not converge)."""
    from dataclasses import replace

    route = register()
    sealed = route.seal(model, {**route.options, "cup": FemCup("A", "coarse", contact=ContactLaw())})
    cup = replace(sealed.cup, options=replace(sealed.cup.options, max_iterations=2))
    b = equilibrium_branch(cup, sealed.state, F1, du_m=DEFAULT_DU_M)
    print(b.reason)
    assert b.detachment is None
    last = b.states[-1] if b.states else sealed.state
    where = "stopped after the state at" if b.states else "stopped raising the plate at N0 from"
    where += f" u = {last.u_m * 1e3:.4g} mm, N = {last.N / sealed.state.N:.4g} N0: "
    assert b.reason.startswith(where), b.reason
    assert "Newton" in b.reason


def test_coulomb_at_large_mu_leaves_the_sealed_state_in_equilibrium(model):
    """Coulomb at mu = 10: the plate's rise at N0 from the sealed state crosses a seal node on
    the edge of the friction cone, where the undamped step has no stick/slide set (Klarbring);
    the damped motion ends at rest there (`fem.newton.out_of_balance`). Followed to u = 4 mm,
    every state pulls F1 and balances plate, contact pressure and suction, N rises, and the
    work balance leaves a dissipation >= 0."""
    cup, b = _branch(model, ContactLaw("coulomb", 10.0), u_min_m=4.0e-3)
    assert b.reason == "u_min" and len(b.states) >= 5
    _holds_and_balances(cup, b)
    D, scale = work_balance(cup, b)
    print(f"coulomb 10: D = {D:.4g} J of {scale:.4g} J, {len(b.states)} states")
    assert D >= -1e-4 * scale
