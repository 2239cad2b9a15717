"""A rendered 3D image placed pixel for pixel in a matplotlib figure of the toolkit's style: its
title above, its colour bar (name, unit in a sensible magnitude, the quantity's colormap) to the
right and a length scale bar on it. All text is matplotlib's, so nothing is clipped and every
image can be measured: `Placed` says where the render sits in the PNG and how long a pixel is.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from validation import style

__all__ = ["ColourKey", "Placed", "compose", "DPI"]

#: the dots per inch of the composed PNGs (a render pixel is one PNG pixel)
DPI = 150


@dataclass(frozen=True)
class ColourKey:
    """A colour bar: the quantity (`validation.style.QUANTITIES`) and its range [SI]."""

    quantity: str
    clim_si: tuple[float, float]

    def unit(self) -> style.DisplayUnit:
        q = style.quantity(self.quantity)
        return style.display_unit(q.si_unit, max(abs(self.clim_si[0]), abs(self.clim_si[1])))


@dataclass(frozen=True)
class Placed:
    """A composed image: its path, the length of one pixel [m] (in the render's image plane), the
    box (col0, row0, col1, row1) of the render in the PNG, and the scale bar's length [m]."""

    path: Path
    m_per_px: float
    view_box_px: tuple[int, int, int, int]
    scale_bar_m: float


def compose(image: np.ndarray, png: str | Path, *, m_per_px: float, title: str = "",
            colour: ColourKey | None = None, bar_fraction: float = 0.2) -> Placed:
    """Write `image` (rows x cols x 3, a render whose pixel is `m_per_px` long) to `png` with the
    title, the colour bar of `colour` and a scale bar of about `bar_fraction` of its width."""
    import matplotlib.pyplot as plt
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    rows, cols = image.shape[:2]
    inch = DPI
    lines = max(1, title.count("\n") + 1) if title else 0
    top = int(round(0.06 * inch + lines * 0.16 * inch))
    right = int(round(0.95 * inch)) if colour else int(round(0.05 * inch))
    left = bottom = int(round(0.05 * inch))
    width, height = cols + left + right, rows + top + bottom
    bar_m = style.nice_length(bar_fraction * cols * m_per_px)
    with style.cupcheck_style():
        fig = plt.figure(figsize=(width / inch, height / inch), dpi=inch, layout="none")
        ax = fig.add_axes((left / width, bottom / height, cols / width, rows / height))
        w_mm, h_mm = 1e3 * cols * m_per_px, 1e3 * rows * m_per_px
        ax.imshow(image, extent=(0.0, w_mm, 0.0, h_mm), interpolation="none", origin="upper")
        ax.set_axis_off()
        style.scale_bar(ax, bar_m)
        if colour:
            unit = colour.unit()
            lo, hi = (unit.factor * v for v in colour.clim_si)
            cax = fig.add_axes(((left + cols + 0.08 * inch) / width, (bottom + 0.1 * rows) / height,
                                0.1 * inch / width, 0.8 * rows / height))
            mappable = ScalarMappable(Normalize(lo, hi), style.quantity(colour.quantity).cmap)
            style.colorbar(fig, mappable, colour.quantity, unit, cax=cax)
        if title:
            text = fig.text(0.5, 1 - 0.04 * inch / height, title, ha="center", va="top")
            _fit(fig, text)
        fig.canvas.draw()
        x0, y0 = ax.transData.transform((0.0, 0.0))
        x1, _ = ax.transData.transform((w_mm, 0.0))
        placed_m_per_px = 1e-3 * w_mm / (x1 - x0)
        box = (int(round(x0)), int(round(height - y0 - rows)), int(round(x0)) + cols, int(round(height - y0)))
        path = style.save_figure(fig, png, dpi=inch)
    return Placed(path=path, m_per_px=placed_m_per_px, view_box_px=box, scale_bar_m=bar_m)


def _fit(fig, text) -> None:
    """Shrink a figure text (down to 5 pt) until it fits the canvas's width."""
    renderer = fig.canvas.get_renderer()
    while text.get_window_extent(renderer).width > 0.98 * fig.bbox.width and text.get_fontsize() > 5:
        text.set_fontsize(text.get_fontsize() - 0.5)
