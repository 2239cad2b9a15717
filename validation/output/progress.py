"""Progress on a terminal: one redrawn line, or a plain line per tenth off a terminal."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

#: progress callback used by long computations: progress(fraction_done in [0, 1], message)
Progress = Callable[[float, str], None]


def terminal_progress(label: str, stream=None, min_interval_s: float = 0.2) -> Progress:
    """A `Progress` callback that redraws one status line on a terminal (stderr by default).

    When the stream is not a terminal (CI, pipes) it prints a plain line at most every ~10 %.
    """
    stream = stream or sys.stderr
    tty = stream.isatty()
    state = {"t": 0.0, "decile": -1}

    def report(fraction: float, message: str) -> None:
        now = time.monotonic()
        fraction = min(max(fraction, 0.0), 1.0)
        if tty:
            if now - state["t"] < min_interval_s and fraction < 1.0:
                return
            state["t"] = now
            end = "\n" if fraction >= 1.0 else ""
            stream.write(f"\r{label}: {100 * fraction:5.1f}% {message}\033[K{end}")
        else:
            decile = int(10 * fraction)
            if decile == state["decile"]:
                return
            state["decile"] = decile
            stream.write(f"{label}: {100 * fraction:5.1f}% {message}\n")
        stream.flush()

    return report
