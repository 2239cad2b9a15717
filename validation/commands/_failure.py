"""A solver failure as the command line reports it: one short line, the full record in a log file."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any


def failure_record(exc: Exception, log_path: Path) -> dict[str, Any]:
    """Write the record of a `fem.solver.ConvergenceError` to `log_path` (JSON: the error, the step,
    its u range in mm, the cause, the residual history of the last attempt) and return it."""
    record = {"error": str(exc), "step": getattr(exc, "step", None),
              "u_from_mm": 1e3 * getattr(exc, "t_from", float("nan")),
              "u_to_mm": 1e3 * getattr(exc, "t_to", float("nan")),
              "cause": getattr(exc, "cause", ""), "residual_history": list(getattr(exc, "history", ()))}
    log_path.parent.mkdir(parents=True, exist_ok=True)
    log_path.write_text(json.dumps(record, indent=1) + "\n")
    return record


def solver_failure(exc: Exception, log_path: Path) -> RuntimeError:
    """The one-line error for a `fem.solver.ConvergenceError` (u in mm, the last residual, the
    likely cause); its whole residual history goes to `log_path` (JSON), which the line names."""
    record = failure_record(exc, log_path)
    history = record["residual_history"]
    if not history:      # a converged state refused (fem.integrity.StateRejected): where and why
        return RuntimeError(f"stopped {exc}; the record is in {log_path}")
    return RuntimeError(f"load step {record['step']} from u = {record['u_from_mm']:.4g} to "
                        f"{record['u_to_mm']:.4g} mm did not converge (residual {history[-1]:.2e} after "
                        f"{len(history)} Newton iterations): {record['cause']}; the residual "
                        f"history is in {log_path}")
