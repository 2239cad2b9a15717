"""The held branch across jumps of the pull: the cup moved as a held pull and a leak move it.

Where the pull F1 jumps (a sticking node lets go and lands elsewhere, a Coulomb seal slips, the
wall snaps) the equilibrium branch of `fem.gas_branch` has no state on the line from its last
state, and a slip often releases the next (a cascade within a fraction of a micrometre). The cup
then moves as the held pull and the leak move it, each move continuing the path of the last
state (so each slip is crossed once, in the direction the cup moves, and its dissipation is in
the solver's energy balance):

- the leak: gas enters at the held plate (N rises by dN), whatever the pull does on the way;
- the plate's response at fixed N (`settle`): where the pull is below F1 the plate rises until
  the pull reaches F1 from below; where it is above F1 (a slip raised it, or the plate's rise
  crossed a jump upwards) gas enters at the held plate until the pull falls to F1. A move that
  crosses F1 inside a jump ends on the far side, and the other move takes over (one crossing,
  `Branch.snaps`), at most CASCADE crossings before the state holds F1 again.

The cup lets go (reason "fold", the branch's largest N) where the pull is below F1 and falls as
the plate rises (dF1/du >= 0 at fixed N, exact for the state's contact set): no equilibrium
holds F1 in the direction the cup moves; the last state holding F1 is the detachment, located
by halving the leak step (HALVINGS times) from it.
"""

from __future__ import annotations

import math

__all__ = ["CASCADE", "HALVINGS", "LetGo", "settle", "leak_and_settle", "leak_to_hold"]

CASCADE = 24        # crossings of jumps (alternations of the two moves) before a state holds F1
HALVINGS = 4        # halvings of the leak step that locate the last state holding F1
_MOVES = 40         # solves of one move (each a Newton step on the exact derivative, clipped)
_CUTS = 3           # a solve that fails: the move's largest step quartered, at most this often


def _tol(walk) -> float:
    """|F1 - F1_N| accepted [N]: a tenth of the walk's (rtol of the suction over the rim), so that
    a state holds F1 to rtol of the suction over its seal radius as the walk's Newton roots do."""
    return 0.1 * walk.tolerance


class LetGo(Exception):
    """No state holds F1 with this N: the pull is below F1 and falls as the plate rises."""


def leak_to_hold(walk, prev, dN: float, du_m: float, u_min: float, opened):
    """`leak_and_settle` from prev with the seal closed (`opened(state)` false), dN halved
    HALVINGS times where the cup lets go or the seal opens: (state, "held", the fraction of dN
    taken), or (None, "fold" | "seal opened" | "u_min", 0): the last state holding F1, prev, is
    then the detachment."""
    why, part = "held", 1.0
    for _ in range(HALVINGS + 1):
        s, why = leak_and_settle(walk, prev, part * dN, du_m, u_min)
        if why == "u_min":
            return None, why, 0.0
        if s is not None and not opened(s):
            return s, "held", part
        why = "fold" if s is None else "seal opened"
        part *= 0.5
    return None, why, 0.0


def leak_and_settle(walk, prev, dN: float, du_m: float, u_min: float):
    """The state holding F1 after gas dN [molecules] entered at the held plate from the state
    `prev` (module docstring). Returns (state, why): why "held", "u_min" (the plate reached
    u_min, state None) or "let go" (state None). Raises RuntimeError where a move finds no state."""
    start = walk.solve(prev, prev.u_m, prev.N + dN, walk.move_options)
    try:
        return settle(walk, start, du_m, dN, u_min)
    except LetGo:
        return None, "let go"


