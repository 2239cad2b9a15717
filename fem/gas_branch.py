"""The sealed cup held by a given pull F1: its equilibrium branch, N as the unknown.

    cup = CupWithGas.of(mesh, NeoHookean(), contact="coulomb", friction=0.5)
    sealed = cup.press(4e-3)[-1]                   # pressed with the gas escaping, sealed at N0
    branch = equilibrium_branch(cup, sealed, F1_N=10.0)
    branch.detachment.N, branch.reason, [(s.u_m, s.N, s.p_b_Pa, s.V_m3, s.seal_r_m) for s in branch.states]

From the sealed state the plate is first raised at fixed N0 until the handle pulls F1 (the pull is
ramped at fixed N). Then, as gas leaks in, the cup moves along the states (u, N) whose pull is
F1: the branch is stepped in the plate position u (upwards, u decreasing) with N the unknown,
or, where the branch turns in u (dF1/dN -> 0: more gas at the held plate no longer lowers the
pull), in N with u the unknown (natural-parameter switching along the branch's tangent, which
`pull_sensitivities` gives exactly; the direction is the one in which N rises, the leak's).
Each state is one `fem.solver` path from the previous state of the branch, the plate and N
moving together on a line in (u, N), so the contact history (sticking anchors, Coulomb slips) is
carried from state to state; N is found by a scalar Newton iteration on F1(u, N) = F1 whose
derivative dF1/dN is exact for the state's contact set: the linear response of the equilibrium
to dN at the held plate, solved with the rank-one gas tangent (`fem.trapped_gas`), the held
contact dofs fixed and Coulomb's sliding nodes sliding (`pull_sensitivities`). Every trial N is
reached from the previous state of the branch (not from the last trial: with friction a trial's
back-and-forth would enter the history; Coulomb's corrections only start their Newton iteration
at the last trial's state, `fem.branch_walk`); a secant step takes over when the tangent's step does
not reduce the mismatch tenfold (the contact set changed in between), and regula falsi on the
bracket of the trials where neither converges. A bordered Newton (N an unknown of the solver's
Newton iteration beside u) would need the solver's Newton step and line search (`fem.newton`)
to carry a constraint that is not an energy; the scalar root keeps the solver an energy
minimization at given (u, N).

Slips and snaps: the pull can jump as N rises at the held plate (or as the plate moves at fixed
N): a sticking node whose normal reaction reaches zero while it carries a tangential one is
released and slips (mu -> infinity has no continuous transition), a Coulomb seal slips where its
quasi-static step has no solution (crossed by damped motion, `fem.newton.relax_step`), or the
wall snaps. Where the bracket of the root closes to 1e-3 of the trial's move with the pull still
on both sides of F1, or a Coulomb trial's path crosses an instability (the state after it is
taken: the cup jumped there), or no state is found on the line even with 1/16 of a step, the cup
moves as the held pull and the leak move it, each move continuing the last state's path
(`fem.branch_jumps`: the plate rises at fixed N where the pull fell, gas enters at the held plate
where it rose, in turn, across the slips this releases; `Branch.snaps` counts the crossings, the
slips' dissipation is in the branch's stats). The sticking law's slips land where its load steps
put them, and the pull reached from the last state on a line jumps at many places (a cascade of
releases); its whole branch is therefore walked that way: gas let in at the held plate by a step
of the branch, then the plate's response, each state the first holding F1 (its moves in
STICKING_STEPS load steps, `fem.branch_walk`).

Detachment (the criterion): with the pull F1 held, the leak raises N, and the cup follows the
branch while N can still rise along it. Where N(u) has its maximum, dN/du = 0 (the fold of the
branch), no state with more gas holds F1: the cup lets go. That N_max is the largest amount of
gas the cup holds at F1, and the branch ends there ("fold"; dN/du is computed exactly at every
state, dN/du = -(dF1/du)/(dF1/dN), and the fold located by a secant on it). The branch also ends
where the seal opens, no node of the cavity chain being on the plane any more: the detachment is
then the last state with the seal closed, bisected to 1/64 of a step ("seal opened"). It ends
without a detachment where the plate reaches u_min_m ("u_min"), or where no state holds F1 even
with 1/16 of a step ("stopped after the state at u = .. mm, N = .. N0: why", the last state the
branch holds and the solver's cause). Where the cup moves by the leak and the held pull, it lets go
(a "fold") where the pull is below F1 and falls as the plate rises (`fem.branch_jumps`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .branch_end import plate_floor_m
from .branch_jumps import LetGo, leak_to_hold, settle
from .branch_slopes import held_plate_system, sensitivities
from .branch_walk import Branch, Jump, Trial as _Trial, Walk as _Walk, seal_open, u_leads
from .gas_path import CupWithGas, GasState

__all__ = ["Branch", "equilibrium_branch", "held_plate_system", "pull_sensitivities", "state_between"]


def pull_sensitivities(cup: CupWithGas, s: GasState) -> tuple[float, float]:
    """(dF1/dN [N per molecule], dF1/du [N/m]) at a converged sealed state: the linear response of
    the equilibrium to a change of N at the held plate and to a plate move at fixed N, with the
    full tangent K + dp Hess V + (N k_B T / V^2) grad V grad V^T on the free dofs and the state's
    held contact dofs fixed (its contact set kept). F1 is the plate's reaction (`fem.gas_path`).
    Coulomb's sliding nodes keep t = -mu lambda s: their radial row gains mu s times their normal
    row (the reaction lambda changes with the state). The matrix is factored by the mesh's banded
    Cholesky, Coulomb's rows added by the Woodbury identity (a sparse LU where it is not definite:
    the gas alone holding the wall; `fem.free_block`), the rank-one term by Sherman-Morrison."""
    return sensitivities(cup, s.N, s.state)


def equilibrium_branch(cup: CupWithGas, sealed: GasState, F1_N: float, du_m: float = 0.1e-3,
                       u_min_m: float | None = None, max_states: int = 400,
                       progress: Callable[[int, float, float], None] | None = None,
                       walk: type | None = None) -> Branch:
    """The states holding the pull F1_N from `sealed` (a "pressed" state, sealed there at p_a, or
    a sealed state) to detachment (module docstring). du_m: the plate step along the branch
    (halved, down to du_m / 16, where a state cannot be found); u_min_m: the lowest plate
    position (default `fem.branch_end.plate_floor_m`: the apex twice the wall's length above the
    plane); progress(k, u_m, N): called with every state k of the branch as it is found;
    walk: the walk's class for another cavity content (None: the gas's; `fem.water_branch`).
    Raises ValueError for bad input; where no state is found even with the smallest step, the
    branch ends there with reason "stopped <where>: <why>" and no detachment."""
    if not (isinstance(F1_N, (int, float)) and math.isfinite(F1_N)):
        raise ValueError(f"F1_N: must be a finite number, got {F1_N!r}")
    if not (math.isfinite(du_m) and 0.0 < du_m <= 0.1 * cup.h1_m):
        raise ValueError(f"du_m: must be in (0, {0.1 * cup.h1_m * 1e3:.4g}] mm, got {du_m * 1e3:.4g} mm")
    u_min = plate_floor_m(cup) if u_min_m is None else float(u_min_m)
    if not (u_min < sealed.u_m):
        raise ValueError(f"u_min_m: must be below the sealed plate position {sealed.u_m * 1e3:.4g} mm, "
                         f"got {u_min * 1e3:.4g} mm")
    content = "N" if walk is None else "V_w"        # the gas's, or the water's volume

    def where(s: _Trial, what: str = "after the state at") -> str:
        return _where(s, sealed.N, what, content)
    walk = (walk or _Walk)(cup, float(F1_N))
    start = _Trial(sealed.u_m, sealed.N, sealed.F1_N, sealed.state)
    try:
        first = walk.pull_to_force(start, du_m, u_min)
    except RuntimeError as err:
        return walk.result(None, f"stopped {where(start, f'raising the plate at {content}0 from')}: {err}")
    if first is None:
        return walk.result(None, "not held")
    trials, slopes = [first], [walk.slope(first)]
    if progress:
        progress(0, first.u_m, first.N)
    N_ref = abs(slopes[0]) * du_m if math.isfinite(slopes[0]) and slopes[0] else 1e-3 * first.N
    tangent = walk.tangent(first, du_m, N_ref, None)

    def crossed(restored: GasState) -> np.ndarray:
        """Take the state a jump of the pull was crossed to; the tangent to go on from it."""
        trials.append(restored)
        if progress:
            progress(len(trials) - 1, restored.u_m, restored.N)
        slopes.append(walk.slope(restored))
        tangent = walk.tangent(restored, du_m, N_ref, None)
        walk.snaps += 1
        return tangent
    h = 1.0
    while len(trials) < max_states:
        prev = trials[-1]
        if walk.staircase:        # sticking: the leak and the held pull in turn (`fem.branch_jumps`)
            try:
                s, why, part = leak_to_hold(walk, prev, h * N_ref * max(abs(tangent[1]), 0.25), du_m, u_min,
                                          lambda t: seal_open(cup, t))
            except RuntimeError as err:
                if h > 1.0 / 16.0 * (1 + 1e-9):
                    h *= 0.5
                    continue
                return walk.result(None, f"stopped {where(prev)}: {err}", trials, slopes)
            if s is None:
                return walk.result(prev if why != "u_min" else None, why, trials, slopes)
            h = min(1.0, 2.0 * h) if part == 1.0 else h * part
            trials.append(s)
            if progress:
                progress(len(trials) - 1, s.u_m, s.N)
            slopes.append(walk.slope(s))
            tangent = walk.tangent(s, du_m, N_ref, tangent)
            continue
        u_pred, N_pred = prev.u_m + h * tangent[0] * du_m, prev.N + h * tangent[1] * N_ref
        if u_pred < u_min:
            return walk.result(None, "u_min", trials, slopes)
        try:
            if u_leads(tangent):                        # u leads: N is the unknown
                s = walk.hold(prev, u_pred, N_pred)
            else:                                        # N leads (near a turn of u): u is
                s = walk.hold_u(prev, u_pred, N_pred)
        except Jump as jump:
            # the pull jumps across F1 (a slip): the cup crosses it at the jump's N, then the
            # plate rises (the pull fell) or gas enters (it rose) until the pull is F1 again,
            # crossing the slips this releases (`fem.branch_jumps.settle`)
            try:
                restored, why = settle(walk, jump.after, du_m, N_ref, u_min)
            except LetGo:
                return walk.result(prev, "fold", trials, slopes)
            except RuntimeError as err:
                return walk.result(None, f"stopped {where(prev)}: {jump}; then {err}", trials,
                                   slopes)
            if restored is None:
                return walk.result(None, why, trials, slopes)
            if seal_open(cup, restored):
                return walk.result(prev, "seal opened", trials, slopes)
            tangent, h = crossed(restored), 1.0
            continue
        except RuntimeError as err:
            if h > 1.0 / 16.0 * (1 + 1e-9):
                h *= 0.5
                continue
            # no state on the line from prev (a jump the trials cannot cross: a slip, a snap):
            # the cup moves as the leak and the held pull move it (`fem.branch_jumps`)
            dN = h * N_ref * max(abs(tangent[1]), 0.25)
            try:
                restored, why, _ = leak_to_hold(walk, prev, dN, du_m, u_min, lambda t: seal_open(cup, t))
            except RuntimeError as again:
                return walk.result(None, f"stopped {where(prev)}: {err}; then {again}", trials,
                                   slopes)
            if restored is None:
                return walk.result(prev if why != "u_min" else None, why, trials, slopes)
            tangent, h = crossed(restored), 1.0
            continue
        h = min(1.0, 2.0 * h)
        if seal_open(cup, s):
            last = walk.opening(prev, s, tangent)
            trials = trials + ([last] if last is not prev else [])
            slopes = slopes + ([walk.slope(last)] if last is not prev else [])
            return walk.result(last, "seal opened", trials, slopes)
        t = walk.tangent(s, du_m, N_ref, tangent)
        if t[1] < 0.0 < tangent[1]:                  # N passed its maximum along the branch
            fold = walk.fold(prev, slopes[-1], s, walk.slope(s))
            return walk.result(fold, "fold", trials + [fold], slopes + [walk.slope(fold)])
        trials.append(s)
        if progress:
            progress(len(trials) - 1, s.u_m, s.N)
        slopes.append(walk.slope(s))
        tangent = t
    raise RuntimeError(f"F1_N = {F1_N:g} N: no detachment within {max_states} states of {du_m * 1e3:g} mm")


def _where(s: _Trial, N0: float, what: str = "after the state at", content: str = "N") -> str:
    """Where a branch stopped: the last state it holds, by plate position and cavity content
    (the gas's N, or the water's volume for `fem.water_branch`), relative to the sealed one."""
    return f"{what} u = {s.u_m * 1e3:.4g} mm, {content} = {s.N / N0:.4g} {content}0"


def state_between(cup: CupWithGas, a: GasState, b: GasState, F1_N: float,
                  walk: type | None = None) -> GasState | None:
    """A state holding F1_N between two consecutive states a and b of a branch, reached from a
    (its history): N the unknown at the plate midway, or where that fails, the plate at N
    midway. None where neither is found between them, or where the way there crosses an
    instability (a jump of the pull between a and b). walk: as `equilibrium_branch`'s."""
    walk = (walk or _Walk)(cup, float(F1_N))
    prev = _Trial(a.u_m, a.N, a.F1_N, a.state)
    u, N = 0.5 * (a.u_m + b.u_m), 0.5 * (a.N + b.N)
    for find in (walk.hold, walk.hold_u):
        try:
            s = find(prev, u, N)
        except Jump as jump:
            if jump.instability:        # the cup jumps between a and b: no state midway
                return None
            continue
        except RuntimeError:
            continue
        if min(a.N, b.N) < s.N < max(a.N, b.N) and not seal_open(cup, s):
            return walk.result(None, "between", [s]).states[0]
    return None
