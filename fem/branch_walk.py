"""The state-to-state machinery of the held branch (`fem.gas_branch`): a trial state reached
from the last state of the branch with the plate and N on a line, the root of F1(u, N) = F1 in N
(or in u) by Newton on the exact sensitivities, regula falsi on the bracket its trials found,
and the jump of the pull where that bracket closes without a root (`fem.branch_root`); the plate
raised at N0 to F1; the fold and the seal's opening located between two states; the branch
measured.

The sensitivities dF1/dN and dF1/du are the linear response of a converged state at the held
plate (`fem.branch_slopes`). With the frictionless law, that response (du/dN, du/du_plate,
`linear_response`) also gives each trial's first Newton iterate (`Walk._predictor`). Coulomb's
trials are solved from the last state of the branch (its anchors are the step's history), and
the first trial of an F1 root from there as Newton goes; its corrections start from that trial's
state and stick/slide set, moved by its response (`Walk._corrects`: 0-1 Newton iterations
instead of 4), and are checked against the step's other solution (`fem.branch_root`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .contact import ContactState
from .gas_path import CupWithGas, GasState
from .solver import ConvergenceError, SolverStats, StepResult
from .cup import _joined
from .branch_root import Jump, PullRoot, Trial
from .branch_slopes import linear_response
from .trapped_gas import GasMechanics, follow_gas_path

__all__ = ["Branch", "Walk", "Trial", "Jump", "STICKING_STEPS", "seal_open", "u_leads"]

STICKING_STEPS = 4  # load steps per move between states for the sticking law (its slips)
PREDICTED_ITERATIONS = 4  # Newton iterations of a Coulomb trial started from another (`Walk._corrects`)


@dataclass(frozen=True, eq=False)
class Branch:
    """The states holding the pull F1_N, the pulled state first (plate raised at N0 to F1), then
    along the plate position; `dN_du` [1/m] per state; the detachment state and its reason
    (module docstring); the cost of the whole branch."""

    F1_N: float
    states: tuple[GasState, ...]
    dN_du: np.ndarray
    detachment: GasState | None       # the fold (largest N) or the state where the seal opened
    reason: str                       # "fold", "seal opened", "u_min", "not held", "stopped <where>: why"
    stats: SolverStats
    snaps: int = 0                    # jumps of the pull crossed (`fem.branch_jumps`)

    @property
    def N_max(self) -> float:
        """The largest N held at F1 (that of the detachment state) [molecules]."""
        return self.detachment.N if self.detachment is not None else float("nan")

    def column(self, name: str) -> np.ndarray:
        """One field of every state as an array, e.g. column("N")."""
        return np.array([getattr(s, name) for s in self.states])


def u_leads(tangent) -> bool:
    """Whether the plate position leads the branch's next move (N the unknown) rather than N. The
    first state's tangent is diagonal by construction (|t_u| = |t_N|): the tie goes to u, not to
    the last bit of round-off, which would pick one of two frictional paths."""
    return abs(tangent[0]) >= (1.0 - 1e-9) * abs(tangent[1])


def seal_open(cup: CupWithGas, s: "Trial") -> bool:
    """Whether no node of the cavity chain is on the plane (the cavity is open to the outside)."""
    x = cup.mesh.doflocs + np.stack([s.step.u[0::2], s.step.u[1::2]])
    return not np.any(cup.cavity.on_plane(x))


class _Crossed(ConvergenceError):
    """Stops a trial's path at the first instability it crosses (`Walk.solve`)."""


