"""The paper's stated numbers (validation/data/paper_numbers.toml) and the table beside every paper figure.

`paper_numbers(figure)` reads the numbers the paper's text and Table 1 state for one figure of
the set (`PaperNumber`: value, unit, where the paper states it, the words quoted). `Drawn`
records everything a figure draws, its computed lines and the paper's marks alike, as rows of one
CSV with the columns design, contact, mesh, route, surface (`Study.record`), so that every
drawn value can be read back from a table.
"""

from __future__ import annotations

import functools
import math
import re
import textwrap
import tomllib
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path
from typing import Any

__all__ = ["PaperNumber", "paper_numbers", "all_paper_numbers", "Drawn", "PAPER_ROUTE_LABEL", "NUMBERS_FILE"]

NUMBERS_FILE = Path(str(files("validation") / "data" / "paper_numbers.toml"))
KINDS = ("line", "band", "point", "slope", "input", "claim")
#: the route column of a row that is the paper's stated number, not a computation
PAPER_ROUTE_LABEL = "paper (stated)"
#: the colour of the paper's marks in every figure (black: apart from the computed lines)
MARK_COLOUR = "0.15"


@dataclass(frozen=True)
class PaperNumber:
    """One number the paper states: for `figure`, drawn as `kind` (validation/data/paper_numbers.toml
    says what each kind means); value or lo..hi in `unit`; `source` where the paper states it."""

    figure: str
    kind: str
    label: str
    unit: str
    source: str
    stated: str
    value: float | None = None
    lo: float | None = None
    hi: float | None = None
    x: float | None = None
    x_hi: float | None = None
    axis: str = "y"
    panel: int = 0
    at: float | None = None       # where along the other axis its label sits (axes fraction)


@functools.cache
def all_paper_numbers() -> tuple[PaperNumber, ...]:
    """Every entry of the numbers file, checked: a known kind, a source, the values its kind needs."""
    data = tomllib.loads(NUMBERS_FILE.read_text(encoding="utf-8"))
    out = []
    for i, entry in enumerate(data["numbers"]):
        number = PaperNumber(**entry)
        need = {"line": ("value",), "band": ("lo", "hi"), "point": ("x", "value"), "slope": ("value", "x_hi"),
                "input": ("value",), "claim": ()}.get(number.kind)
        if need is None:
            raise ValueError(f"numbers[{i}].kind: expected one of {', '.join(KINDS)}, got {number.kind!r}")
        missing = [k for k in need if getattr(number, k) is None]
        if missing or not number.source.strip() or not number.stated.strip():
            raise ValueError(f"numbers[{i}] ({number.label}): needs {', '.join(missing) or 'source and stated'}")
        out.append(number)
    return tuple(out)


def paper_numbers(figure: str, kind: str | None = None) -> list[PaperNumber]:
    """The paper's numbers for one figure of the set (of one kind, if given)."""
    return [n for n in all_paper_numbers() if n.figure == figure and (kind is None or n.kind == kind)]


