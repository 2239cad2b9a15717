"""The linear-algebra kernels of Coulomb's Newton step and its stop on a creeping residual:
the condensation's scatter as a sparse product (bit for bit the bincount it replaces), the
contact rows of the gas tangent kept as sparse rows plus the rank-one term (against the whole
tangent's product with the identity), `fem.newton.creeping` on the residual histories of a
converging and a creeping iteration, and the columns solved only where they are read (`solve_at`
of each factor against its whole solve; the condensed problem with it against whole solves and
against the linearized conditions on the whole tangent)."""

import numpy as np
import pytest
import scipy.sparse as sp

from fem.condensation import _scatter_matrix
from fem.friction_condensed import _rows
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
    """`fem.friction_condensed._rows` of a gas tangent K_s + c g g^T: its dense rows and its products with
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


# --- the condensed columns solved only where they are read (`solve_at`) -------------------------

@pytest.fixture(scope="module")
def frictional_iterate():
    """The arguments of a Coulomb Newton iteration's condensed problem (coarse cup A, mu 0.5,
    pressed to 0.35 h1, solved with whole solves, so that it does not depend on `solve_at`): the
    first with more than four held nodes, some of them sliding."""
    import fem.friction_condensed as condensed
    from fem.cup import compress_cup
    from fem.geometry import cup_geometry
    from fem.material import NeoHookean
    from fem.mesh import cup_mesh

    kept = {}
    init = condensed.CondensedProblem.__init__

    def record(self, plane, old, u, res0, K, fac, du0, held, tol):
        if "args" not in kept and len(held) > 4 and np.any(old.slip[held] != 0):
            kept["args"] = (plane, old, u.copy(), res0.copy(), K, fac, du0.copy(), held.copy(), tol)
        init(self, plane, old, u, res0, K, _WholeSolves(fac), du0, held, tol)

    geometry = cup_geometry("A")
    condensed.CondensedProblem.__init__ = record
    try:
        compress_cup(cup_mesh(geometry, "coarse"), NeoHookean(), contact="coulomb", friction=0.5,
                     u_max_m=0.35 * geometry.h1_m)
    finally:
        condensed.CondensedProblem.__init__ = init
    return kept["args"]


class _WholeSolves:
    """A factor with whole solves only (no `solve_at`): the plain kernel."""

    def __init__(self, fac):
        self.fac, self.free = fac, fac.free

    def solve(self, rhs, du_fixed=None):
        return self.fac.solve(rhs, du_fixed)


def _rim_rhs(fac, K, plane, rng, m=5):
    """A right-hand side on the rows of 12 contact nodes and their tangent rows' dofs (interior
    nodes and constrained dofs among them), and the dofs to read: those and a few more."""
    nodes = plane.nodes[-12:]
    rows = np.union1d(np.concatenate([2 * nodes, 2 * nodes + 1]), K[2 * nodes + 1].indices)
    values = rng.normal(size=(len(rows), m))
    dofs = np.union1d(rows[::2], K[rows[:6]].indices)
    b = np.zeros((K.shape[0], m))
    b[rows] = values
    return rows, values, dofs, b


def test_solve_at_equals_the_whole_solve_at_the_asked_dofs(frictional_iterate):
    """The condensed (interior nodes) and the plain banded factor, and the gas tangent's
    rank-one factor over each and over a sparse LU (no `solve_at` of its own): x at the asked
    dofs equals the whole solve's there (round-off of another summation order), constrained
    dofs 0."""
    from fem.condensation import make_solver
    from fem.linsolve import BandedCholesky
    from fem.trapped_gas import RankOneFactor, RankOneSolver, SymmetricLU

    plane, old, u, res0, K, fac, du0, held, tol = frictional_iterate
    rng = np.random.default_rng(11)
    free = fac.free
    kin = plane.kin
    condensed = make_solver(K, kin.node_coordinates(), kin.mesh)
    plain = BandedCholesky(K, kin.node_coordinates(), kin.mesh)
    g = np.zeros(K.shape[0])
    g[rng.choice(np.flatnonzero(free), 40, replace=False)] = rng.normal(size=40)
    gas = GasTangent.of(K, K.data, 3.0 * K.diagonal().max(), g / np.linalg.norm(g))
    factors = [condensed.factor(K, free), plain.factor(K, free),
               RankOneSolver(condensed).factor(gas, free), RankOneSolver(plain).factor(gas, free),
               RankOneFactor(SymmetricLU(K, free), *gas.rank_one)]     # a base with whole solves only
    rows, values, dofs, b = _rim_rhs(fac, K, plane, rng)
    assert np.any(~free[rows]) and np.any(~free[dofs])
    for f in factors:
        whole = f.solve(b)[dofs]
        at = f.solve_at(rows, values, dofs)
        assert np.allclose(at, whole, rtol=0, atol=1e-12 * np.abs(whole).max())
        assert np.all(at[~free[dofs]] == 0.0)
    fac_c = factors[0]
    assert fac_c._owner._element[dofs].max() >= 0      # interior nodes asked for


def _assert_linearized_conditions(sub, K, res0):
    """The step du of a converged condensed problem against the whole tangent K (its rank-one
    term included): equilibrium r = res0 + K du = 0 at the free dofs off the contact rows; at a
    pressed node g + du_z = 0, else r_z = 0; at a held pressed node du_r = -d0 (stuck) or
    r_r = -mu slip r_z (sliding), else r_r = 0."""
    du = sub.du()
    r = res0 + K @ du
    rows, nh, nn = sub.rows, len(sub.held), len(sub.nodes)
    off = sub.fac.free.copy()
    off[rows] = False
    scale_f, scale_u = np.abs(res0).max(), np.abs(du).max()
    assert np.abs(r[off]).max() <= 1e-8 * scale_f
    z = np.concatenate([rows[:nh], rows[2 * nh:]])
    g = sub.g_all[sub.nodes]
    assert np.abs((g + du[z])[sub.An]).max(initial=0) <= 1e-9 * scale_u
    assert np.abs(r[z][~sub.An]).max(initial=0) <= 1e-8 * scale_f
    rr, rz, An = r[rows[nh:2 * nh]], r[rows[:nh]], sub.An[:nh]
    stuck, slide = An & (sub.slip == 0), An & (sub.slip != 0)
    assert np.abs((sub.d0 + du[rows[nh:2 * nh]])[stuck]).max(initial=0) <= 1e-9 * scale_u
    assert np.abs((rr + sub.mu * sub.slip * rz)[slide]).max(initial=0) <= 1e-8 * scale_f
    assert np.abs(rr[~An]).max(initial=0) <= 1e-8 * scale_f
    assert nn >= nh and slide.any()


def test_condensed_problem_with_solve_at_equals_the_plain_one(frictional_iterate):
    """The linearized frictional contact problem of a real iteration, solved with `solve_at`
    and with whole solves: the same sets, multipliers and step (to round-off), and the step meets
    the linearized conditions on the whole tangent; also with a rank-one gas term whose g lies on
    the contact rows and elsewhere, and after free nodes join (a larger support)."""
    from fem.condensation import make_solver
    from fem.friction_condensed import CondensedProblem
    from fem.trapped_gas import RankOneSolver

    plane, old, u, res0, K, fac, du0, held, tol = frictional_iterate
    rng = np.random.default_rng(5)
    cases = [(K, fac, du0)]
    g = np.zeros(K.shape[0])         # on the contact rows too, as the cavity chain is
    on = np.union1d(rng.choice(np.flatnonzero(fac.free), 60, replace=False),
                    np.concatenate([2 * plane.nodes[held], 2 * plane.nodes[held] + 1]))
    g[on] = rng.normal(size=len(on))
    gas = GasTangent.of(K, K.data, 0.3 * K.diagonal().max(), g / np.linalg.norm(g))
    gfac = RankOneSolver(make_solver(K, plane.kin.node_coordinates(), plane.kin.mesh)).factor(gas, fac.free)
    cases.append((gas, gfac, gfac.solve(-res0)))
    for K_, f, d0 in cases:
        a = CondensedProblem(plane, old, u, res0, K_, f, d0, held, tol)
        b = CondensedProblem(plane, old, u, res0, K_, _WholeSolves(f), d0, held, tol)
        for sub in (a, b):
            sub.ssn()
        assert a.converged and b.converged
        assert np.array_equal(a.An, b.An) and np.array_equal(a.slip, b.slip)
        assert np.any(a.slip != 0) and len(a.cols) > 0
        assert np.allclose(a.y, b.y, rtol=1e-9, atol=1e-12 * np.abs(b.y).max())
        assert np.allclose(a.du(), b.du(), rtol=0, atol=1e-9 * np.abs(b.du()).max())
        _assert_linearized_conditions(a, K_, res0)
        new = np.setdiff1d(np.arange(len(plane.nodes)), held)[-3:]
        for sub in (a, b):                          # nodes pressed anew: a larger support
            sub.add(new)
            sub.ssn()
        assert np.allclose(a.F, b.F, rtol=0, atol=1e-9 * np.abs(b.F).max())
        assert np.allclose(a.du(), b.du(), rtol=0, atol=1e-9 * np.abs(b.du()).max())
        _assert_linearized_conditions(a, K_, res0)
