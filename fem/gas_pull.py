"""The largest pull a sealed gas-filled cup holds: the plate raised at the sealed content N.

    cup = CupWithGas.of(mesh, NeoHookean())
    sealed = cup.press_to(r_start_m=10e-3)[-1]
    F_max, partial = largest_pull_checked(cup, sealed)

At fixed N the cavity's suction grows as the plate rises and the pull F1 with it, until the wall's
pull-off (the maximum of F1 along the path) or the seal opening. A branch held at a larger F1 does
not start: the cup lets go at once. Slips of the seal drop the pull within one step and it may rise
again after them, so the search goes on past each (`largest_pull`). The water-filled cup's
counterpart is `fem.water_branch.largest_pull`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .branch_end import plate_floor_m
from .gas_path import CupWithGas, GasState
from .solver import ConvergenceError
from .trapped_gas import GasMechanics, TrappedGas, follow_gas_path

__all__ = ["largest_pull", "largest_pull_checked"]


class _Past(Exception):
    """Stops the fixed-N0 pull once its pull has passed its maximum."""


def largest_pull(cup: CupWithGas, sealed: GasState, drop: float = 0.02) -> float:
    """The largest pull F1 [N] along the plate raised at fixed N (the sealed state's) from
    `sealed`: the path is followed up to the plate's floor (`fem.branch_end`)
    until F1 has fallen steadily by `drop` of its maximum since the last slip (a slip drops the
    pull by more than that within one step, and the pull may rise again after it: the search goes
    on past it), or the solver stops (the seal opening); the maximum over the path refined by the
    parabola through the three states around it."""
    return largest_pull_checked(cup, sealed, drop)[0]


def largest_pull_checked(cup: CupWithGas, sealed: GasState, drop: float = 0.02) -> tuple[float, str | None]:
    """`largest_pull` and, where the solver stopped or the plate reached its floor while the pull
    was still rising (the maximum not reached: a lower bound only), why; else None."""
    mech = GasMechanics(cup.cup.mech, cup.cavity, TrappedGas(sealed.N, cup.T_K, cup.p_a_Pa))
    top = cup.cup.top
    dofs, zeros = np.concatenate([2 * top, 2 * top + 1]), np.zeros(top.size)
    u0, span = sealed.u_m, sealed.u_m - plate_floor_m(cup)
    plate = lambda t: (dofs, np.concatenate([zeros, np.full(top.size, -(u0 - t))]))  # noqa: E731
    seen: list[tuple[float, float]] = [(u0, sealed.F1_N)]

    since_slip = [sealed.F1_N]                   # the pulls since the last slip

    def on_step(step) -> None:
        F1 = float(np.sum(step.r_int[2 * top + 1]))
        best = max(since_slip)
        if best > 0 and seen[-1][1] - F1 > drop * best:        # fell by more than drop in one step: a slip
            since_slip[:] = [F1]
        else:
            since_slip.append(F1)
        seen.append((u0 - step.t, F1))
        if best > 0 and len(since_slip) > 1 and F1 < (1.0 - drop) * max(since_slip):
            raise _Past
    # the solver's steps are fractions of the whole range: scaled to give the same steps in u
    # whatever the floor's depth, those of 1 % of the way from the sealed plate to -h1
    o, f = cup.options, (u0 + cup.h1_m) / span
    options = replace(o, initial_step=f * o.initial_step, max_step=f * min(o.max_step, 0.01),
                      min_step=f * o.min_step, jump_min_step=f * o.jump_min_step)
    stopped = None
    try:
        follow_gas_path(mech, plate, span, plane=cup.cup.plane, start=sealed.state, options=options,
                        on_step=on_step)
    except _Past:
        pass
    except ConvergenceError as err:
        stopped = str(err)
    u, F = np.array(seen).T
    k = int(np.argmax(F))
    partial = stopped if stopped is not None and k == F.size - 1 else None
    if stopped is None and k == F.size - 1 > 0:            # still rising at the plate's floor
        partial = f"the pull still rising at the plate's floor u = {1e3 * u[-1]:.4g} mm"
    if 0 < k < F.size - 1:
        a, b, c = np.polyfit(u[k - 1:k + 2], F[k - 1:k + 2], 2)
        if a < 0:
            return float(max(F[k], c - b * b / (4 * a))), partial
    return float(F[k]), partial
