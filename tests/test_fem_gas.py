"""The cavity's trapped gas in the FEM (fem/trapped_gas.py) and the sealed cup's path
(fem/gas_path.py): the rank-one tangent against dense linear algebra and finite differences,
frictionless (u, N) states against the dp-driven states of fem.suction (path independence),
global equilibrium of plate, contact and suction, and the sealed cup pulled and leaked into."""

from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fem.cavity import CavitySurface, PressurizedMechanics
from fem.condensation import make_solver
from fem.cup import CupSetup
from fem.geometry import cup_geometry
from fem.gas_branch import equilibrium_branch, pull_sensitivities
from fem.gas_path import CupWithGas, cup_path
from fem.linsolve import NotPositiveDefinite
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from fem.solver import SolverOptions, follow_path
from fem.suction import suction_grid
from fem.trapped_gas import K_B, GasMechanics, GasTangent, RankOneSolver, TrappedGas

RTOL = 1e-9      # tight solver tolerance: states compared across two paths to ~1e-6


@pytest.fixture(scope="module")
def mesh():
    return cup_mesh(cup_geometry("A"), "coarse")


@pytest.fixture(scope="module", params=["frictionless", "sticking"])
def path(request, mesh):
    return cup_path(mesh, NeoHookean(), 3e-3, 1.5e-3, 1.3, contact=request.param, rtol=RTOL)


@pytest.fixture(scope="module")
def frictionless(mesh):
    return cup_path(mesh, NeoHookean(), 3e-3, 1.5e-3, 1.3, rtol=RTOL)


def _gas_mech(mesh, state):
    cup = CupWithGas.of(mesh, NeoHookean())
    return cup, GasMechanics(cup.cup.mech, cup.cavity, TrappedGas(state.N))


def test_rank_one_factor_solves_the_full_tangent(mesh, frictionless):
    """The Newton step with the rank-one term (Sherman-Morrison on the sparse part's banded
    factor) equals a dense solve of K + c g g^T on the free dofs, with prescribed values on the
    plate and contact dofs, and after freeing some of those (the solver's bordered factor)."""
    s = next(s for s in frictionless.states if s.stage == "pulled" and s.dp_Pa > 5e3)
    cup, mech = _gas_mech(mesh, s)
    _, K = mech.linearize(s.state.u)
    assert isinstance(K, GasTangent)
    c, g = K.rank_one
    dense = K.toarray() + c * np.outer(g, g)
    n = K.shape[0]
    rng = np.random.default_rng(3)
    d = rng.standard_normal(n)
    assert np.allclose(K @ d, dense @ d, rtol=1e-12, atol=1e-12 * np.abs(dense @ d).max())
    contact_z = 2 * cup.cup.plane.nodes[s.state.contact.active] + 1
    fixed = np.concatenate([2 * cup.cup.top, 2 * cup.cup.top + 1, contact_z])
    free = np.ones(n, bool)
    free[fixed] = False
    du_fixed = np.zeros(n)
    du_fixed[fixed] = 1e-6 * rng.standard_normal(fixed.size)
    rhs = rng.standard_normal(n)
    solver = RankOneSolver(make_solver(K.plain(), mech.kin.node_coordinates(), mesh))
    fac = solver.factor(K, free)

    def reference(free):
        x = np.where(free, 0.0, du_fixed)
        b = rhs - dense @ x
        x[free] = np.linalg.solve(dense[np.ix_(free, free)], b[free])
        return x

    x = fac.solve(rhs, du_fixed)
    assert np.linalg.norm(x - reference(free)) <= 1e-8 * np.linalg.norm(x)
    let_go = contact_z[:2]
    wider = free.copy()
    wider[let_go] = True
    x = fac.freeing(let_go).solve(rhs, du_fixed)
    assert np.linalg.norm(x - reference(wider)) <= 1e-8 * np.linalg.norm(x)


