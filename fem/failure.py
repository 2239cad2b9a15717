"""Why the Newton iteration of one load step gave up.

`StepFailure` travels from the factorization, the contact step, the line search and the
convergence test up to `fem.solver.follow_path`, which cuts the step back (or, at the smallest
step, raises the public `fem.solver.ConvergenceError` with its cause and history).
"""

from __future__ import annotations

__all__ = ["StepFailure", "NoContactSet"]


class StepFailure(Exception):
    """A load step failed: the likely `cause` (one line), the residual `history` of its
    iterations, and whether the tangent was `indefinite` on the way (a structural instability,
    across which the path tries to jump)."""

    def __init__(self, cause: str, history: list[float], indefinite: bool = False):
        super().__init__(cause)
        self.cause, self.history, self.indefinite = cause, history, indefinite


class NoContactSet(StepFailure):
    """Coulomb's linearized contact problem found no stick/slide set, iteration after iteration:
    the incremental frictional problem has no solution at this step (Klarbring), which damping
    the slip restores (`fem.newton.relax_step`)."""