class Walk(PullRoot):
    """The state-to-state machinery of `equilibrium_branch`: solves, the F1 root, the costs."""

    def __init__(self, cup: CupWithGas, F1_N: float):
        self.cup, self.F1 = cup, F1_N
        # a move's t is a fraction of the move, not a length: the damped motion across an
        # instability (`fem.newton.relax_step`) moves a node at most as far per sub-step as on the
        # pressing path (0.05 of its range ~ h1), not max_step = 1 of the move "in metres"
        self.options = replace(cup.options, initial_step=1.0, max_step=1.0, relax_move_m=0.05 * cup.h1_m)
        # a trial of the F1 root: cut at most 4 times, a trial that does not converge in 1/16
        # of its move is given up (the walk shortens its step) rather than ground through
        self.trial_options = replace(self.options, min_step=max(cup.options.min_step, 1.0 / 16.0),
                                     max_iterations=min(cup.options.max_iterations, 40))
        law = cup.cup.plane.law
        # a law anchored where its nodes touched down (sticking: anchored, not incremental): its
        # slips land where the load step puts them, every move in STICKING_STEPS steps
        touchdown = law.anchored and not law.incremental
        if touchdown:
            self.options = replace(self.options, initial_step=1.0 / STICKING_STEPS,
                                   max_step=1.0 / STICKING_STEPS)
            self.trial_options = replace(self.trial_options, initial_step=1.0 / STICKING_STEPS,
                                         max_step=1.0 / STICKING_STEPS, min_step=1.0 / (16 * STICKING_STEPS))
        # a move of `fem.branch_jumps` (the leak, the plate's response): given up after a step of
        # 1/16 of its length fails in 100 iterations (the move is then shortened)
        self.move_options = replace(self.options, min_step=max(self.options.min_step, 1.0 / 16.0),
                                    max_iterations=min(self.options.max_iterations, 100))
        self.stats: SolverStats | None = None
        self.snaps = 0
        # an incremental friction law crosses instabilities by damped motion: a trial whose path
        # crosses one has jumped (the state after it is the jump's far side, `_root`)
        self.relaxes = bool(getattr(cup.cup.plane.law, "relaxes", False))
        self.stop_at_crossing = False
        self.staircase = touchdown
        self.slopes: dict[Trial, tuple[float, float]] = {}     # by identity
        # the linear response (du/dN, du/du_plate) of the states whose slopes are known, and the
        # state whose response predicts the next solve's Newton start (`solve`)
        self.responses: dict[Trial, tuple[np.ndarray, np.ndarray]] = {}
        self.predict_from: Trial | None = None
        # only a law without a history (frictionless) starts its trials predicted (`_predictor`)
        self.predicts = bool(cup.cup.plane.law.conservative)
        # Coulomb (incremental: its history is the last state's anchors) predicts only the trials
        # that correct another trial from the same state (`_corrects`; off in `_root`'s second try)
        self.incremental = law.incremental
        self.predicting = True
        rim = cup.mesh.doflocs[0, cup.cavity.nodes[-1]]
        # |F1 - F1_N| accepted: rtol of the largest suction force on the cup, p_a pi r_rim^2 [N]
        self.tolerance = cup.options.rtol * cup.p_a_Pa * math.pi * rim**2

    def derivatives(self, s: Trial) -> tuple[float, float]:
        if s not in self.slopes:
            dF1_dN, dF1_du, x_N, x_u = linear_response(self.cup, s.N, s.step)
            self.slopes[s], self.responses[s] = (dF1_dN, dF1_du), (x_N, x_u)
        return self.slopes[s]

    def slope(self, s: Trial) -> float:
        """dN/du along the branch at s [1/m]."""
        dF1_dN, dF1_du = self.derivatives(s)
        return -dF1_du / dF1_dN

    def tangent(self, s: Trial, du_m: float, N_ref: float, previous) -> tuple[float, float]:
        """The branch's unit tangent at s in (u / du_m, N / N_ref), dF1 = 0: along the previous
        tangent (continuity), or with N rising if there is none."""
        dF1_dN, dF1_du = self.derivatives(s)
        t = np.array([dF1_dN * N_ref, -dF1_du * du_m])
        t /= np.linalg.norm(t)
        if (previous is None and t[1] < 0.0) or (previous is not None and t @ previous < 0.0):
            t = -t
        return float(t[0]), float(t[1])

    def solve(self, start: Trial, u_m: float, N: float, options=None) -> Trial:
        """The state at (u_m, N), reached from `start` with the plate and N on a line; its
        `crossed` is the state after the first instability the path crossed by damped motion
        (a law that `relaxes`), where the path stops while `stop_at_crossing` is set (`_root`)."""
        stop_at_crossing, caller_options = self.stop_at_crossing, options
        u0, N0 = start.u_m, start.N
        mech = GasMechanics(self.cup.cup.mech, self.cup.cavity, self.cup._gas(N0),
                            schedule=lambda t: N0 + t * (N - N0), relaxes=True)
        top = self.cup.cup.top
        dofs, zeros = np.concatenate([2 * top, 2 * top + 1]), np.zeros(top.size)

        def plate(t):
            return dofs, np.concatenate([zeros, np.full(top.size, -(u0 + t * (u_m - u0)))])
        last: list[StepResult] = []

        def on_step(step: StepResult) -> None:
            last.append(step)
            if stop_at_crossing and self.relaxes and step.unstable:
                raise _Crossed("the path crossed an instability")
        corrects = self._corrects(start)
        options = options or self.options
        if corrects:            # one step, given up early: it is solved again from `start` alone
            options = replace(options, max_iterations=min(options.max_iterations, PREDICTED_ITERATIONS),
                              min_step=1.0)
        try:
            stats = follow_gas_path(mech, plate, 1.0, plane=self.cup.cup.plane, start=self._start(start),
                                    options=options, on_step=on_step,
                                    predict=self._predictor(start, u_m, N))
        except _Crossed as stop:
            stats = stop.stats
        except ConvergenceError as err:         # the cost of a failed trial counts too
            self._count(err.stats)
            if corrects:
                return self._unpredicted(start, u_m, N, caller_options)
            raise
        self._count(stats)
        if corrects and not self._same_set(last):
            # the set changed (a node landed, one more let go, a slide turned): another solution
            # of the step may have been found than the one `start` leads to; solved again from it
            return self._unpredicted(start, u_m, N, caller_options)

        def trial(step: StepResult, f: float) -> Trial:
            at_end = f >= 1.0
            return Trial(float(u_m if at_end else u0 + f * (u_m - u0)),
                          float(N if at_end else N0 + f * (N - N0)),
                          float(np.sum(step.r_int[2 * top + 1])), step)
        crossed = next((st for st in last if st.unstable), None) if self.relaxes else None
        end = replace(trial(last[-1], last[-1].t), predicted=corrects)
        if crossed is not None:
            return replace(end, crossed=end if crossed is last[-1] else trial(crossed, crossed.t))
        return end

    def _same_set(self, path: list[StepResult]) -> bool:
        """Whether a predicted trial's path (`_corrects`) ended on its start's stick/slide set
        (the last trial's) in one stable step."""
        if len(path) != 2 or path[-1].unstable:
            return False
        a, b = path[0].contact, path[-1].contact
        return bool(np.array_equal(a.active, b.active) and np.array_equal(a.slip, b.slip))

    def _unpredicted(self, start: Trial, u_m: float, N: float, options) -> Trial:
        """`solve` from `start` alone (no started Newton iterate)."""
        base, self.predict_from = self.predict_from, None
        try:
            return self.solve(start, u_m, N, options)
        finally:
            self.predict_from = base

    def _solve_from(self, base: Trial, start: Trial, u_m: float, N: float, options=None) -> Trial:
        """`solve` with its Newton starts predicted by `base`'s linear response (`_predictor`)."""
        self.predict_from = base
        try:
            return self.solve(start, u_m, N, options)
        finally:
            self.predict_from = None

    def _start(self, start: Trial) -> StepResult:
        """The path's start state: `start`'s, with the contact set of `predict_from` where the law
        carries no history (frictionless: the state does not depend on the path, and the Newton
        then starts from the predicting state's contact set as from its displacement); Coulomb's
        correcting trials (`_corrects`) start from the last trial's stick/slide set with
        `start`'s anchors (its history)."""
        base = self.predict_from
        if base is None or base is start or base not in self.responses:
            return start.step
        if self.predicts:
            return replace(start.step, contact=base.step.contact)
        if self._corrects(start):
            held, set_ = start.step.contact, base.step.contact
            return replace(start.step, contact=ContactState(set_.active, held.u_r_stick_m, set_.slip))
        return start.step

    def _corrects(self, start: Trial) -> bool:
        """Whether a trial of an incremental law (Coulomb) starts from the last trial
        (`predict_from`, reached from the same `start` to a nearby end, whose linear response is
        known): its displacement moved by that response, its stick/slide set, `start`'s anchors.
        Only where the last trial landed no node (it may have let some go): a landing node's
        anchor (its touchdown) is the path's, not the last trial's. `solve` takes the trial only
        on that set in one step of at most PREDICTED_ITERATIONS, else solves it again from
        `start` alone; `_root` checks the roots so found against the others' trials."""
        base = self.predict_from
        if not (self.incremental and self.predicting) or base is None or base is start \
                or base not in self.responses:
            return False
        return not np.any(base.step.contact.active & ~start.step.contact.active)

    def _predictor(self, start: Trial, u_m: float, N: float):
        """Each load step's first Newton iterate on the line from `start` to (u_m, N): the linear
        response of `predict_from` (a state whose slopes are known, e.g. the last trial of an F1
        root) to the change of plate and N, from that state for the first step and from the last
        converged one after it; None (Newton from the last converged state) without one, and for
        a law with a history (sticking, Coulomb) from `start` itself: there the iterate picks
        among the stick/slide sets, and a predicted start moved a lifetime by more than the step
        error, and cost more. Coulomb's corrections of a trial start from that trial
        (`_corrects`): the same step's solution nearby, on its set."""
        base = self.predict_from
        response = self.responses.get(base) if base is not None else None
        if response is None or not (self.predicts or self._corrects(start)):
            return None
        x_N, x_u = response
        u0, N0 = start.u_m, start.N

        def predict(t0: float, u_t0: np.ndarray, t1: float) -> np.ndarray:
            u1, N1 = u0 + t1 * (u_m - u0), N0 + t1 * (N - N0)
            if t0 == 0.0:
                return base.step.u + (u1 - base.u_m) * x_u + (N1 - base.N) * x_N
            return u_t0 + ((t1 - t0) * (u_m - u0)) * x_u + ((t1 - t0) * (N - N0)) * x_N
        return predict

    def _count(self, stats: SolverStats | None) -> None:
        if stats is not None:
            self.stats = stats if self.stats is None else _joined(self.stats, stats)

    def pull_to_force(self, sealed: Trial, du_m: float, u_min: float) -> Trial | None:
        """Raise the plate at fixed N from `sealed` until the pull is F1: steps up of at most du_m
        (Newton's with the exact dF1/du where it points up), each from the last state pulling
        less than F1; a step that overshoots brackets the crossing, which regula falsi (Illinois)
        closes. None if the plate reaches u_min or the seal opens first. The plate never moves
        down: with friction a back-and-forth would enter the history."""
        a, b = sealed, None
        while b is None:
            miss = a.F1_N - self.F1
            if abs(miss) <= self.tolerance:
                return a
            dF1_du = self.derivatives(a)[1]
            step = -miss / dF1_du if dF1_du < 0.0 else -du_m
            u_new = a.u_m + float(np.clip(step, -du_m, -1e-6 * du_m))
            if u_new < u_min:
                return None
            s = self._solve_from(a, a, u_new, a.N)
            if seal_open(self.cup, s):          # the seal opened before the pull reached F1
                return None
            if s.F1_N - self.F1 > self.tolerance:
                b = s
            else:
                a = s
        fa, fb, side = a.F1_N - self.F1, b.F1_N - self.F1, 0
        for _ in range(60):
            u = b.u_m + (a.u_m - b.u_m) * fb / (fb - fa)
            s = self._solve_from(a, a, u, a.N)
            f = s.F1_N - self.F1
            if abs(f) <= self.tolerance:
                return s
            if f < 0.0:
                a, fa = s, f
                fb *= 0.5 if side == -1 else 1.0
                side = -1
            else:
                b, fb = s, f
                fa *= 0.5 if side == 1 else 1.0
                side = 1
        raise RuntimeError(f"F1_N = {self.F1:g} N: the pull at fixed N0 not closed between "
                           f"u = {b.u_m * 1e3:.6g} and {a.u_m * 1e3:.6g} mm")

    def opening(self, closed: Trial, opened: Trial, tangent, halvings: int = 6) -> Trial:
        """The last state with the seal closed between `closed` and `opened` (bisection on the
        line between them, each trial from `closed`, to 2^-halvings of their distance)."""
        for _ in range(halvings):
            u, N = 0.5 * (closed.u_m + opened.u_m), 0.5 * (closed.N + opened.N)
            try:
                s = self.hold(closed, u, N) if u_leads(tangent) else \
                    self.hold_u(closed, u, N)
            except RuntimeError:
                opened = Trial(u, N, math.nan, opened.step)
                continue
            if seal_open(self.cup, s):
                opened = s
            else:
                closed = s
        return closed

    def fold(self, a: Trial, ka: float, b: Trial, kb: float) -> Trial:
        """The state between a and b where dN/du = 0 on the branch (secant on dN/du)."""
        s = b
        for _ in range(8):
            u = b.u_m + (a.u_m - b.u_m) * kb / (kb - ka)
            try:
                s = self.hold(a, u, a.N + ka * (u - a.u_m))
            except RuntimeError:        # no state there (a jump): the last one found
                return s
            k = self.slope(s)
            if abs(k) <= 1e-3 * max(abs(ka), abs(kb)) or abs(u - a.u_m) < 1e-9 * self.cup.h1_m:
                return s
            if (k > 0.0) == (kb > 0.0):
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
                      None if detachment is None else states[id(detachment)], reason, self.stats,
                      self.snaps)
