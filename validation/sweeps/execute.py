"""Running a sweep on dask.distributed, resumably: one committed result file per design.

The scheduler is dask's: a `LocalCluster` of single-threaded worker processes by default, or an
existing cluster by address. Each design is one task (`evaluate_design`). The client writes a
design's rows the moment its task completes, atomically, to ``DIR/designs/<hash>.json``; a sweep
run again computes only the designs without such a file (``retry_failed``: also those whose rows
carry a failure), so a killed sweep loses at most the designs that were running, never a row and
never a duplicate. A worker that dies is replaced by the cluster and its task retried once
(`distributed.scheduler.allowed-failures` = 1); a second death becomes the design's failure row.
The tidy table (``results.parquet`` through pyarrow, and ``results.csv``) is assembled from the
design files at the end, one row per design and force.
"""

from __future__ import annotations

import json
import os
import secrets
import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from validation.sweeps.evaluate import evaluate_design
from validation.sweeps.spec import SweepSpec, design_hash

__all__ = ["SweepRun", "run_sweep", "collect_table", "pending_designs"]


@dataclass(frozen=True)
class SweepRun:
    """What one call did: designs in the sweep, computed now, found done, failed; the wall time."""

    designs: int
    computed: int
    reused: int
    failed: int
    wall_s: float
    startup_s: float           # starting the local cluster and connecting (0 when nothing ran)
    table: Path
    dashboard: str | None


def pending_designs(spec: SweepSpec, out: Path, retry_failed: bool = False) -> list[dict[str, Any]]:
    """The designs of `spec` without a committed result in `out` (or with a failed one, if asked)."""
    todo = []
    for design in spec.designs():
        path = _design_file(out, design)
        if path.is_file():
            if not retry_failed or not any(row.get("failure") for row in _read_rows(path)):
                continue
        todo.append(design)
    return todo


def run_sweep(spec: SweepSpec, out: str | Path, *, workers: int | None = None,
              scheduler: str | None = None, retry_failed: bool = False,
              progress: Callable[[int, int, int, str], None] | None = None,
              evaluate: Callable[[dict[str, Any]], list[dict[str, Any]]] = evaluate_design) -> SweepRun:
    """Evaluate every pending design of `spec` on dask and write the table into `out`.

    progress(done, failed, total, message) is called as designs complete; `evaluate` is the unit
    of work (`evaluate_design`; another function of a design returning rows, e.g. in tests).
    """
    import dask
    from distributed import Client, LocalCluster, as_completed

    out = Path(out)
    (out / "designs").mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    all_designs = spec.designs()
    todo = pending_designs(spec, out, retry_failed)
    computed = failed = 0
    dashboard, startup = None, 0.0
    if todo:
        cluster = client = None
        with dask.config.set({"distributed.scheduler.allowed-failures": 1}):
            try:
                with _ctrl_c_held():
                    cluster = None if scheduler else LocalCluster(
                        n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                        dashboard_address=":0", silence_logs=40)
                    client = Client(scheduler or cluster)
                dashboard, startup = client.dashboard_link, time.perf_counter() - t0
                futures = {client.submit(evaluate, d, key=f"design-{design_hash(d)}", pure=False): d
                           for d in todo}
                for future in as_completed(futures):
                    design = futures[future]
                    rows = _rows_of(future, design)
                    _commit(out, design, rows)
                    computed += 1
                    failed += any(r.get("failure") for r in rows)
                    if progress:
                        progress(computed, failed, len(todo), design_hash(design))
            finally:
                _shut_down(client, cluster)
    table = collect_table(spec, out)
    return SweepRun(designs=len(all_designs), computed=computed, reused=len(all_designs) - len(todo),
                    failed=failed, wall_s=time.perf_counter() - t0, startup_s=startup, table=table,
                    dashboard=dashboard)


@contextmanager
def _ctrl_c_held() -> Iterator[None]:
    """Start the cluster with Ctrl-C held back: SIGINT is ignored, so the worker processes spawned
    now start ignoring it (a Ctrl-C reaching the process group while a worker still imports dask,
    before its preload `validation.sweeps.worker` runs, would print that worker's traceback), and
    blocked in this thread, so a Ctrl-C meanwhile stays pending and lands here on leaving, once
    the cluster exists to be shut down. multiprocessing's resource tracker unblocks SIGINT after
    starting, so it is started first."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    from multiprocessing import resource_tracker
    resource_tracker.ensure_running()
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    handler = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, handler)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def _shut_down(client, cluster) -> None:
    """Close the client and the local cluster. Every finished design is committed by then, so a
    cluster that does not stop cleanly (a nanny still restarting a killed worker) is reported on
    stderr, not raised: it must not turn a finished sweep into a failed one."""
    import sys
    for close in (part.close for part in (client, cluster) if part is not None):
        try:
            close()
        except Exception as exc:      # noqa: BLE001 - shutdown only, results already on disk
            print(f"sweep: warning: the dask cluster did not shut down cleanly ({type(exc).__name__}: "
                  f"{exc})", file=sys.stderr)


def collect_table(spec: SweepSpec, out: Path) -> Path:
    """results.parquet and results.csv from the committed design files (in the sweep's order)."""
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    rows = []
    for design in spec.designs():
        path = _design_file(out, design)
        if path.is_file():
            rows.extend(_read_rows(path))
    columns: dict[str, list] = {}
    for row in rows:
        for key in row:
            columns.setdefault(key, [])
    table = pa.table({k: [row.get(k) for row in rows] for k in columns})
    for name, writer in (("results.parquet", pq.write_table), ("results.csv", pacsv.write_csv)):
        tmp = out / f".{name}.{secrets.token_hex(4)}.tmp"
        writer(table, tmp)
        os.replace(tmp, out / name)
    return out / "results.parquet"


def _rows_of(future, design: dict[str, Any]) -> list[dict[str, Any]]:
    """The task's rows, or failure rows if the task itself died (its worker, twice)."""
    try:
        return future.result()
    except Exception as exc:          # KilledWorker, a scheduler error: the design's failure, not the sweep's
        reason = f"worker: {type(exc).__name__}: {' '.join(str(exc).split())[:200]}"
        base = {k: v for k, v in design.items() if k not in ("F1_N", "F0_at_u_mm", "allow_unusual_design")}
        return [{**base, "design_hash": design_hash(design), "F1_N": F, "failure": reason}
                for F in design["F1_N"]]


def _design_file(out: Path, design: dict[str, Any]) -> Path:
    return out / "designs" / f"{design_hash(design)}.json"


def _commit(out: Path, design: dict[str, Any], rows: list[dict[str, Any]]) -> None:
    """Write a design's rows atomically (temporary file, fsync, rename)."""
    path = _design_file(out, design)
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(4)}.tmp")
    with open(tmp, "w") as f:
        json.dump(rows, f, default=float, allow_nan=False)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _read_rows(path: Path) -> list[dict[str, Any]]:
    return json.loads(path.read_text())
