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
from typing import Any

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
    was still rising (the maximum not reached: a lower bound only), why; else None.
    A law without a history (frictionless: the state at a plate position does not depend on the
    steps that led there) is scouted with double steps and the single steps filled in around the
    maximum only (`_Pull.scouted`); a pull the scout finds irregular is followed in single steps.
    A law with a history (Coulomb, sticking) takes double steps only where no node lands, sticks
    again or turns (`_Pull.resumed`): the end of such a step solves the same problem whatever
    the steps between, so the states are the single steps' to Newton's tolerance."""
    pull = _Pull(cup, sealed, drop)
    if cup.cup.plane.law.conservative:
        found = pull.scouted()
        if found is not None:
            return found
        return pull.largest(*pull.follow(1))
    return pull.largest(*pull.resumed())


class _OffGrid(Exception):
    """Stops a scout whose path left the grid of single steps (a cut-back, the floor's last
    step) or slipped; in `_Pull.resumed`, also at a double step that is not `_easy`."""


class _Easy(Exception):
    """Stops single steps that may go on in double steps (`_Pull.resumed`)."""


#: an easy step's largest Newton iterations, and the easy single steps in a row before double
#: steps are taken (`_Pull.resumed`)
EASY_ITERATIONS, EASY_STEPS = 4, 2


def _easy(before: tuple[float, float, Any], F1: float, step) -> bool:
    """Whether a step from the state `before` (t, F1, state) to `step` (its pull F1) could have
    been one of two: the pull rises, Newton took at most EASY_ITERATIONS iterations, and the
    contact leaves no history that the steps decide (`_history_free`)."""
    return F1 > before[1] and step.iterations <= EASY_ITERATIONS and \
        _history_free(before[2].contact, step.contact)


def _history_free(a, b) -> bool:
    """Whether the step from contact state a to b leaves no history that its steps decide: no
    node lands (its anchor is where it touches down) and no sliding node sticks again or turns
    (its anchor is where that step starts); nodes may start to slide and leave the plane. The
    end state then solves the same problem whatever the steps between (`fem.contact.ContactState`)."""
    if a is None or b is None:
        return a is b
    held = a.active & b.active
    return not (np.any(b.active & ~a.active) or np.any(held & (a.slip != 0) & (b.slip != a.slip)))


class _Pull:
    """The plate raised at the sealed N on the grid of single steps t_i = i dt [m]."""

    def __init__(self, cup: CupWithGas, sealed: GasState, drop: float):
        self.cup, self.sealed, self.drop = cup, sealed, drop
        self.mech = GasMechanics(cup.cup.mech, cup.cavity, TrappedGas(sealed.N, cup.T_K, cup.p_a_Pa))
        top = self.top = cup.cup.top
        self.dofs, self.zeros = np.concatenate([2 * top, 2 * top + 1]), np.zeros(top.size)
        self.u0, self.span = sealed.u_m, sealed.u_m - plate_floor_m(cup)
        # the solver's steps are fractions of the whole range: scaled to give the same steps in u
        # whatever the floor's depth, those of 1 % of the way from the sealed plate to -h1
        o, f = cup.options, (self.u0 + cup.h1_m) / self.span
        self.options = replace(o, initial_step=f * o.initial_step, max_step=f * min(o.max_step, 0.01),
                               min_step=f * o.min_step, jump_min_step=f * o.jump_min_step)
        self.uniform = self.options.initial_step >= self.options.max_step
        self.dt = self.options.max_step * self.span

    def plate(self, t0: float):
        """The plate's prescribed displacement at t0 + t."""
        z = lambda t: np.full(self.top.size, -(self.u0 - t0 - t))           # noqa: E731
        return lambda t: (self.dofs, np.concatenate([self.zeros, z(t)]))

    def pull_N(self, step) -> float:
        return float(np.sum(step.r_int[2 * self.top + 1]))

    def follow(self, stride: int, prefix: list | None = None,
               switch: bool = False) -> tuple[list[tuple[float, float, Any]], str | None]:
        """The states (t, F1, state) along the path in steps of `stride` dt up to the stop
        (`largest_pull`), and the solver's message where it stopped; stride > 1 raises `_OffGrid`
        at a step off the grid or a slip. prefix: the states followed before; the path goes on
        from the last (default: the sealed state). With `switch` (`resumed`), a double step
        whose step is not `_easy` raises `_OffGrid`, and single steps raise `_Easy` after
        EASY_STEPS easy ones in a row (the states so far in self.seen, in both)."""
        drop = self.drop
        seen = self.seen = list(prefix or [(0.0, self.sealed.F1_N, self.sealed.state)])
        since_slip = self.since_slip([s[1] for s in seen])   # the pulls since the last slip
        t0, start, easy = seen[-1][0], seen[-1][2], [0]

        def on_step(step) -> None:
            if prefix and step.t == 0:                   # the start: seen already
                return
            t, F1 = t0 + step.t, self.pull_N(step)
            if stride > 1 and step.t > 0 and abs(t - seen[-1][0] - stride * self.dt) > 1e-9 * self.dt:
                raise _OffGrid
            if switch and step.t > 0:
                easy[0] = easy[0] + 1 if _easy(seen[-1], F1, step) else 0
                if stride > 1 and not easy[0]:
                    raise _OffGrid(F1 <= seen[-1][1])          # (whether the pull fell)
            best = max(since_slip)
            if best > 0 and seen[-1][1] - F1 > drop * best:    # fell by more than drop in one step: a slip
                if stride > 1:
                    raise _OffGrid
                since_slip[:] = [F1]
            else:
                since_slip.append(F1)
            seen.append((t, F1, step))
            if best > 0 and len(since_slip) > 1 and F1 < (1.0 - drop) * max(since_slip):
                raise _Past
            if switch and stride == 1 and easy[0] >= EASY_STEPS:
                raise _Easy
        # fractions of the rest of the way that are the steps (in u) of the whole way
        o, f = self.options, self.span / (self.span - t0) if t0 > 0 else 1.0
        options = o if f == 1.0 else replace(o, initial_step=min(1.0, f * o.initial_step),
                                             max_step=min(1.0, f * o.max_step),
                                             min_step=min(1.0, f * o.min_step),
                                             jump_min_step=min(1.0, f * o.jump_min_step))
        if stride > 1:
            size = min(1.0, stride * options.max_step)
            options = replace(options, initial_step=size, max_step=size)
        stopped = None
        try:
            follow_gas_path(self.mech, self.plate(t0), self.span - t0, plane=self.cup.cup.plane,
                            start=start, options=options, on_step=on_step)
        except _Past:
            pass
        except ConvergenceError as err:
            stopped = str(err)
        return seen, stopped

    def since_slip(self, pulls: list[float]) -> list[float]:
        """The pulls since the last slip among `pulls` (`follow`'s rule)."""
        since = pulls[:1]
        for before, F1 in zip(pulls, pulls[1:]):
            if max(since) > 0 and before - F1 > self.drop * max(since):
                since = [F1]
            else:
                since.append(F1)
        return since

    def largest(self, seen, stopped: str | None) -> tuple[float, str | None]:
        """The largest pull over `seen` refined by the parabola through the three states around
        it, and why it is a lower bound (`largest_pull_checked`)."""
        u, F = self.u0 - np.array([s[0] for s in seen]), np.array([s[1] for s in seen])
        k = int(np.argmax(F))
        partial = stopped if stopped is not None and k == F.size - 1 else None
        if stopped is None and k == F.size - 1 > 0:            # still rising at the plate's floor
            partial = f"the pull still rising at the plate's floor u = {1e3 * u[-1]:.4g} mm"
        if 0 < k < F.size - 1:
            a, b, c = np.polyfit(u[k - 1:k + 2], F[k - 1:k + 2], 2)
            if a < 0:
                return float(max(F[k], c - b * b / (4 * a))), partial
        return float(F[k]), partial

    def resumed(self) -> tuple[list[tuple[float, float, Any]], str | None]:
        """`follow`'s states of a law with a history: single steps, and double steps after
        EASY_STEPS easy single steps in a row (`_easy`: the pull rising, few Newton iterations,
        no history the steps decide) for as long as each double step is easy too. A double step
        that is not is redone in single steps from its start, or from the start of the double
        step before where the pull fell, so that every maximum and the stop are found in single
        steps; single steps follow to the stop (double steps once per pull: the contact test is
        not a proof, and taken again after later easy pairs they were mostly rejected)."""
        if not self.uniform:
            return self.follow(1)
        try:
            return self.follow(1, switch=True)
        except _Easy:
            seen = self.seen
        try:
            seen, stopped = self.follow(2, seen, switch=True)    # ended: the floor or the solver's stop
            return self.follow(1, seen[:-1])
        except _OffGrid as off:
            fell = off.args and off.args[0] and len(self.seen) > 2
            return self.follow(1, self.seen[:-1] if fell else self.seen)

    def scouted(self) -> tuple[float, str | None] | None:
        """The largest pull from double steps, the single steps between them filled in next to
        every double step within one double step's change of the pull from its maximum, and
        next to the largest until its neighbours are known; None (follow single steps) where the
        scout leaves the grid, slips, stops in the solver or ends at its largest pull."""
        if not self.uniform:
            return None
        try:
            seen, stopped = self.follow(2)
        except _OffGrid:
            return None
        F = [s[1] for s in seen]
        k = int(np.argmax(F))
        if stopped is not None or not 0 < k < len(F) - 1:
            return None
        grid = {round(t / self.dt): (t, F1, step) for t, F1, step in seen}
        last = max(grid)
        near = max(abs(F[k] - F[k - 1]), abs(F[k + 1] - F[k]))
        wanted = {i + j for i, (_, F1, _) in grid.items() if F1 >= F[k] - near for j in (-1, 1)}
        while True:
            for i in sorted(wanted - grid.keys()):
                if not 0 < i < last:
                    return None
                grid[i] = self.single_step(*grid[i - 1][::2])
                if grid[i] is None:
                    return None
            best = max(grid, key=lambda i: grid[i][1])
            wanted = {best - 1, best + 1}
            if wanted <= grid.keys():
                break
        return self.largest([grid[i] for i in (best - 1, best, best + 1)], None)

    def single_step(self, t0: float, start) -> tuple[float, float, Any] | None:
        """(t, F1, state) one single step on from the state `start` at t0 (None: not converged)."""
        end: list = []
        try:
            follow_gas_path(self.mech, self.plate(t0), self.dt, plane=self.cup.cup.plane, start=start,
                            options=replace(self.cup.options, initial_step=1.0, max_step=1.0),
                            on_step=lambda step: end.append(step))
        except ConvergenceError:
            return None
        return t0 + self.dt, self.pull_N(end[-1]), end[-1]
