"""The report a validation run writes: tables (CSV + Markdown), figures (PNG), notes, summary.json.

Every table is written twice from the same rows, as CSV (units in the column names) and as a
Markdown table inside the section's page, so the numbers in the prose and in the files agree.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["Report", "fmt"]


def fmt(value: Any, digits: int = 4) -> str:
    """A table cell: floats to `digits` significant figures, inf/nan spelled out."""
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return f"{value:.{digits}g}"
    return str(value)


@dataclass
class Report:
    """Collects one run's files under `root` (a temporary directory made atomic by the caller)."""

    root: Path
    pages: dict[str, list[str]] = field(default_factory=dict)
    summary: dict[str, Any] = field(default_factory=dict)
    files: list[str] = field(default_factory=list)

    def text(self, section: str, markdown: str) -> None:
        self.pages.setdefault(section, []).append(markdown.strip() + "\n")

    def table(self, section: str, name: str, columns: Sequence[str], rows: Sequence[Sequence[Any]],
              caption: str = "") -> Path:
        """Write `name`.csv and append the same rows as a Markdown table to the section's page."""
        path = self.root / f"{name}.csv"
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(columns)
            for row in rows:
                w.writerow([fmt(v, 8) if isinstance(v, float) else v for v in row])
        self.files.append(path.name)
        md = [f"**{caption or name}** (`{path.name}`)\n", "| " + " | ".join(columns) + " |",
              "|" + "---|" * len(columns)]
        md += ["| " + " | ".join(fmt(v) for v in row) + " |" for row in rows]
        self.text(section, "\n".join(md))
        return path

    def figure(self, section: str, name: str, fig, caption: str) -> Path:
        """Save a matplotlib figure as `name`.png and reference it from the section's page."""
        from validation.style import save_figure

        path = save_figure(fig, self.root / f"{name}.png", dpi=150)
        self.files.append(path.name)
        self.text(section, f"![{caption}]({path.name})\n\n*{caption}*")
        return path

    def write(self, title: str, order: Sequence[str], headers: dict[str, str]) -> None:
        """Write README.md (all pages in `order`) and summary.json."""
        lines = [f"# {title}\n"]
        for section in order:
            if section in self.pages:
                lines.append(f"## {headers.get(section, section)}\n")
                lines.extend(self.pages[section])
        (self.root / "README.md").write_text("\n".join(lines))
        (self.root / "summary.json").write_text(json.dumps(_finite(self.summary), indent=1,
                                                           sort_keys=True, default=_plain) + "\n")


def _finite(value: Any) -> Any:
    """JSON has no inf/nan: they become null (an infinite lifetime is null, as in `cupcheck lifetime`)."""
    if isinstance(value, dict):
        return {str(k): _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _plain(value: Any) -> Any:
    try:
        return float(value)
    except (TypeError, ValueError):
        return str(value)


def new_figure(ncols: int = 1, nrows: int = 1, width: float = 5.0, height: float = 3.6):
    """A matplotlib figure in the toolkit's style (`validation.style.apply_style`: the Agg backend,
    the style sheet for the rest of the run), `width` x `height` inches per panel."""
    import matplotlib.pyplot as plt

    from validation.style import apply_style

    apply_style()

    return plt.subplots(nrows, ncols, figsize=(width * ncols, height * nrows), constrained_layout=True,
                        squeeze=False)
