"""The water-filled cup held by a given pull F1: its equilibrium branch, V_w as the unknown.

    cup = CupWithWater.of(mesh, NeoHookean())
    sealed = cup.press(4e-3)[-1]                   # pressed with the water expelled, sealed at V_w0
    branch = water_branch(cup, sealed, F1_N=10.0)
    branch.detachment.V_w_m3, branch.reason, [(s.u_m, s.V_w_m3, s.p_b_Pa, s.seal_r_m) for s in branch.states]

The walk is the gas branch's (`fem.gas_branch`: the plate raised at fixed content until the pull
is F1, then the states holding F1 stepped in the plate position with the content the unknown,
switching to the content as the parameter where the branch turns in u, jumps of the pull crossed
and restored), with the water volume V_w in place of the molecules N: each state is the
constrained state of `fem.water_cavity` (V_cav = V_w, the cavity pressure its multiplier),
reached from the previous state of the branch with the plate and V_w on a line.

The F1 root's derivatives are exact for the state's contact set (`pull_sensitivities`): the
linear response of the constrained equilibrium, the bordered system

    [K_s  g] [du ]   [-K_s du_plate]
    [g^T  0] [ddp] = [dV_w - g.du_plate]

(K_s = K + dp Hess V, g = grad V, on the free dofs with the held contact dofs fixed and Coulomb's
sliding nodes sliding), solved by eliminating ddp on one sparse LU of K_s: the limit c -> inf of
the gas's Sherman-Morrison formula.

Detachment (the criterion): the inflow raises V_w, and the cup follows the branch while V_w can
still rise along it. Where V_w(u) has its maximum (the fold of the branch, dV_w/du = 0) no state
with more water holds F1: the cup lets go ("fold"). The branch also ends where the seal opens, no
node of the cavity chain on the plane ("seal opened"). The lifetime is t = int dV_w / Q_w over
the branch (`validation.bridge.fem_route`: the inflow Q_w of eq 24 through each state's profile).

The largest pull the sealed cup holds (`largest_pull`) is the largest along the plate raised at
fixed V_w0: the liquid may go into tension (p_b < 0, no cavitation), so it is bounded by the seal
opening or by the wall folding onto itself, not by p_a pi r_k^2 as for a gas.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
import scipy.sparse.linalg as spla

from .branch_slopes import held_plate_system
from .gas_branch import Branch, _Trial, _Walk, equilibrium_branch, state_between
from .solver import StepResult
from .cup import _joined
from .integrity import check_state
from .water_cavity import CupWithWater, WaterMechanics, WaterState

__all__ = ["water_branch", "water_state_between", "pull_sensitivities", "cavity_pressure_difference",
           "largest_pull", "WaterWalk"]


def water_branch(cup: CupWithWater, sealed: WaterState, F1_N: float, du_m: float = 0.1e-3,
                 u_min_m: float | None = None, max_states: int = 400,
                 progress: Callable[[int, float, float], None] | None = None) -> Branch:
    """The states holding F1_N from `sealed` to detachment (module docstring; the arguments and
    ends are `fem.gas_branch.equilibrium_branch`'s, `Branch.N_max` is the largest V_w [m^3])."""
    if not isinstance(cup, CupWithWater):
        raise TypeError(f"cup: a CupWithWater is required, got {type(cup).__name__}")
    return equilibrium_branch(cup, sealed, F1_N, du_m, u_min_m, max_states, progress, walk=WaterWalk)


def water_state_between(cup: CupWithWater, a: WaterState, b: WaterState, F1_N: float) -> WaterState | None:
    """A state holding F1_N between two consecutive states of a water branch
    (`fem.gas_branch.state_between`)."""
    return state_between(cup, a, b, F1_N, walk=WaterWalk)


def cavity_pressure_difference(cup: CupWithWater, step: StepResult) -> float:
    """dp [Pa] of a converged constrained state, from its equilibrium: r + dp grad V = 0 on the
    cavity surface's dofs that are neither on the plate nor on the plane (least squares)."""
    mech = cup.cup.mech
    x = mech.kin.node_coordinates() + np.stack([step.u[0::2], step.u[1::2]])
    _, (dofs, grad), _, _ = cup.cavity.derivatives(x)
    r = mech.internal_force(step.u)
    g = np.bincount(dofs, grad, minlength=r.size)
    keep = np.ones(r.size, bool)
    top = cup.cup.top
    keep[np.concatenate([2 * top, 2 * top + 1])] = False
    if step.contact is not None:
        on = cup.cup.plane.nodes[step.contact.active]
        keep[np.concatenate([2 * on, 2 * on + 1])] = False
    gk = g[keep]
    return float(-(gk @ r[keep]) / (gk @ gk))


def pull_sensitivities(cup: CupWithWater, s: WaterState) -> tuple[float, float]:
    """(dF1/dV_w [N/m^3], dF1/du [N/m]) at a converged water state: the bordered linear response
    (module docstring) to a change of V_w at the held plate and to a plate move at fixed V_w."""
    return _sensitivities(cup, s.state, s.dp_Pa)


def _sensitivities(cup: CupWithWater, state: StepResult, dp_Pa: float) -> tuple[float, float]:
    u = state.u
    mech = WaterMechanics(cup.cup.mech, cup.cavity, cup.cavity.volume(
        cup.cup.mech.kin.node_coordinates() + np.stack([u[0::2], u[1::2]])), dp_Pa, 1.0)
    _, _, K = mech.evaluate(u)                  # K_s = K + dp Hess V (V = V_w: dp exact)
    _, g = K.rank_one
    Ks = K.plain()
    plate_z, free, P, down = held_plate_system(cup, state)
    lu = spla.splu((P @ Ks)[free][:, free].tocsc())
    a, b = lu.solve(np.stack([(P @ (Ks @ down))[free], (P @ g)[free]], axis=1)).T
    gf = g[free]
    s = gf @ b                                            # dV/d(-dp) at the held plate

    def response(dV: float, d: np.ndarray, a_f: np.ndarray) -> float:
        ddp = (g @ d - gf @ a_f - dV) / s
        x = d.copy()
        x[free] = -a_f - ddp * b
        return float(np.sum((Ks @ x + ddp * g)[plate_z]))
    return response(1.0, np.zeros(u.size), np.zeros(gf.size)), response(0.0, down, a)


def largest_pull(cup: CupWithWater, sealed: WaterState, du_m: float = 0.1e-3,
                 drop: float = 0.02) -> tuple[float, str | None]:
    """The largest pull F1 [N] along the plate raised at the sealed state's V_w, and the solver's
    message where it stopped while the pull was still rising (a lower bound: the liquid under
    tension pulls the wall until it folds onto itself, which the FEM does not model, or the plate
    reaches -h1), else None.
    Plate steps of du_m up to -h1, each ending on the constraint (`CupWithWater.solve_water`),
    until F1 has fallen by `drop` of its maximum or the seal opens; the maximum refined by the
    parabola through the three states around it."""
    top = cup.cup.top
    step, u, V_w, dp = sealed.state, sealed.u_m, sealed.V_w_m3, sealed.dp_Pa
    seen: list[tuple[float, float]] = [(u, sealed.F1_N)]
    stopped, opened = None, False
    options = replace(cup.options, initial_step=1.0, max_step=1.0)      # one load step per move
    while u - du_m > -cup.h1_m:
        try:
            step, dp, _ = cup.solve_water(step, dp, u, u - du_m, V_w, V_w, options)
            check_state(cup.mesh, step.u, u - du_m, 0, u - du_m)    # no fold of the wall
        except RuntimeError as err:                                 # StateRejected is one
            stopped = str(err)
            break
        z = cup.mesh.doflocs[1, cup.cavity.nodes] + step.u[2 * cup.cavity.nodes + 1]
        if not np.any(z <= cup.cavity.tolerance_m):           # the seal opened: not held
            opened = True
            break
        u -= du_m
        seen.append((u, float(np.sum(step.r_int[2 * top + 1]))))
        best = max(f for _, f in seen)
        if best > 0 and seen[-1][1] < (1.0 - drop) * best:
            break
    us, F = np.array(seen).T
    k = int(np.argmax(F))
    partial = None
    if k == F.size - 1 and not opened:          # still rising where the path ended
        partial = stopped or f"the pull still rising at u = {1e3 * us[-1]:.4g} mm, the plate's end (-h1)"
    if 0 < k < F.size - 1:
        a, b, c = np.polyfit(us[k - 1:k + 2], F[k - 1:k + 2], 2)
        if a < 0:
            return float(max(F[k], c - b * b / (4 * a))), partial
    return float(F[k]), partial


class WaterWalk(_Walk):
    """`fem.gas_branch`'s walk with V_w as the content (`_Trial.N` holds V_w [m^3]): each solve is
    `CupWithWater.solve_water`, its sensitivities the bordered ones, its states `WaterState`s."""

    def __init__(self, cup: CupWithWater, F1_N: float):
        super().__init__(cup, F1_N)
        self.dp: dict[int, tuple[StepResult, float]] = {}        # id(state) -> (state, dp)

    def multiplier(self, step: StepResult) -> float:
        """dp [Pa] of a state: kept from its solve, else from its equilibrium."""
        kept = self.dp.get(id(step))
        if kept is None or kept[0] is not step:
            kept = self.dp[id(step)] = (step, cavity_pressure_difference(self.cup, step))
        return kept[1]

    def derivatives(self, s: _Trial) -> tuple[float, float]:
        if s not in self.slopes:
            self.slopes[s] = _sensitivities(self.cup, s.step, self.multiplier(s.step))
        return self.slopes[s]

    def solve(self, start: _Trial, u_m: float, N: float, options=None) -> _Trial:
        """The state at (u_m, V_w = N), reached from `start` with the plate and V_w on a line."""
        step, dp, stats = self.cup.solve_water(start.step, self.multiplier(start.step), start.u_m,
                                               float(u_m), start.N, float(N), options or self.options)
        self.stats = stats if self.stats is None else _joined(self.stats, stats)
        self.dp[id(step)] = (step, dp)
        return _Trial(float(u_m), float(N), float(np.sum(step.r_int[2 * self.cup.cup.top + 1])), step)

    def result(self, detachment, reason, trials=(), slopes=()) -> Branch:
        states = {id(t): self.cup.measure_water(t.step, t.N, self.multiplier(t.step), t.u_m, "held")
                  for t in trials}
        return Branch(self.F1, tuple(states[id(t)] for t in trials), np.array(slopes),
                      None if detachment is None else states[id(detachment)], reason, self.stats,
                      self.snaps)

