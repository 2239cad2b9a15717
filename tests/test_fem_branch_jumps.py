"""`fem.branch_jumps`: the held pull and the leak moving the cup across jumps of the pull, on a
model pull F1(u, N) with jumps (no FEM: the rule alone, each check against the model's own
exact answer).

The model: the pull rises as the plate rises (u falls) and falls as gas enters, F1 = k (u0 - u)
- c (N - N0), plus the jumps the test puts in. A state holding F1 is where that equals F1."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from fem.branch_jumps import CASCADE, HALVINGS, LetGo, leak_and_settle, leak_to_hold, settle

K, C, F1 = 2.0e4, 1.0, 10.0         # N/m, N per molecule (scaled), N


@dataclass(frozen=True)
class State:
    u_m: float
    N: float
    F1_N: float


class Walk:
    """The interface `fem.branch_jumps` asks of the walk: solve, derivatives, F1, tolerance."""

    def __init__(self, pull, slope_u=lambda u, N: -K):
        self.pull, self.slope_u = pull, slope_u
        self.F1, self.tolerance, self.snaps, self.move_options = F1, 1e-9, 0, None
        self.solves = 0

    def solve(self, start, u_m, N, options=None):
        self.solves += 1
        return State(u_m, N, self.pull(u_m, N))

    def derivatives(self, s):
        return -C, self.slope_u(s.u_m, s.N)


def smooth(u, N):
    return K * (1e-3 - u) - C * N


def test_a_smooth_pull_is_restored_by_the_plate_at_fixed_N():
    """Below F1 the plate rises at fixed N to the exact root; no jump is counted."""
    walk = Walk(smooth)
    s, why = settle(walk, State(1e-3, 0.0, smooth(1e-3, 0.0)), 0.25e-3, 1.0, -1.0)
    assert why == "held" and s.N == 0.0
    assert s.u_m == pytest.approx(1e-3 - F1 / K, abs=1e-12) and walk.snaps == 0


def test_an_upward_jump_across_F1_is_crossed_and_the_gas_restores_the_pull():
    """The plate's rise meets a jump of the pull from below F1 to above it (at u_j): the move
    ends just past the jump, then gas enters at the held plate until the pull is F1: one crossing,
    the state at the jump's plate position within the move's resolution and at the gas amount
    that brings the jumped pull back to F1."""
    u_j, up = 1e-3 - 0.9 * F1 / K, 3.0           # the pull jumps by +3 N as the plate passes u_j

    def pull(u, N):
        return smooth(u, N) + (up if u < u_j else 0.0)
    walk = Walk(pull)
    s, why = settle(walk, State(1e-3, 0.0, pull(1e-3, 0.0)), 0.25e-3, 1.0, -1.0)
    assert why == "held" and walk.snaps == 1
    assert abs(s.u_m - u_j) <= 1e-3 * 0.25e-3
    assert s.N == pytest.approx((K * (1e-3 - s.u_m) + up - F1) / C, rel=1e-9)


def test_the_cup_lets_go_where_the_pull_falls_as_the_plate_rises():
    """The pull at fixed N has its maximum below F1: past it (dF1/du >= 0) no state holds F1 in
    the direction the cup moves; `leak_and_settle` says so (no state)."""
    top = 1e-3 - 0.5 * F1 / K                   # the pull's maximum (0.5 F1) as the plate rises

    def pull(u, N):
        return K * (1e-3 - u) - C * N if u > top else 0.5 * F1 - K * (top - u)
    walk = Walk(pull, slope_u=lambda u, N: -K if u > top else K)
    with pytest.raises(LetGo):
        settle(walk, State(1e-3, 0.0, pull(1e-3, 0.0)), 0.25e-3, 1.0, -1.0)
    s, why = leak_and_settle(walk, State(1e-3, 0.0, F1), 1.0, 0.25e-3, -1.0)
    assert s is None and why == "let go"


def test_the_plate_stops_at_u_min():
    walk = Walk(smooth)
    s, why = settle(walk, State(1e-3, 0.0, smooth(1e-3, 0.0)), 0.25e-3, 1.0, 1e-3 - 0.1 * F1 / K)
    assert s is None and why == "u_min"


def test_jumps_that_never_settle_end_with_a_named_reason():
    """A pull that jumps back across F1 wherever either move goes (each move ends past a jump)
    stops after CASCADE crossings with an error naming why, not a state."""
    def pull(u, N):
        return F1 + (1.0 if (walk.solves % 2) else -1.0)
    walk = Walk(pull)
    with pytest.raises(RuntimeError, match="did not settle"):
        settle(walk, State(1e-3, 0.0, F1 - 1.0), 0.25e-3, 1.0, -1.0)
    assert walk.snaps == CASCADE - 1


def test_the_leak_step_is_halved_to_the_last_state_holding_F1():
    """Beyond N_go no state holds F1 (the cup lets go): a leak step past it is halved until a
    state holds F1 (the fraction taken is returned), and where even HALVINGS halvings pass N_go,
    the cup lets go from the state it was in ("fold", no state)."""
    N_go = 0.3

    def pull(u, N):
        return smooth(u, N) if N <= N_go else 0.5 * F1
    walk = Walk(pull, slope_u=lambda u, N: -K if N <= N_go else K)
    start = State(1e-3 - F1 / K, 0.0, F1)
    s, why, part = leak_to_hold(walk, start, 1.0, 0.25e-3, -1.0, lambda t: False)
    assert why == "held" and part == 0.25 and s.N == 0.25
    assert s.F1_N == pytest.approx(F1, abs=1e-9)
    assert 100.0 * 0.5 ** HALVINGS > N_go
    s, why, part = leak_to_hold(walk, start, 100.0, 0.25e-3, -1.0, lambda t: False)
    assert (s, why, part) == (None, "fold", 0.0)
    s, why, part = leak_to_hold(walk, start, 0.25, 0.25e-3, -1.0, lambda t: True)
    assert (s, why) == (None, "seal opened")
