"""The sweep's dask workers leave Ctrl-C to the command that started them.

A terminal's Ctrl-C reaches every process of its group: the `cupcheck sweep` process, which
reports "interrupted" in one line and shuts its cluster down, and each worker process, whose
asyncio runner would print its own KeyboardInterrupt traceback (some 30 lines per worker). As a
dask preload (``distributed.worker.preload``, `PRELOAD`), this module makes each worker ignore
SIGINT as it starts; the workers still end with the cluster.
"""

from __future__ import annotations

import signal

__all__ = ["PRELOAD", "dask_setup"]

#: the dask configuration that loads this module into every worker
PRELOAD = {"distributed.worker.preload": ["validation.sweeps.worker"]}


def dask_setup(worker: object = None) -> None:
    """Ignore SIGINT in this worker process (dask calls this when the worker starts)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
