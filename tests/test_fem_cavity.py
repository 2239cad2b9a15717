"""The cavity pressure as a conservative load (fem/cavity.py) and the cup on a (u, dp) grid
(fem/suction.py): exact derivatives, a hydrostatic closed form, global equilibrium, the
envelope theorem dPi*/d(dp) = V_cav, and the dp = 0 column against the plain cup job."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import brentq
from skfem import MeshQuad, MeshQuad2

from fem.cavity import CavitySurface, PressurizedMechanics
from fem.cup import compress_cup
from fem.forms import Mechanics
from fem.geometry import cup_geometry
from fem.kinematics import Kinematics
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from fem.solver import follow_path
from fem.suction import suction_grid


def _flat(x):
    v = np.empty(x.size)
    v[0::2], v[1::2] = x
    return v


def _xy(v):
    return np.stack([v[0::2], v[1::2]])


@pytest.mark.parametrize("wetting_m, seal, halved", [(0.0, -1, False), (2e-5, -1, False),
                                                      (0.0, -6, True), (2e-5, -6, True)])
def test_volume_gradient_and_hessian_match_finite_differences(wetting_m, seal, halved):
    """On a perturbed chain whose first node on the plane is the rim (a vertex) or a mid-side node
    (the cut halves that edge)."""
    mesh = cup_mesh(cup_geometry("A"), "coarse")
    cav = CavitySurface.of(mesh, wetting_m)
    rng = np.random.default_rng(1)
    x = mesh.doflocs + 1e-6 * rng.standard_normal(mesh.doflocs.shape)
    x[1, cav.nodes[-12:-1]] = 3e-5 * rng.random(11)      # the wall near the rim just above the plane
    x[1, cav.nodes[seal]] = 0.0
    if halved:
        x[1, cav.nodes[-1]] = 3e-5                        # the rim lifted: the seal alone touches
    assert (cav.cut_index(x) % 2 == 1) == halved
    n = x.size
    V, (dofs, g), h, pairs = cav.derivatives(x)
    G = np.bincount(dofs, g, minlength=n)
    H = sp.coo_matrix((h, (pairs[0], pairs[1])), shape=(n, n)).toarray()
    d, eps = rng.standard_normal(n), 1e-9
    if halved:                               # an inner node on the plane stays there (V is cut there)
        d[2 * cav.nodes[seal] + 1] = 0.0
    xv = _flat(x)
    fd = (cav.loaded_volume(_xy(xv + eps * d)) - cav.loaded_volume(_xy(xv - eps * d))) / (2 * eps)
    assert fd == pytest.approx(G @ d, rel=1e-6)

    def grad(v):
        (dd, gg) = cav.derivatives(_xy(v))[1]
        return np.bincount(dd, gg, minlength=n)
    fd_H = (grad(xv + eps * d) - grad(xv - eps * d)) / (2 * eps)
    assert np.linalg.norm(fd_H - H @ d) <= 1e-4 * np.linalg.norm(H @ d)
    assert np.allclose(H, H.T)
    if wetting_m == 0.0:
        assert V == pytest.approx(cav.volume(x), rel=1e-14)


def test_volume_is_continuous_when_an_inner_touchdown_lifts():
    """A wall touching the plane mid-way and at the rim, with a lifted pocket between: lifting the
    inner touchdown by eps changes V_cav by O(eps) (the pocket is part of the gas region, its
    pressure the cavity's), and the gradient predicts the change; the seal r_k moves out to the
    rim. Cut at the first contact zone instead, V jumped by the pocket's volume."""
    mesh = cup_mesh(cup_geometry("A"), "coarse")
    cav = CavitySurface.of(mesh)
    x = mesh.doflocs.copy()
    chain = cav.nodes
    k = chain.size - 15                                   # the inner touchdown
    x[1, chain[k:]] = 2e-4 * np.sin(np.pi * np.arange(chain.size - k) / (chain.size - 1 - k))
    x[1, chain[k]] = x[1, chain[-1]] = 0.0
    assert cav.seal_index(x) == k and cav.cut_index(x) == chain.size - 1
    V, (dofs, g), _, _ = cav.derivatives(x)
    pocket = -np.pi * np.trapezoid(x[0, chain[k:]] ** 2, x[1, chain[k:]])
    for eps in (1e-9, 1e-8):
        lifted = x.copy()
        lifted[1, chain[k]] = eps
        assert cav.seal_index(lifted) == chain.size - 1
        dV = cav.volume(lifted) - V
        assert abs(dV) < 1e-3 * abs(pocket)                 # no jump by the pocket
        assert dV == pytest.approx(eps * np.bincount(dofs, g, minlength=x.size)[2 * chain[k] + 1],
                                   rel=1e-3)


def test_undeformed_cone_volume_is_the_frustum():
    mesh = cup_mesh(cup_geometry("A"), "coarse")
    cav = CavitySurface.of(mesh)
    (r0, z0), (r1, z1) = mesh.doflocs[:, cav.nodes[0]], mesh.doflocs[:, cav.nodes[-1]]
    frustum = np.pi / 3 * (z0 - z1) * (r0**2 + r0 * r1 + r1**2)
    assert cav.volume(mesh.doflocs) == pytest.approx(frustum, rel=1e-12)


def test_hydrostatic_cylinder_compresses_uniformly():
    """A solid cylinder on a frictionless floor with the 'cavity' pressure on its top and side:
    the state is homogeneous, F = lambda I with Cauchy stress -dp I, which the constitutive law
    alone fixes (solved here by brentq on the law's own stress); the nodes, the volume and the
    floor's reaction follow in closed form."""
    b, H = 0.01, 0.008
    base = MeshQuad.init_tensor(np.linspace(0.0, b, 5), np.linspace(0.0, H, 4))
    mesh = MeshQuad2.from_mesh(base).with_boundaries(
        {"cavity": lambda x: (x[1] > H - 1e-9) | (x[0] > b - 1e-9)})
    material = NeoHookean(E_Pa=4e6, nu=0.3)
    dp = 0.25 * material.E_Pa
    kin = Kinematics.of(mesh)
    X = kin.node_coordinates()
    axis, floor = np.flatnonzero(X[0] < 1e-12), np.flatnonzero(X[1] < 1e-12)
    fixed = np.concatenate([2 * axis, 2 * floor + 1])
    mech = PressurizedMechanics(Mechanics(kin, material), CavitySurface.of(mesh), dp,
                                schedule=lambda t: t * dp)
    states = []
    follow_path(mech, lambda t: (fixed, np.zeros(fixed.size)), 1.0, on_step=states.append)
    u = states[-1].u

    def cauchy(lam):
        P = material.stress(np.array([lam, 0.0, 0.0, lam, lam])[:, None, None])
        return float(P[0, 0, 0]) / lam**2
    lam = brentq(lambda s: cauchy(s) + dp, 0.5, 1.0)
    assert lam < 0.95                                      # a finite strain, not a linear check
    assert np.max(np.abs(u - _flat((lam - 1.0) * X))) < 1e-9 * b
    assert mech.cavity.volume(X + _xy(u)) == pytest.approx(lam**3 * np.pi * b**2 * H, rel=1e-9)
    floor_force = np.sum(states[-1].r_int[2 * floor + 1])
    assert floor_force == pytest.approx(dp * np.pi * (lam * b) ** 2, rel=1e-8)   # the floor pushes up


@pytest.fixture(scope="module")
def grid():
    mesh = cup_mesh(cup_geometry("A"), "coarse")
    return mesh, suction_grid(mesh, NeoHookean(), u_m=[1e-3, 3e-3],
                              dp_Pa=[0.0, 2.5e3, 5e3, 7.5e3, 1e4, 2e4, 4e4])


def test_suction_grid_balances_handle_contact_and_suction(grid):
    """F1 + N = dp pi r_k^2: the plate's pull, the contact force from the lumped pressures and
    the projected area of the cavity up to the seal (the pressure's resultant)."""
    _, g = grid
    suction = g.dp_Pa * np.pi * g.seal_r_m**2
    assert np.all(np.abs(g.F1_N + g.contact_force_N - suction) <= 1e-6 * np.maximum(suction, 1.0))
    assert np.all(np.diff(g.F1_N, axis=1) > 0)            # more suction, more pull at fixed u
    assert np.all(np.diff(g.V_m3, axis=1) < 0)            # ... and a smaller cavity
    assert np.all(g.contact_force_N > 0)


def test_suction_grid_potential_derivative_is_the_cavity_volume(grid):
    """Envelope theorem at fixed u: dPi*/d(dp) = V_cav. The trapezoid of V over dp matches the
    change of Pi* to its second-order error (halving the spacing divides the error by ~4)."""
    _, g = grid
    for i in range(g.u_m.size):
        P, V, dp = g.potential_J[i, :5], g.V_m3[i, :5], g.dp_Pa[:5]
        exact = P[-1] - P[0]
        fine = np.sum(0.5 * (V[1:] + V[:-1]) * np.diff(dp))
        coarse = np.sum(0.5 * (V[2::2] + V[:-2:2]) * np.diff(dp[::2]))
        assert abs(fine - exact) <= 2e-3 * abs(exact)
        assert 2.5 < abs(coarse - exact) / abs(fine - exact) < 6.0


def test_suction_grid_without_suction_is_the_cup_curve(grid):
    mesh, g = grid
    resp = compress_cup(mesh, NeoHookean(), u_max_m=3e-3)
    F0 = np.interp(g.u_m, resp.u_m, resp.F0_N)
    hit = np.isin(np.round(g.u_m, 12), np.round(resp.u_m, 12))
    assert np.allclose(-g.F1_N[hit, 0], F0[hit], rtol=1e-6)
    assert np.allclose(-g.F1_N[:, 0], F0, rtol=2e-2)       # between steps: the curve's interpolation


def test_suction_grid_refuses_bad_axes():
    mesh = cup_mesh(cup_geometry("A"), "coarse")
    for u_m in ([1e-3, 0.0], [-1.0, 1e-3], [1e-3, 1.0]):        # not increasing; outside [h1 - 2 L, h1]
        with pytest.raises(ValueError, match="u_m"):
            suction_grid(mesh, NeoHookean(), u_m=u_m, dp_Pa=[0.0, 1e4])
    with pytest.raises(ValueError, match="dp_Pa"):
        suction_grid(mesh, NeoHookean(), u_m=[1e-3], dp_Pa=[1e3, 1e4])