def settle(walk, s, du_m: float, dN: float, u_min: float):
    """From the state s (any pull), the plate's response at fixed N and the gas at the held plate
    in turn until the pull is F1 (module docstring); du_m, dN: the largest plate and gas move
    per solve. Returns (state, "held") or (None, "u_min"); raises LetGo, RuntimeError."""
    for crossing in range(CASCADE):
        if abs(s.F1_N - walk.F1) <= _tol(walk):
            return s, "held"
        if crossing:
            walk.snaps += 1
        if s.F1_N < walk.F1:
            s = _move(walk, s, 1, -du_m, u_min)
            if s is None:
                return None, "u_min"
        else:
            s = _move(walk, s, 0, dN, u_min)
    raise RuntimeError(f"F1_N = {walk.F1:g} N: the jumps of the pull did not settle in {CASCADE} "
                       f"crossings (N = {s.N:.6g}, u = {s.u_m * 1e3:.6g} mm)")


def _move(walk, s, k: int, largest: float, u_min: float):
    """Move x (k = 0: N at the held plate, largest > 0; k = 1: the plate position at fixed N,
    largest < 0, up) from s until the pull reaches F1: steps by Newton on the exact dF1/dx,
    clipped to `largest`, each solved from the last state short of F1; a step past F1 brackets
    the crossing, which Illinois regula falsi closes (trials from the near side, every third a
    bisection); a solve that fails quarters the largest step (_CUTS times; it doubles again
    after each solve short of F1). A bracket closed
    to 1e-3 of `largest` without a root is a jump across F1: its far side is returned. None where
    the plate would pass u_min."""
    side = 1.0 if s.F1_N < walk.F1 else -1.0         # the sign of F1 - F1(s): which way is short

    def short(t) -> float:                          # > 0: F1 not reached yet
        return side * (walk.F1 - t.F1_N)

    def at(a, x):
        return walk.solve(a, a.u_m, x, walk.move_options) if k == 0 else \
            walk.solve(a, x, a.N, walk.move_options)

    def x_of(t) -> float:
        return t.N if k == 0 else t.u_m
    a, b, cuts, longest = s, None, 0, largest
    for _ in range(_MOVES):
        miss = a.F1_N - walk.F1
        if abs(miss) <= _tol(walk):
            return a
        d = walk.derivatives(a)[k]
        if k == 1 and side > 0 and not d < 0.0:
            raise LetGo()
        if k == 0 and side < 0 and not d < 0.0:
            raise RuntimeError(f"F1_N = {walk.F1:g} N: the pull is {a.F1_N:.4g} N and more gas "
                               f"does not lower it")
        step = -miss / d
        step = math.copysign(min(abs(step), abs(largest)), largest) if step * largest > 0 else largest
        x = x_of(a) + step
        if k == 1 and x < u_min:
            return None
        try:
            t = at(a, x)
        except RuntimeError:            # no state that far (a slip the step cannot descend):
            if cuts == _CUTS:           # shorter moves, from the same state
                raise
            cuts, largest = cuts + 1, 0.25 * largest
            continue
        if short(t) > _tol(walk):
            a, largest = t, math.copysign(min(2.0 * abs(largest), abs(longest)), longest)
        elif abs(t.F1_N - walk.F1) <= _tol(walk):
            return t
        else:
            b = t
            break
    if b is None:
        raise RuntimeError(f"F1_N = {walk.F1:g} N: the pull stayed at {a.F1_N:.4g} N after "
                           f"{_MOVES} moves")
    fa, fb, last = short(a), short(b), 0
    for i in range(60):
        xa, xb = x_of(a), x_of(b)
        if abs(xa - xb) <= 1e-3 * abs(largest):
            return b                                 # a jump across F1: its far side
        x = 0.5 * (xa + xb) if i % 3 == 2 else xa + (xb - xa) * fa / (fa - fb)
        t = at(a, x)
        f = short(t)
        if abs(t.F1_N - walk.F1) <= _tol(walk):
            return t
        if f > 0.0:
            a, fa = t, f
            fb *= 0.5 if last == 1 else 1.0
            last = 1
        else:
            b, fb = t, f
            fa *= 0.5 if last == -1 else 1.0
            last = -1
    raise RuntimeError(f"F1_N = {walk.F1:g} N: the crossing of F1 not closed between "
                       f"{x_of(a):.6g} and {x_of(b):.6g}")