def test_rank_one_factor_of_an_indefinite_sparse_part(mesh, frictionless):
    """Where the sparse part K_s,ff has one negative eigenvalue and c is large enough, K_s + c g g^T
    is positive definite (1 + c g^T K_s^-1 g < 0): the solver's factor is exact there (a dense
    solve agrees) instead of failing into a shift; with c too small the whole is indefinite and
    the factor says so (NotPositiveDefinite)."""
    s = next(s for s in frictionless.states if s.stage == "pulled" and s.dp_Pa > 5e3)
    cup, mech = _gas_mech(mesh, s)
    _, K = mech.linearize(s.state.u)
    n = K.shape[0]
    fixed = np.concatenate([2 * cup.cup.top, 2 * cup.cup.top + 1,
                            2 * cup.cup.plane.nodes[s.state.contact.active] + 1])
    free = np.ones(n, bool)
    free[fixed] = False
    Ks = K.plain()
    D = sp.diags(Ks.diagonal(), format="csr")
    mu = np.sort(spla.eigsh(Ks[free][:, free].tocsc(), k=2, M=D[free][:, free].tocsc(), sigma=0.0,
                            return_eigenvectors=False))
    lam = 0.5 * (mu[0] + mu[1])                      # K_s - lam D: one negative eigenvalue
    shifted = (Ks - lam * D).tocsr()
    shifted.sort_indices()
    w, v = np.linalg.eigh((shifted[free][:, free]).toarray())
    assert w[0] < 0.0 < w[1]
    g = np.zeros(n)
    g[free] = v[:, 0] + 0.1 * v[:, 1]
    solver = RankOneSolver(make_solver(Ks, mech.kin.node_coordinates(), mesh))
    rhs = np.random.default_rng(4).standard_normal(n)
    for c, definite in ((4.0 * abs(w[0]), True), (0.25 * abs(w[0]), False)):
        T = GasTangent.of(shifted, shifted.data, c, g)
        if not definite:
            with pytest.raises(NotPositiveDefinite):
                solver.factor(T, free)
            continue
        x = solver.factor(T, free).solve(rhs)
        dense = (shifted + c * sp.csr_matrix(np.outer(g, g))).toarray()[np.ix_(free, free)]
        assert np.linalg.eigvalsh(dense)[0] > 0.0
        assert np.linalg.norm(x[free] - np.linalg.solve(dense, rhs[free])) <= 1e-8 * np.linalg.norm(x)
        assert np.all(x[~free] == 0.0)


def test_gas_potential_force_and_tangent_are_exact(mesh, frictionless):
    """Central differences on a deformed, sucked state: dPi/du is the force (with dp = p_a -
    N k_B T / V), and the derivative of the force is the tangent with its rank-one term. The
    nodes on the plane keep their height (V_cav is cut there: piecewise smooth, `fem.cavity`)."""
    s = frictionless.states[-1]
    _, mech = _gas_mech(mesh, s)
    u = s.state.u
    rng = np.random.default_rng(5)
    d = rng.standard_normal(u.size) * 1e-9
    on_plane = np.flatnonzero(mech.coordinates(u)[1] <= mech.cavity.tolerance_m)
    assert on_plane.size > 3
    d[2 * on_plane + 1] = 0.0
    E, r, K = mech.evaluate(u)
    fd_E = (mech.energy(u + d) - mech.energy(u - d)) / 2.0
    assert fd_E == pytest.approx(r @ d, rel=1e-6)
    fd_r = (mech.internal_force(u + d) - mech.internal_force(u - d)) / 2.0
    assert np.linalg.norm(fd_r - K @ d) <= 1e-5 * np.linalg.norm(K @ d)
    # along the path (the cavity grows as a whole) the rank-one term is most of the stiffness
    d = 1e-3 * (frictionless.states[-2].state.u - u)
    d[2 * on_plane + 1] = 0.0
    fd_r = (mech.internal_force(u + d) - mech.internal_force(u - d)) / 2.0
    assert np.linalg.norm(fd_r - K @ d) <= 1e-5 * np.linalg.norm(K @ d)
    assert np.linalg.norm(fd_r - K.plain() @ d) > 0.1 * np.linalg.norm(K @ d)
    V = mech.volume_m3(u)
    assert mech.dp_Pa(u) == pytest.approx(1e5 - s.N * K_B * 293.15 / V, rel=1e-12)