class Drawn:
    """The rows of a figure's table: one per drawn point, with what it was computed for."""

    def __init__(self) -> None:
        self.rows: list[dict[str, Any]] = []

    def line(self, ax, x, y, record: dict[str, str], series: str, x_name: str, y_name: str,
             extra: dict[str, Any] | None = None, **style):
        """Draw y(x) (finite, and positive on log axes) on `ax` and record every point; an `extra`
        column given as a list has one value per point."""
        pts = [(float(a), float(b)) for a, b in zip(x, y) if _shown(ax, a, b)]
        for i, (a, b) in enumerate(zip(x, y)):
            more = {k: v[i] if isinstance(v, list) else v for k, v in (extra or {}).items()}
            self.rows.append({**record, "series": series, x_name: float(a), y_name: float(b), **more})
        if not pts:
            return None
        return ax.plot(*zip(*pts), **style)[0]

    def marks(self, axes, figure: str, x_name: str, y_names: tuple[str, ...]) -> list[PaperNumber]:
        """Draw the paper's numbers for `figure` on `axes` (one per panel) in black, each labelled,
        and record them with their source; return the claims (no drawable number)."""
        claims = []
        for n in paper_numbers(figure):
            if n.kind in ("claim", "input"):
                claims.append(n) if n.kind == "claim" else None
                continue
            ax, y_name = axes[n.panel], y_names[n.panel]
            base = {"route": PAPER_ROUTE_LABEL, "series": n.label, "source": n.source}
            if n.kind == "line":
                name = x_name if n.axis == "x" else y_name
                self.rows.append({**base, name: n.value})
                _line(ax, n.axis, n.value, n.label, n.at)
            elif n.kind == "band":
                name = x_name if n.axis == "x" else y_name
                self.rows += [{**base, name: n.lo}, {**base, name: n.hi}]
                (ax.axvspan if n.axis == "x" else ax.axhspan)(n.lo, n.hi, color=MARK_COLOUR, alpha=0.07, lw=0)
                middle = math.sqrt(n.lo * n.hi) if _log(ax, n.axis) else 0.5 * (n.lo + n.hi)
                _label(ax, n.axis, middle, textwrap.fill(n.label, 20) if n.axis == "y" else n.label, n.at,
                       across=n.axis == "x", centre=n.axis == "y")
            elif n.kind == "point":
                self.rows.append({**base, x_name: n.x, y_name: n.value})
                ax.plot([n.x], [n.value], "*", color=MARK_COLOUR, ms=5, zorder=5)
            elif n.kind == "slope":
                self.rows += [{**base, x_name: 0.0, y_name: 0.0}, {**base, x_name: n.x_hi, y_name: n.value * n.x_hi}]
                ax.plot([0.0, n.x_hi], [0.0, n.value * n.x_hi], ":", color=MARK_COLOUR, lw=1.0,
                        label=re.sub(r"\bum\b", "\u00b5m", n.label))
        return claims

    def columns(self) -> dict[str, list]:
        """The rows as table columns (a value a row does not have: empty)."""
        names: list[str] = []
        for row in self.rows:
            names += [k for k in row if k not in names]
        return {k: [row.get(k, "") for row in self.rows] for k in names}


def _shown(ax, x, y) -> bool:
    x, y = float(x), float(y)
    if not (math.isfinite(x) and math.isfinite(y)):
        return False
    return not ((_log(ax, "x") and x <= 0) or (_log(ax, "y") and y <= 0))


def _log(ax, axis: str) -> bool:
    return (ax.get_xscale() if axis == "x" else ax.get_yscale()) == "log"


def _line(ax, axis: str, value: float, label: str, at: float | None) -> None:
    (ax.axvline if axis == "x" else ax.axhline)(value, color=MARK_COLOUR, ls=":", lw=0.8)
    _label(ax, axis, value, label, at)


def _label(ax, axis: str, value: float, label: str, at: float | None, across: bool = False,
           centre: bool = False) -> None:
    """A small label beside a mark, inside the axes, at `at` (axes fraction) along the other axis: a
    vertical mark's along it (default: hanging from the top; given `at`: rising from it) or,
    `across`, level (default near the bottom); a horizontal mark's above it (default at the left;
    right-aligned past the middle; `centre`: centred on it, a band's label)."""
    label = re.sub(r"\bum\b", "\u00b5m", label)
    if axis == "x" and across:
        ax.text(value, 0.03 if at is None else at, label, transform=ax.get_xaxis_transform(), ha="center",
                va="bottom", fontsize=5, color=MARK_COLOUR)
    elif axis == "x":
        ax.text(value, 0.97 if at is None else at, f" {label} ", transform=ax.get_xaxis_transform(),
                rotation=90, ha="right", va="top" if at is None else "bottom", fontsize=5, color=MARK_COLOUR)
    else:
        at = 0.02 if at is None else at
        ax.text(at, value, label, transform=ax.get_yaxis_transform(), ha="left" if at < 0.5 else "right",
                va="center" if centre else "bottom", fontsize=5, color=MARK_COLOUR)
