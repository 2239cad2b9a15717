"""The gas trapped in the cavity as part of the FEM state: N molecules at fixed T (eqs 8-9).

Sealed, the cavity holds N molecules of an isothermal ideal gas, p_b V = N k_B T, with the
ambient pressure p_a outside. With V = V_cav(u) the cavity's geometric volume (`fem.cavity`),
the gas and the atmosphere add to the body's stored energy W(u) the potential

    Pi_gas(V) = p_a V - N k_B T ln V,     dPi_gas/dV = p_a - p_b = dp,     d2Pi_gas/dV2 = N k_B T / V^2,

so the equilibrium at fixed N minimizes W(u) + Pi_gas(V_cav(u)) under the plate and the contact
conditions, and its tangent is

    K + dp Hess(V) + (N k_B T / V^2) grad V grad V^T.

The first two terms are `fem.cavity.PressurizedMechanics`'s at dp = p_a - N k_B T / V (in the
body's own sparse pattern); the third couples every dof of the cavity surface with every other.
It is kept as a rank-one term beside the sparse matrix (`GasTangent`), not added to it: the
band of the solver's ordering runs along the wall and a dense block over the whole cavity chain
would make it the full matrix. The Newton step solves with it exactly by the Sherman-Morrison
formula on the solver's factor of the sparse part (`RankOneFactor`: one more back-substitution per
factor), which keeps the minimization form the solver's line search and contact QP rely on;
a bordered system with V (or p_b) as an extra unknown is the same elimination written as a
saddle point, which the energy line search could not use. The gas term is what keeps the path
stiff at fixed N: against the plate, N k_B T / V^2 (dV/du)^2 ~ p_b (pi r_k^2)^2 / V is ~4e4 N/m
for cup A pulled at 1.5 mm, tens of times the pressed cup's own ~7e2 N/m, and it holds the wall
where at fixed dp it would snap.

`fem.solver.follow_path` asks the mechanics for its linear solver (`GasMechanics.make_solver`:
the body's sparse factor wrapped in `RankOneSolver`). The load parameter t may move N (`GasMechanics.schedule`,
through `at(t)`, as the cavity's dp ramp does) and the plate (the path's `dirichlet`); the
contact state, with its sticking anchors and Coulomb slips, is carried from state to state by
`start`.

Only the geometric volume takes part (no wetted fraction: the gas law needs the volume the gas
fills, and the load must be its derivative). For Coulomb friction the condensed contact problem
(`fem.friction`) reads rows of the sparse part only, so its Newton step misses the rank-one term
on the contact rows (an inexact tangent there; the energy and the residual stay exact);
`tangent_rows` (`GasTangent.rows`) gives those rows with the term, K_s[rows] + c g[rows] g^T.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .cavity import CavitySurface, PressurizedMechanics
from .chain_cut import ChainCut
from .condensation import make_solver
from .contact import RigidPlane
from .forms import Mechanics
from .linsolve import NotPositiveDefinite, solve_at
from .solver import SolverOptions, SolverStats, StepResult, follow_path

__all__ = ["K_B", "TrappedGas", "GasMechanics", "GasTangent", "RankOneSolver", "RankOneFactor",
           "SymmetricLU", "follow_gas_path", "tangent_rows"]

K_B = 1.380649e-23          # J/K (exact, SI 2019)


@dataclass(frozen=True)
class TrappedGas:
    """N molecules of an ideal gas at T_K [K] in the cavity, the ambient p_a_Pa [Pa] outside."""

    N: float
    T_K: float = 293.15
    p_a_Pa: float = 1e5

    def __post_init__(self) -> None:
        for name in ("N", "T_K", "p_a_Pa"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name}: must be a number > 0, got {value!r}")

    @classmethod
    def sealed_at(cls, V_m3: float, T_K: float = 293.15, p_a_Pa: float = 1e5) -> "TrappedGas":
        """The gas of a cavity of volume V_m3 sealed at the ambient pressure: N = p_a V / k_B T."""
        return cls(p_a_Pa * V_m3 / (K_B * T_K), T_K, p_a_Pa)

    @property
    def NkT_J(self) -> float:
        """N k_B T [J] = p_b V."""
        return self.N * K_B * self.T_K

    def pressure_Pa(self, V_m3: float) -> float:
        """p_b = N k_B T / V [Pa]."""
        return self.NkT_J / V_m3

    def potential_J(self, V_m3: float) -> float:
        """Pi_gas = p_a V - N k_B T ln V [J] (module docstring; V in m^3)."""
        if not V_m3 > 0.0:
            raise FloatingPointError(f"the cavity volume is {V_m3:.3g} m^3: the wall crossed the plate or the plane")
        return self.p_a_Pa * V_m3 - self.NkT_J * math.log(V_m3)


class GasTangent(sp.csr_matrix):
    """The tangent K_s + c g g^T: the sparse part K_s (this matrix's entries, in the body's
    pattern) and the rank-one term `rank_one` = (c, g); products with arrays include the term,
    slices and the sparse data do not (`plain`)."""

    rank_one: tuple[float, np.ndarray] | None = None
    chain_cut: ChainCut | None = None     # the gas load's jump where the contact's outer end moves

    @classmethod
    def of(cls, K: sp.csr_matrix, data: np.ndarray, c: float, g: np.ndarray) -> "GasTangent":
        T = cls((data, K.indices, K.indptr), shape=K.shape)
        T.rank_one = (float(c), g)
        return T

    def plain(self) -> sp.csr_matrix:
        """The sparse part K_s as a plain CSR matrix (the pattern the solver factors)."""
        return sp.csr_matrix((self.data, self.indices, self.indptr), shape=self.shape)

    def rows(self, dofs: np.ndarray) -> sp.csr_matrix:
        """The rows `dofs` of the whole tangent, K_s[dofs] + c g[dofs] g^T, as a sparse matrix
        (g is nonzero on the cavity chain's dofs only): what a condensation onto a few rows
        (`fem.friction`'s contact rows) needs; plain slicing gives the sparse part only."""
        return tangent_rows(self, dofs)

    def __matmul__(self, other):
        out = super().__matmul__(other)
        if self.rank_one is None or not isinstance(other, np.ndarray):
            return out
        c, g = self.rank_one
        return out + c * np.multiply.outer(g, g @ other)

    def dot(self, other):
        return self @ other


def tangent_rows(K: sp.csr_matrix, dofs: np.ndarray) -> sp.csr_matrix:
    """Rows `dofs` of a tangent with its rank-one term if it has one (`GasTangent`), else K[dofs]."""
    rank_one = getattr(K, "rank_one", None)
    Ks = _sparse_part(K)[dofs]
    if rank_one is None:
        return Ks
    c, g = rank_one
    support = np.flatnonzero(g)
    block = c * np.outer(g[dofs], g[support])                  # [len(dofs), len(support)]
    rows = np.repeat(np.arange(block.shape[0]), len(support))
    return (Ks + sp.csr_matrix((block.ravel(), (rows, np.tile(support, block.shape[0]))),
                               shape=Ks.shape)).tocsr()


def _sparse_part(K):
    return K.plain() if isinstance(K, GasTangent) else K


class RankOneFactor:
    """A factor of (K_s + c g g^T)_ff from a factor of (K_s)_ff by the Sherman-Morrison formula;
    the interface of `fem.linsolve.Factor` (solve, freeing, free)."""

    def __init__(self, base, c: float, g: np.ndarray):
        self._base, self._c, self._g = base, c, g
        self.free = base.free
        self._gf = np.where(self.free, g, 0.0)
        self._y = base.solve(self._gf)                        # (K_s)_ff^-1 g_f, zero off f
        self._den = 1.0 + c * (self._gf @ self._y)

    def solve(self, rhs: np.ndarray, du_fixed: np.ndarray | None = None) -> np.ndarray:
        """x with (K_s + c g g^T)_ff x_f = rhs_f - (K_s + c g g^T)_fc du_fixed_c, x_c = du_fixed_c."""
        if du_fixed is not None:
            coupling = self._g[~self.free] @ du_fixed[~self.free]
            rhs = rhs - (self._c * coupling) * (self._g if rhs.ndim == 1 else self._g[:, None])
        x = self._base.solve(rhs, du_fixed)
        scale = self._c * (self._gf @ x) / self._den
        return x - np.multiply.outer(self._y, scale)

    @property
    def solved_g(self) -> np.ndarray:
        """(K_s + c g g^T)_ff^-1 g_f = y / (1 + c g_f.y), y = (K_s)_ff^-1 g_f, without a solve."""
        return self._y / self._den

    def solve_at(self, rows: np.ndarray, values: np.ndarray, dofs: np.ndarray) -> np.ndarray:
        """`fem.linsolve.Factor.solve_at` (x at `dofs` for a right-hand side on `rows`) where the
        base factor has it, else from its whole solve: the term's weight g_f.x is y.b_f."""
        x = solve_at(self._base, rows, values, dofs, len(self._y))
        scale = self._c * (self._y[rows] @ values) / self._den
        return x - np.multiply.outer(self._y[dofs], scale)

    def freeing(self, dofs: np.ndarray) -> "RankOneFactor":
        """As `fem.linsolve.Factor.freeing`, with the rank-one term on the larger block."""
        return _definite(RankOneFactor(self._base.freeing(dofs), self._c, self._g))

    @property
    def definite(self) -> bool:
        """Whether (K_s + c g g^T)_ff is positive definite: K_s,ff is (c >= 0), or it has one
        negative eigenvalue and 1 + c g^T K_s^-1 g < 0 (the rank-one update's determinant lemma)."""
        negative = getattr(self._base, "negative", 0)
        return negative == 0 or (negative == 1 and self._den < 0.0)


def _definite(fac: RankOneFactor) -> RankOneFactor:
    if not fac.definite:
        raise NotPositiveDefinite("the gas tangent K_s + c g g^T is not positive definite")
    return fac


class SymmetricLU:
    """An indefinite K_ff (+ shift diag|K_ff|) factored by sparse LU with diagonal pivots only
    (SuperLU in symmetric mode): P K_ff P^T = L D L^T, so `negative`, the count of negative
    pivots, is K_ff's count of negative eigenvalues (Sylvester's law of inertia). The interface
    of `fem.linsolve.Factor`; raises NotPositiveDefinite where a diagonal pivot is refused."""

    def __init__(self, K: sp.csr_matrix, free: np.ndarray, shift: float = 0.0):
        self.K, self.free, self.shift = K, free, shift
        A = K[free][:, free].tocsc()
        if shift:
            A = A + sp.diags(shift * np.abs(A.diagonal()), format="csc")
        try:
            lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options=dict(SymmetricMode=True))
        except RuntimeError as err:             # an exactly singular pivot
            raise NotPositiveDefinite(f"symmetric LU: {err}") from None
        if not np.array_equal(lu.perm_r, lu.perm_c):
            raise NotPositiveDefinite("symmetric LU: an off-diagonal pivot was taken")
        self._lu = lu
        self.negative = int(np.count_nonzero(lu.U.diagonal() < 0.0))

    def solve(self, rhs: np.ndarray, du_fixed: np.ndarray | None = None) -> np.ndarray:
        """x with K_ff x_f = rhs_f - K_fc du_fixed_c, x_c = du_fixed_c (0 if None); rhs [n] or [n, m]."""
        fixed = ~self.free
        x = np.zeros_like(rhs, dtype=float)
        b = rhs
        if du_fixed is not None:
            d = np.where(fixed, du_fixed, 0.0)
            b = rhs - (self.K @ d if rhs.ndim == 1 else (self.K @ d)[:, None])
            x[fixed] = du_fixed[fixed] if rhs.ndim == 1 else du_fixed[fixed, None]
        x[self.free] = self._lu.solve(np.ascontiguousarray(b[self.free]))
        return x

    def freeing(self, dofs: np.ndarray) -> "SymmetricLU":
        """The factor of the larger free block (a new factorization)."""
        free = self.free.copy()
        free[dofs] = True
        return SymmetricLU(self.K, free, self.shift)


class RankOneSolver:
    """The solver's linear solver for a `GasTangent`: the wrapped solver factors the sparse part,
    `RankOneFactor` adds the rank-one term."""

    def __init__(self, base):
        self._base = base

    def factor(self, K, free: np.ndarray, shift: float = 0.0):
        """The factor of (K_s + c g g^T)_ff (+ shift diag|K_s,ff|). Where K_s,ff is not definite but
        the whole is (the gas holds the wall that would snap at fixed dp), an indefinite
        factor of the sparse part (`SymmetricLU`) replaces the Cholesky factor: the Newton step
        stays exact instead of shifted. Raises NotPositiveDefinite where the whole is not."""
        rank_one = getattr(K, "rank_one", None)
        try:
            fac = self._base.factor(_sparse_part(K), free, shift)
        except NotPositiveDefinite:
            if rank_one is None:
                raise
            return _definite(RankOneFactor(SymmetricLU(_sparse_part(K), free, shift), *rank_one))
        return fac if rank_one is None else RankOneFactor(fac, *rank_one)

    def __getattr__(self, name):
        return getattr(self._base, name)


@dataclass
class GasMechanics:
    """`fem.forms.Mechanics` of the cup with the gas of `gas` sealed in its cavity: energy
    W + Pi_gas(V_cav), force r + dp dV/du, tangent K + dp d2V/du2 + (N k_B T / V^2) dV dV^T
    (a `GasTangent`; module docstring).

    schedule: N as a function of the path parameter t (molecules let in or out along the path);
    `at(t)` is then the potential at t, which `follow_gas_path` minimizes step by step."""

    body: Mechanics
    cavity: CavitySurface
    gas: TrappedGas
    schedule: Callable[[float], float] | None = None
    # an incremental friction law's instabilities crossed by damped motion on this path
    # (`fem.newton.relax_step`): the held branch's short moves opt in (`fem.gas_branch`)
    relaxes: bool = False
    _load: PressurizedMechanics | None = field(default=None, repr=False)   # CSR positions, shared

    def __post_init__(self) -> None:
        if self.cavity.wetting_m != 0.0:
            raise ValueError(f"wetting_m: the trapped gas needs the geometric cavity volume "
                             f"(wetting_m = 0), got {self.cavity.wetting_m}")
        if self._load is None:
            self._load = PressurizedMechanics(self.body, self.cavity, 0.0)

    def make_solver(self, pattern, coordinates: np.ndarray, mesh=None) -> "RankOneSolver":
        """The linear solver `follow_path` uses for this mechanics: the body's sparse factor with the
        gas's rank-one term by Sherman-Morrison (module docstring). The body's solver depends on
        the mesh and the tangent's pattern only, so it is built once per mesh (`make_solver` keeps it):
        a branch runs hundreds of short paths on one cup."""
        return RankOneSolver(make_solver(_sparse_part(pattern), coordinates, mesh))

    def at(self, t: float) -> "GasMechanics":
        if self.schedule is None:
            return self
        return replace(self, gas=replace(self.gas, N=float(self.schedule(t))), schedule=None)

    @property
    def kin(self):
        return self.body.kin

    @property
    def material(self):
        return self.body.material

    def coordinates(self, u: np.ndarray) -> np.ndarray:
        """Deformed node coordinates x = X + u [2, nnodes] (the cavity load's)."""
        return self._load.coordinates(u)

    def volume_m3(self, u: np.ndarray) -> float:
        """V_cav(u) [m^3]."""
        return self.cavity.volume(self.coordinates(u))

    def dp_Pa(self, u: np.ndarray) -> float:
        """dp = p_a - N k_B T / V_cav(u) [Pa] at the state u."""
        return self.gas.p_a_Pa - self.gas.pressure_Pa(self.volume_m3(u))

    def pressurized(self, u: np.ndarray) -> PressurizedMechanics:
        """The dp-loaded mechanics with the dp of the state u (same force at u; its tangent lacks
        the rank-one term): the object `fem.suction`'s outputs are measured with."""
        return replace(self._load, dp_Pa=self.dp_Pa(u), schedule=None)

    def energy(self, u: np.ndarray) -> float:
        return self.body.energy(u) + self.gas.potential_J(self.volume_m3(u))

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return self.evaluate(u)[1]

    def linearize(self, u: np.ndarray) -> tuple[np.ndarray, GasTangent]:
        return self.evaluate(u)[1:]

    def evaluate(self, u: np.ndarray) -> tuple[float, np.ndarray, GasTangent]:
        x = self.coordinates(u)
        V, (dofs, grad), hess, pairs = self.cavity.derivatives(x)
        Pi_gas = self.gas.potential_J(V)
        dp = self.gas.p_a_Pa - self.gas.pressure_Pa(V)
        W, r, K = self.body.evaluate(u)
        g = np.bincount(dofs, grad, minlength=r.size)
        data = self._load.add_hessian(K, pairs, hess, dp)
        T = GasTangent.of(K, data, self.gas.NkT_J / V**2, g)
        T.chain_cut = ChainCut(self.cavity, x, dp)
        return W + Pi_gas, r + dp * g, T


def follow_gas_path(mech: GasMechanics, dirichlet: Callable[[float], tuple[np.ndarray, np.ndarray]],
                    t_max: float, *, plane: RigidPlane | None, start: StepResult | None,
                    options: SolverOptions = SolverOptions(),
                    on_step: Callable[[StepResult], None] | None = None,
                    name: str = "t",
                    predict: Callable[[float, np.ndarray, float], np.ndarray] | None = None) -> SolverStats:
    """`fem.solver.follow_path` for a `GasMechanics`, with the exact rank-one tangent (module
    docstring); predict: each step's first Newton iterate (`fem.solver.follow_path`). Raises what
    follow_path raises, and RuntimeError if the solver did not build its linear solver through
    the wrapped factory."""
    if not isinstance(mech, GasMechanics):
        raise TypeError(f"mech: a GasMechanics is required, got {type(mech).__name__}")
    return follow_path(mech, dirichlet, t_max, plane=plane, start=start, options=options,
                       on_step=on_step, name=name, predict=predict)
