"""The sealed cup held by a given pull F1: its equilibrium branch, N as the unknown.

    cup = CupWithGas.of(mesh, NeoHookean(), contact="sticking")
    sealed = cup.press(4e-3)[-1]                   # pressed with the gas escaping, sealed at N0
    branch = equilibrium_branch(cup, sealed, F1_N=10.0)
    branch.detachment.N, branch.reason, [(s.u_m, s.N, s.p_b_Pa, s.V_m3, s.seal_r_m) for s in branch.states]

From the sealed state the plate is first raised at fixed N0 until the handle pulls F1 (the pull is
ramped at fixed N). Then, as gas leaks in, the cup moves along the states (u, N) whose pull is
F1: the branch is stepped in the plate position u (upwards, u decreasing) with N the unknown.
Each state is one `fem.solver` path from the previous state of the branch, the plate and N
moving together on a line in (u, N), so the contact history (sticking anchors, Coulomb slips) is
carried from state to state; N is found by a scalar Newton iteration on F1(u, N) = F1 whose
derivative dF1/dN is exact for the state's contact set: the linear response of the equilibrium
to dN at the held plate, solved with the rank-one gas tangent (`fem.trapped_gas`), the held
contact dofs fixed and Coulomb's sliding nodes sliding (`pull_sensitivities`). Every trial N is
reached from the previous state of the branch (not from the last trial: with friction a trial's
back-and-forth would enter the history); a secant step takes over when the tangent's step does
not halve the mismatch (the contact set changed in between).
A bordered Newton (N an unknown of the solver's Newton iteration beside u) would need the
solver's Newton step and line search (`fem.newton`) to carry a constraint that is not an energy;
the scalar root keeps the solver an energy minimization at given (u, N).

Detachment (the criterion): with the pull F1 held, the leak raises N, and the cup follows the
branch while N can still rise along it. Where N(u) has its maximum, dN/du = 0 (the fold of the
branch), no state with more gas holds F1: the cup lets go. That N_max is the largest amount of
gas the cup holds at F1, and the branch ends there ("fold"; dN/du is computed exactly at every
state, dN/du = -(dF1/du)/(dF1/dN), and the fold located by a secant on it). The branch also ends
where the seal opens, no node of the cavity chain being on the plane ("seal opened"), or where the
plate reaches u_min_m without either ("u_min"; not a detachment).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .gas_path import CupWithGas, GasState
from .solver import SolverStats, StepResult
from .cup import _joined
from .trapped_gas import K_B, GasMechanics, follow_gas_path

__all__ = ["Branch", "equilibrium_branch", "pull_sensitivities"]


@dataclass(frozen=True, eq=False)
class Branch:
    """The states holding the pull F1_N, the pulled state first (plate raised at N0 to F1), then
    along the plate position; `dN_du` [1/m] per state; the detachment state and its reason
    (module docstring); the cost of the whole branch."""

    F1_N: float
    states: tuple[GasState, ...]
    dN_du: np.ndarray
    detachment: GasState | None       # the fold (largest N) or the state where the seal opened
    reason: str                       # "fold", "seal opened", "u_min", "not held"
    stats: SolverStats

    @property
    def N_max(self) -> float:
        """The largest N held at F1 (that of the detachment state) [molecules]."""
        return self.detachment.N if self.detachment is not None else float("nan")

    def column(self, name: str) -> np.ndarray:
        """One field of every state as an array, e.g. column("N")."""
        return np.array([getattr(s, name) for s in self.states])


def pull_sensitivities(cup: CupWithGas, s: GasState) -> tuple[float, float]:
    """(dF1/dN [N per molecule], dF1/du [N/m]) at a converged sealed state: the linear response of
    the equilibrium to a change of N at the held plate and to a plate move at fixed N, with the
    full tangent K + dp Hess V + (N k_B T / V^2) grad V grad V^T on the free dofs and the state's
    held contact dofs fixed (its contact set kept). F1 is the plate's reaction (`fem.gas_path`).
    Coulomb's sliding nodes keep t = -mu lambda s: their radial row gains mu s times their normal
    row (the reaction lambda changes with the state). The matrix is factored by sparse LU (it
    need not be symmetric, nor definite where the gas alone holds the wall), the rank-one term
    added by Sherman-Morrison."""
    return _sensitivities(cup, s.N, s.state)


def _sensitivities(cup: CupWithGas, N: float, state: StepResult) -> tuple[float, float]:
    mech = GasMechanics(cup.cup.mech, cup.cavity, cup._gas(N))
    u = state.u
    _, r, K = mech.evaluate(u)
    c, g = K.rank_one
    plane, top = cup.cup.plane, cup.cup.top
    plate_z = 2 * top + 1
    held, _ = plane.constraints(state.contact)
    free = np.ones(u.size, bool)
    free[np.concatenate([2 * top, plate_z, held])] = False
    slide = state.contact.active & (state.contact.slip != 0)
    P = sp.identity(u.size, format="csr")                 # rows: r + mu s lambda = 0 when sliding
    if slide.any():
        nodes = plane.nodes[slide]
        P = P + sp.csr_matrix((plane.law.mu * state.contact.slip[slide].astype(float),
                               (2 * nodes, 2 * nodes + 1)), shape=P.shape)
    Ks = K.plain()
    lu = spla.splu((P @ Ks)[free][:, free].tocsc())
    down = np.zeros(u.size)
    down[plate_z] = -1.0                                  # u_z = -u on the plate: d/du
    b = -(K_B * cup.T_K / mech.volume_m3(u)) * g          # dr/dN at fixed u
    h = (P @ g)[free]
    rhs = np.stack([-(P @ b)[free], -(P @ (Ks @ down))[free] - c * h * (g @ down), h], axis=1)
    y = lu.solve(rhs)
    gf = g[free]
    y[:, :2] -= np.outer(y[:, 2], c * (gf @ y[:, :2]) / (1.0 + c * gf @ y[:, 2]))
    x_N, x_u = np.zeros(u.size), down.copy()
    x_N[free], x_u[free] = y[:, 0], y[:, 1]
    return float(np.sum((K @ x_N + b)[plate_z])), float(np.sum((K @ x_u)[plate_z]))


def equilibrium_branch(cup: CupWithGas, sealed: GasState, F1_N: float, du_m: float = 0.1e-3,
                       u_min_m: float | None = None, max_states: int = 400) -> Branch:
    """The states holding the pull F1_N from `sealed` (a "pressed" state, sealed there at p_a, or
    a sealed state) to detachment (module docstring). du_m: the plate step along the branch
    (halved, down to du_m / 16, where a state cannot be found); u_min_m: the lowest plate
    position (default -h1: the plate above the touching height, the suction holding the wall on
    the plane). Raises ValueError for bad input; where no state is found even with the smallest
    step, the branch ends there with reason "stopped: <why>" and no detachment."""
    if not (isinstance(F1_N, (int, float)) and math.isfinite(F1_N)):
        raise ValueError(f"F1_N: must be a finite number, got {F1_N!r}")
    if not (math.isfinite(du_m) and 0.0 < du_m <= 0.1 * cup.h1_m):
        raise ValueError(f"du_m: must be in (0, {0.1 * cup.h1_m * 1e3:.4g}] mm, got {du_m * 1e3:.4g} mm")
    u_min = -cup.h1_m if u_min_m is None else float(u_min_m)
    if not (u_min < sealed.u_m):
        raise ValueError(f"u_min_m: must be below the sealed plate position {sealed.u_m * 1e3:.4g} mm, "
                         f"got {u_min * 1e3:.4g} mm")
    walk = _Walk(cup, float(F1_N))
    start = _Trial(sealed.u_m, sealed.N, sealed.F1_N, sealed.state)
    try:
        first = walk.pull_to_force(start, du_m, u_min)
    except RuntimeError as err:
        return walk.result(None, f"stopped: {err}")
    if first is None:
        return walk.result(None, "not held")
    trials, slopes = [first], [walk.slope(first)]
    step = du_m
    while len(trials) < max_states:
        prev = trials[-1]
        u_next = prev.u_m - step
        if u_next < u_min:
            return walk.result(None, "u_min", trials, slopes)
        try:
            s = walk.hold(prev, u_next, prev.N - slopes[-1] * step)
        except RuntimeError as err:
            if step > du_m / 16 * (1 + 1e-9):
                step *= 0.5
                continue
            return walk.result(None, f"stopped: {err}", trials, slopes)
        step = min(du_m, 2.0 * step)
        if _open(cup, s):
            return walk.result(s, "seal opened", trials + [s], slopes + [walk.slope(s)])
        k = walk.slope(s)
        if k > 0.0 >= slopes[-1]:                # N(u) passed its maximum (u decreasing)
            fold = walk.fold(prev, slopes[-1], s, k)
            return walk.result(fold, "fold", trials + [fold], slopes + [walk.slope(fold)])
        trials.append(s)
        slopes.append(k)
    raise RuntimeError(f"F1_N = {F1_N:g} N: no detachment within {max_states} states of {du_m * 1e3:g} mm")


def _open(cup: CupWithGas, s: "_Trial") -> bool:
    """Whether no node of the cavity chain is on the plane (the cavity is open to the outside)."""
    x = cup.mesh.doflocs + np.stack([s.step.u[0::2], s.step.u[1::2]])
    return not np.any(x[1, cup.cavity.nodes] <= cup.cavity.tolerance_m)


@dataclass(frozen=True, eq=False)
class _Trial:
    """A converged sealed state before its measurement: plate position, N, pull, solver state."""

    u_m: float
    N: float
    F1_N: float
    step: StepResult


class _Walk:
    """The state-to-state machinery of `equilibrium_branch`: solves, the F1 root, the costs."""

    def __init__(self, cup: CupWithGas, F1_N: float):
        self.cup, self.F1 = cup, F1_N
        self.options = replace(cup.options, initial_step=1.0, max_step=1.0)
        self.stats: SolverStats | None = None
        self.slopes: dict[_Trial, tuple[float, float]] = {}     # by identity
        rim = cup.mesh.doflocs[0, cup.cavity.nodes[-1]]
        # |F1 - F1_N| accepted: rtol of the largest suction force on the cup, p_a pi r_rim^2 [N]
        self.tolerance = cup.options.rtol * cup.p_a_Pa * math.pi * rim**2

    def derivatives(self, s: _Trial) -> tuple[float, float]:
        if s not in self.slopes:
            self.slopes[s] = _sensitivities(self.cup, s.N, s.step)
        return self.slopes[s]

    def slope(self, s: _Trial) -> float:
        """dN/du along the branch at s [1/m]."""
        dF1_dN, dF1_du = self.derivatives(s)
        return -dF1_du / dF1_dN

    def solve(self, start: _Trial, u_m: float, N: float) -> _Trial:
        """The state at (u_m, N), reached from `start` with the plate and N on a line."""
        u0, N0 = start.u_m, start.N
        mech = GasMechanics(self.cup.cup.mech, self.cup.cavity, self.cup._gas(N0),
                            schedule=lambda t: N0 + t * (N - N0))
        top = self.cup.cup.top
        dofs, zeros = np.concatenate([2 * top, 2 * top + 1]), np.zeros(top.size)

        def plate(t):
            return dofs, np.concatenate([zeros, np.full(top.size, -(u0 + t * (u_m - u0)))])
        last = []
        stats = follow_gas_path(mech, plate, 1.0, plane=self.cup.cup.plane, start=start.step,
                                options=self.options, on_step=last.append)
        self.stats = stats if self.stats is None else _joined(self.stats, stats)
        end = last[-1]
        return _Trial(float(u_m), float(N), float(np.sum(end.r_int[2 * top + 1])), end)

    def hold(self, prev: _Trial, u_m: float, N_guess: float) -> _Trial:
        """The state at plate position u_m whose pull is F1 (N by Newton on F1(N), module
        docstring), reached from prev."""
        s = self.solve(prev, u_m, N_guess)
        tried: list[tuple[float, float]] = [(s.N, s.F1_N - self.F1)]
        for _ in range(12):
            miss = s.F1_N - self.F1
            if abs(miss) <= self.tolerance:
                return s
            N_new = s.N - miss / self.derivatives(s)[0]
            if len(tried) >= 2 and abs(miss) > 0.5 * abs(tried[-2][1]):   # slow: secant
                (Na, fa), (Nb, fb) = tried[-2:]
                if fb != fa:
                    N_new = Nb - fb * (Nb - Na) / (fb - fa)
            if not N_new > 0.0:
                break
            s = self.solve(prev, u_m, N_new)
            tried.append((s.N, s.F1_N - self.F1))
        raise RuntimeError(f"F1_N = {self.F1:g} N: N not found at u = {u_m * 1e3:.4g} mm "
                           f"(pull off by {s.F1_N - self.F1:.3g} N after {len(tried) - 1} corrections)")

    def pull_to_force(self, sealed: _Trial, du_m: float, u_min: float) -> _Trial | None:
        """Raise the plate at fixed N from `sealed` until the pull is F1 (Newton in u with the exact
        dF1/du, the steps at most du_m); None if the plate reaches u_min first."""
        s = sealed
        while True:
            miss = s.F1_N - self.F1
            if abs(miss) <= self.tolerance:
                return s
            step = -miss / self.derivatives(s)[1]
            u_new = s.u_m + float(np.clip(step, -du_m, du_m))
            if u_new < u_min:
                return None
            s = self.solve(s, u_new, s.N)

    def fold(self, a: _Trial, ka: float, b: _Trial, kb: float) -> _Trial:
        """The state between a and b where dN/du = 0 on the branch (secant on dN/du)."""
        for _ in range(8):
            u = b.u_m + (a.u_m - b.u_m) * kb / (kb - ka)
            s = self.hold(a, u, a.N + ka * (u - a.u_m))
            k = self.slope(s)
            if abs(k) <= 1e-3 * max(abs(ka), abs(kb)) or abs(u - a.u_m) < 1e-9 * self.cup.h1_m:
                return s
            if k > 0.0:
                b, kb = s, k
            else:
                a, ka = s, k
        return s

    def result(self, detachment, reason, trials=(), slopes=()) -> Branch:
        """The measured branch (`fem.gas_path.CupWithGas.measure`)."""
        states = {id(t): self.cup.measure(t.step, GasMechanics(self.cup.cup.mech, self.cup.cavity,
                                                               self.cup._gas(t.N)), t.u_m, "held")
                  for t in trials}
        return Branch(self.F1, tuple(states[id(t)] for t in trials), np.array(slopes),
                      None if detachment is None else states[id(detachment)], reason, self.stats)
