"""A scene's figures drawn in a second process while its products are computed.

The figures need none of the FEM and the FEM curve needs no plotting, yet in one process the two
queue: matplotlib's import (~0.3 s) and every figure's drawing wait for the curve and the
lifetimes. `FigureDrawer` forks a drawing process when the run starts; it imports matplotlib while
this process computes, then draws each figure (`validation.scenes.figures.draw`) from its
`FigureInputs`: the products the figure shows, computed here and sent through a pipe. Where fork
is not the platform's way (only Linux forks here) or one processor is all there is, the figures
are drawn in this process, as they are without a drawer.

The drawing process ignores Ctrl-C (this process reports it and ends the drawer); a figure that
fails raises its error here, where `wait` is called; a drawing process that dies is a RuntimeError.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from validation.bridge.study import Study
from validation.scenes.figures import NEEDS, appendix_a_reference, draw

__all__ = ["FigureInputs", "FigureDrawer", "can_fork"]


@dataclass(frozen=True)
class FigureInputs:
    """The products a figure draws, computed (plain data, sent to the drawing process): what
    `validation.bridge.products.Products` would give the figure's function, under the same names."""

    study: Study
    done: Mapping[str, Any] = field(default_factory=dict)      # "lifetimes", "curve", "uc_table"
    appendix: FigureInputs | None = None
    swept: tuple[tuple[Any, FigureInputs], ...] = ()

    @classmethod
    def of(cls, products, needs: tuple[str, ...]) -> FigureInputs:
        """Compute `needs` (a figure's `NEEDS`) of `products`: of every swept value for a sweep,
        the Appendix A-fed reference's lifetimes where the figure draws them."""
        if products.study.sweep is not None:
            own = tuple(n for n in needs if n != "appendix_a")
            return cls(products.study, swept=tuple((v, cls.of(p, own)) for v, p in products.variants()))
        reference = appendix_a_reference(products) if "appendix_a" in needs else None
        return cls(products.study, {n: getattr(products, n)() for n in needs if n != "appendix_a"},
                   None if reference is None else cls.of(reference, ("lifetimes",)))

    def lifetimes(self):
        return self.done["lifetimes"]

    def curve(self):
        return self.done["curve"]

    def uc_table(self):
        return self.done["uc_table"]

    def appendix_a(self) -> FigureInputs | None:
        return self.appendix

    def variants(self) -> list[tuple[Any, FigureInputs]]:
        return list(self.swept)


def can_fork() -> bool:
    """Whether a drawing process can run beside this one: Linux (fork) and two processors or more."""
    return sys.platform.startswith("linux") and len(os.sched_getaffinity(0)) > 1


def _serve(conn) -> None:
    """The drawing process: import the plotting library at once, then draw each job sent until
    None or the pipe's end; answer each with (True, None) or (False, the error)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)          # Ctrl-C is the main process's to report
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    import matplotlib.pyplot  # noqa: F401                 # the import this process is for

    import validation.style  # noqa: F401
    while True:
        try:
            job = conn.recv()
        except EOFError:
            return
        if job is None:
            return
        try:
            draw(*job)
            conn.send((True, None))
        except BaseException as exc:                      # noqa: BLE001 - raised in the main process
            try:
                conn.send((False, exc))
            except Exception:                             # an error that does not pickle
                conn.send((False, RuntimeError(f"{type(exc).__name__}: {exc}")))


class FigureDrawer:
    """Draws a run's figures, in a forked drawing process if `forked` (see the module), else at once
    in this one. `submit` a figure, `wait` for all, `close` always (a context manager)."""

    def __init__(self, forked: bool):
        self._pending: list[str] = []
        self._process = self._conn = None
        if forked:
            context = multiprocessing.get_context("fork")
            self._conn, theirs = context.Pipe()
            self._process = context.Process(target=_serve, args=(theirs,), name="cupcheck-figures", daemon=True)
            # born with Ctrl-C blocked until it ignores it; here a Ctrl-C meanwhile waits, not lost
            blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
            try:
                self._process.start()
            finally:
                signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
            theirs.close()

    @property
    def forked(self) -> bool:
        """Whether the figures are drawn in the drawing process."""
        return self._process is not None

    def submit(self, name: str, products, paths: list[Path], table: Path | None) -> None:
        """Draw the figure `name` of `products` to `paths` and `table` (`validation.scenes.figures.draw`)."""
        if self._process is None:
            draw(name, products, paths, table)
            return
        self._conn.send((name, FigureInputs.of(products, NEEDS[name]), paths, table))
        self._pending.append(name)

    def wait(self) -> None:
        """Every figure submitted is drawn; the first that failed raises its error."""
        while self._pending:
            name = self._pending.pop(0)
            try:
                ok, error = self._conn.recv()
            except (EOFError, OSError):
                self._process.join(1)
                raise RuntimeError(f"figure {name}: the drawing process ended before drawing it "
                                   f"(exit status {self._process.exitcode})") from None
            if not ok:
                raise error

    def close(self) -> None:
        """End the drawing process: at once (nothing more is written) if figures are pending, a
        failed or interrupted run; else after it has read the end of the jobs."""
        if self._process is None:
            return
        process, self._process = self._process, None
        try:
            if not self._pending:
                self._conn.send(None)
                process.join(5)
        except OSError:
            pass
        if process.is_alive():
            process.terminate()
            process.join()
        self._conn.close()
        self._pending.clear()

    def __enter__(self) -> FigureDrawer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
