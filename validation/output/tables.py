"""Plain CSV tables, every column guarded against NaN."""

from __future__ import annotations

import csv
import os
from pathlib import Path

#: columns whose infinite values mean something (an infinite lifetime: sealed or beyond the
#: horizon; an unbounded strip pressure: a line contact; an unbounded leak rate: the gas holds the
#: seal open; the time at which a sealed state is reached); NaN is refused everywhere
INFINITE_OK = ("lifetime_s", "p_Pa", "N_dot_per_s", "Q_w_mm3_per_s", "t_s")


def check_finite(name: str, values, stage: str, infinite_ok: bool = False) -> None:
    """The one guard every public output passes: no NaN (and no inf unless it means something);
    a RuntimeError naming the column and the stage that produced it."""
    import numpy as np

    arr = np.asarray(values, dtype=object)
    numbers = np.array([float(v) for v in arr.ravel() if isinstance(v, (int, float)) and not isinstance(v, bool)])
    bad = np.isnan(numbers) | (np.isinf(numbers) & (not infinite_ok))
    if bad.any():
        raise RuntimeError(f"{stage}: column {name} has {int(bad.sum())} non-finite value(s) "
                           f"({numbers[bad][0]}): refusing to write it")


def write_table(path: str | os.PathLike, columns: dict[str, object], stage: str = "output") -> Path:
    """A plain CSV: one header line (units in the names), then rows; numbers as %.10g, text quoted
    only where it must be. No comment lines, so pandas.read_csv and numpy.genfromtxt read it as is.

    `columns` maps each name to a sequence (all of one length) or to one value repeated (a label).
    Every column passes `check_finite` (`stage` names what produced it).
    """
    for name, values in columns.items():
        if not isinstance(values, str):
            check_finite(name, [values] if isinstance(values, (int, float)) else values, stage,
                         infinite_ok=name in INFINITE_OK)
    lengths = {len(v) for v in columns.values() if not isinstance(v, (str, int, float))}
    if len(lengths) > 1:
        raise ValueError(f"write_table: columns of different lengths {sorted(lengths)}")
    n = lengths.pop() if lengths else 1
    cells = [[v] * n if isinstance(v, (str, int, float)) else list(v) for v in columns.values()]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for row in zip(*cells):
            w.writerow([x if isinstance(x, str) else f"{float(x):.10g}" for x in row])
    return Path(path)