def test_frictionless_states_equal_the_dp_driven_states(mesh, frictionless):
    """Frictionless states are path independent: a state reached by pressing, sealing, pulling
    and letting gas in is an equilibrium of the dp-driven problem at its dp = p_a - N k_B T / V
    (the dp solver started there moves it by round-off), and equals the state of `suction_grid`
    (pressed to u, then dp ramped at the held plate). The two paths may leave a node of the
    outer contact zone, where the reaction is ~0, on the plane or 1e-8..1e-7 m above it (a
    marginal contact both admit): F1 and N_c agree to 3e-6 of the suction's resultant."""
    pulled = [s for s in frictionless.states if s.stage == "pulled"]
    leaked = [s for s in frictionless.states if s.stage == "leaked"]
    cup = CupSetup.of(mesh, NeoHookean(), "frictionless")
    cavity = CavitySurface.of(mesh)
    for s in (pulled[len(pulled) // 2], pulled[-1], leaked[len(leaked) // 2]):
        again = []
        follow_path(PressurizedMechanics(cup.mech, cavity, s.dp_Pa), cup.plate_at(s.u_m, moving=False),
                    1.0, plane=cup.plane, start=s.state, on_step=again.append,
                    options=SolverOptions(rtol=RTOL, initial_step=1.0, max_step=1.0))
        assert np.max(np.abs(again[-1].u - s.state.u)) <= 1e-10 * np.max(np.abs(s.state.u))
        g = suction_grid(mesh, NeoHookean(), u_m=[s.u_m], dp_Pa=[0.0, s.dp_Pa], rtol=RTOL)
        scale = s.dp_Pa * np.pi * s.seal_r_m**2          # the suction's resultant
        assert abs(g.F1_N[0, 1] - s.F1_N) <= 3e-6 * scale
        assert abs(g.contact_force_N[0, 1] - s.contact_force_N) <= 3e-6 * scale
        assert g.V_m3[0, 1] == pytest.approx(s.V_m3, rel=1e-6)
        assert g.seal_r_m[0, 1] == pytest.approx(s.seal_r_m, rel=1e-6)


def test_plate_contact_and_suction_balance(mesh, path):
    """Global equilibrium of every sealed state: the pull on the handle (the plate's reaction),
    the contact resultant (the integral of the contact pressure) and the suction dp pi r_cut^2
    over the wall's projection up to the end of the loaded chain balance to round-off."""
    cavity = CavitySurface.of(mesh)
    X = mesh.doflocs
    for s in path.states:
        x = X + np.stack([s.state.u[0::2], s.state.u[1::2]])
        r_cut = x[0, cavity.nodes[cavity.cut_index(x)]]
        contact = float(np.sum(s.profile.p_gauss_Pa * s.profile.w_m2))
        p_b = s.N * K_B * 293.15 / cavity.volume(x)          # the gas law on the geometric volume
        suction = (1e5 - p_b) * np.pi * r_cut**2
        assert abs(s.F1_N + contact - suction) <= 1e-7 * max(contact, abs(s.F1_N))


def test_sealed_cup_pulled_at_fixed_N_holds_harder(path):
    """Raising the plate at fixed N enlarges the cavity, so p_b = N k_B T / V falls and the
    handle's pull rises; letting gas in at the held plate does the opposite (frictionless: the
    cup relaxes; sticking: the seal held, the same signs)."""
    pulled = [s for s in path.states if s.stage == "pulled"]
    assert len(pulled) > 5
    assert len({s.N for s in pulled}) == 1
    assert np.all(np.diff([s.V_m3 for s in pulled]) > 0)
    assert np.all(np.diff([s.p_b_Pa for s in pulled]) < 0)
    assert np.all(np.diff([s.F1_N for s in pulled]) > 0)
    assert pulled[-1].F1_N > pulled[0].F1_N + 2.0          # N: a real pull, not round-off
    sealed = [s for s in path.states if s.stage == "pressed"][-1]
    assert sealed.p_b_Pa == pytest.approx(1e5, rel=1e-12) and pulled[0].N == sealed.N
    leaked = [s for s in path.states if s.stage == "leaked"]
    assert np.all(np.diff([s.N for s in leaked]) > 0)
    assert np.all(np.diff([s.p_b_Pa for s in leaked]) > 0)
    assert np.all(np.diff([s.F1_N for s in leaked]) < 0)
    assert np.allclose([s.u_m for s in leaked], 1.5e-3, rtol=1e-12)


def test_path_cost_and_dissipation(mesh, path):
    """Newton converges quadratically with the rank-one tangent (a few iterations per state),
    and the path's energy balance (stored energy, plate work, the work of N) closes:
    frictionless, to the trapezoid's defect, small against the cup's elastic energy; sticking
    slips dissipate, far more than that and >= 0."""
    stats = path.stats
    assert stats.newton_iterations <= 5 * stats.steps
    body = CupSetup.of(mesh, NeoHookean(), path.contact).mech
    elastic = body.energy([s for s in path.states if s.stage == "pressed"][-1].state.u)
    if path.contact.law == "frictionless":
        assert abs(stats.dissipated_J) <= 1e-4 * elastic
    else:
        assert stats.dissipated_J >= 1e-3 * elastic        # measured: 0.55 %


def test_bad_input_is_refused_before_work(mesh):
    with pytest.raises(ValueError, match="^N: "):
        TrappedGas(0.0)
    with pytest.raises(ValueError, match="^T_K: "):
        TrappedGas(1e20, T_K=-1.0)
    cup = CupWithGas.of(mesh, NeoHookean())
    with pytest.raises(ValueError, match="^wetting_m: "):
        GasMechanics(cup.cup.mech, CavitySurface.of(mesh, 1e-5), TrappedGas(1e20))
    with pytest.raises(ValueError, match="^N_end_ratio: "):
        cup_path(mesh, NeoHookean(), 3e-3, 1.5e-3, 0.9)
    with pytest.raises(ValueError, match="^u_pulled_m: "):
        cup_path(mesh, NeoHookean(), 3e-3, 3.5e-3, 1.2)
    assert not cup.costs


# --- the cup held by a given pull (fem/gas_branch.py) -------------------------------------------

F1_HELD = 25.0      # N: frictionless coarse cup A folds at u ~ -4.6 mm (no seal opening first)


@pytest.fixture(scope="module")
def held(mesh):
    cup = CupWithGas.of(mesh, NeoHookean(), rtol=RTOL)
    return cup, equilibrium_branch(cup, cup.press(4e-3)[-1], F1_HELD, du_m=0.25e-3)


def test_branch_holds_the_pull_and_balances(mesh, held):
    """Every state of the branch pulls F1 (to the root's tolerance) and balances plate, contact
    and suction; N rises as the plate rises, up to the fold, where it is largest."""
    cup, b = held
    assert b.reason == "fold" and b.detachment is b.states[-1]
    N = b.column("N")
    assert np.all(np.diff(b.column("u_m")[:-1]) < 0) and np.all(np.diff(N) > 0)
    assert b.N_max == N.max() and b.N_max > 1.5 * N[0]
    for s in b.states:
        scale = cup.p_a_Pa * np.pi * s.seal_r_m**2
        assert abs(s.F1_N - F1_HELD) <= RTOL * scale
        contact = float(np.sum(s.profile.p_gauss_Pa * s.profile.w_m2))
        assert abs(s.F1_N + contact - s.dp_Pa * np.pi * s.cut_r_m**2) <= 1e-7 * scale


def test_branch_frictionless_states_equal_the_suction_grid(mesh, held):
    """At mu = 0 a branch state (reached by pressing, sealing, pulling and letting gas in along
    the branch) is the dp-driven state of `suction_grid` at its (u, dp): the grid's pull there
    is F1 (the branch's root), with the same volume and seal."""
    _, b = held
    for s in [s for s in b.states if s.u_m > 0][1::3][:2]:
        g = suction_grid(mesh, NeoHookean(), u_m=[s.u_m], dp_Pa=[0.0, s.dp_Pa], rtol=RTOL)
        scale = s.dp_Pa * np.pi * s.seal_r_m**2
        assert abs(g.F1_N[0, 1] - F1_HELD) <= 3e-6 * scale
        assert g.V_m3[0, 1] == pytest.approx(s.V_m3, rel=1e-6)
        assert g.seal_r_m[0, 1] == pytest.approx(s.seal_r_m, rel=1e-6)


def test_pull_sensitivities_match_neighbouring_states(mesh, held):
    """dF1/dN and dF1/du of `pull_sensitivities` against central differences of converged states
    at N (1 +- 1e-5) and u +- 1e-4 mm from a branch state; and at the reported detachment
    dN/du = -(dF1/du)/(dF1/dN) vanishes (to 1e-3 of its largest value on the branch)."""
    cup, b = held
    s = b.states[len(b.states) // 2]
    dF1_dN, dF1_du = pull_sensitivities(cup, s)
    options = replace(cup.options, initial_step=1.0, max_step=1.0)

    def pull(u_m, N):
        mech = GasMechanics(cup.cup.mech, cup.cavity, TrappedGas(N))
        last = []
        follow_path(mech, cup.cup.plate_at(u_m, moving=False), 1.0, plane=cup.cup.plane,
                    start=s.state, on_step=last.append, options=options)
        return float(np.sum(last[-1].r_int[2 * cup.cup.top + 1]))
    dN, du = 1e-5 * s.N, 1e-7
    assert (pull(s.u_m, s.N + dN) - pull(s.u_m, s.N - dN)) / (2 * dN) == pytest.approx(dF1_dN, rel=1e-4)
    assert (pull(s.u_m + du, s.N) - pull(s.u_m - du, s.N)) / (2 * du) == pytest.approx(dF1_du, rel=1e-4)
    assert abs(b.dN_du[-1]) <= 1e-3 * np.max(np.abs(b.dN_du))
    assert np.all(b.dN_du[:-1] < 0)


def test_friction_holds_more_gas_than_frictionless(mesh, held):
    """The largest N held at F1 (the fold of the branch): with Coulomb friction (mu = 0.5) the
    contact zone cannot slide freely inwards under the suction as the plate rises, so the wall
    stays stiffer and the cup reaches a larger cavity before the fold: more gas is held, the
    fold comes at a higher plate, the gas at a higher pressure (coarse: N_max 2.31 against 2.17 N0
    of the frictionless cup, the fold at u = -4.76 against -4.63 mm). Sticking is not compared:
    its slips (a released node lands where the iteration puts it) make F1(N) at the held plate
    discontinuous, and the branch stops at their onset."""
    _, smooth = held
    cup = CupWithGas.of(mesh, NeoHookean(), "coulomb", 0.5, rtol=RTOL)
    rough = equilibrium_branch(cup, cup.press(4e-3)[-1], F1_HELD, du_m=0.25e-3)
    assert rough.reason == "fold" and abs(rough.dN_du[-1]) <= 1e-3 * np.max(np.abs(rough.dN_du))
    assert rough.N_max > 1.03 * smooth.N_max
    assert rough.detachment.u_m < smooth.detachment.u_m
    assert rough.detachment.p_b_Pa > smooth.detachment.p_b_Pa
    assert rough.detachment.V_m3 > smooth.detachment.V_m3


@pytest.mark.parametrize("target", [{"force_N": 2.0}, {"r_start_m": 13e-3}])
def test_press_to_a_force_or_a_start_radius(mesh, target):
    """Pressing with the cavity open stops where the pressing force F0 = -F1 reaches force_N, or
    the inner contact radius falls to r_start_m: the last state meets the target, the one before
    (1e-7 m of plate short of it) does not; the cavity is open (p_b = p_a). The force is met to
    1e-3; r_c can jump by a node spacing there (the mesh's resolution of r_start)."""
    cup = CupWithGas.of(mesh, NeoHookean())
    states = cup.press_to(**target)
    before, last = states[-2], states[-1]
    assert last.u_m - before.u_m <= 1e-7 and all(s.stage == "pressed" for s in states)
    assert last.p_b_Pa == pytest.approx(cup.p_a_Pa, rel=1e-12)
    if "force_N" in target:
        assert -before.F1_N < 2.0 <= -last.F1_N <= 2.0 * (1 + 1e-3)
    else:
        chain = mesh.doflocs[:, cup.cavity.nodes]
        spacing = np.max(np.hypot(*np.diff(chain, axis=1)))     # r_c moves node to node
        assert before.r_c_m > 13e-3 >= last.r_c_m >= before.r_c_m - spacing


def test_branch_bad_input_is_refused(mesh):
    cup = CupWithGas.of(mesh, NeoHookean())
    sealed = cup.press(1e-3)[-1]
    with pytest.raises(ValueError, match="^F1_N: "):
        equilibrium_branch(cup, sealed, float("nan"))
    with pytest.raises(ValueError, match="^du_m: "):
        equilibrium_branch(cup, sealed, 5.0, du_m=0.0)
    with pytest.raises(ValueError, match="^press_to: "):
        cup.press_to(force_N=1.0, r_start_m=12e-3)
    with pytest.raises(ValueError, match="^force_N: "):
        cup.press_to(force_N=-1.0)
