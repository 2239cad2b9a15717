"""One look for every figure of the toolkit: the style sheet, readable log axes, colour bars in a
sensible unit, one colormap per quantity, and a length scale bar.

* `cupcheck_style()` (a context) or `apply_style()`: the package's matplotlib style sheet
  (`validation/data/cupcheck.mplstyle`: a journal column, 8 pt text, constrained layout);
* `log_axis` / `readable_log_axes`: log ticks as plain numbers (20, 50, 100 rather than 2x10^1),
  at least three of them when the range allows, chosen at draw time from the view limits;
* `QUANTITIES` / `display_unit`: per physical quantity its name, SI unit and perceptually uniform
  colormap, and the SI prefix that puts a range's largest value in [1, 1000) (0.75 / 1.50 MPa,
  never 1.48e+03 kPa);
* `colorbar`, `scale_bar`, `save_figure`: the colour bar labelled "name (unit)", a 1-2-5 scale bar
  of a known length, and the one way figures are written (log axes made readable, then closed).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

import numpy as np

__all__ = ["STYLE_SHEET", "COLUMN_WIDTH_IN", "cupcheck_style", "apply_style", "Quantity", "QUANTITIES",
           "quantity", "DisplayUnit", "display_unit", "ReadableLogLocator", "plain_number",
           "log_axis", "readable_log_axes", "colorbar", "nice_length", "length_label", "scale_bar",
           "save_figure", "clipped_texts"]

STYLE_SHEET = Path(str(files("validation") / "data" / "cupcheck.mplstyle"))
#: a journal's single column [in] (the style sheet's figure width)
COLUMN_WIDTH_IN = 3.4


@contextlib.contextmanager
def cupcheck_style() -> Iterator[None]:
    """Draw inside with the toolkit's style sheet (matplotlib's own settings come back after)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    with plt.style.context(str(STYLE_SHEET)):
        yield


def apply_style() -> None:
    """Use the toolkit's style sheet from now on (the Agg backend: headless)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.style.use(str(STYLE_SHEET))


@dataclass(frozen=True)
class Quantity:
    """A drawn quantity: its name in labels, its SI unit ('' for a ratio) and its colormap."""

    label: str
    si_unit: str
    cmap: str


#: one perceptually uniform colormap per quantity, the same in every figure and 3D view
QUANTITIES = {
    "contact_pressure": Quantity("contact pressure", "Pa", "plasma"),
    "von_mises": Quantity("von Mises stress", "Pa", "viridis"),
    "min_stretch": Quantity("smallest principal stretch", "", "cividis"),
    "lifetime_s": Quantity("lifetime", "s", "magma"),
    "small_u_stiffness_N_per_mm": Quantity("small-u stiffness", "N/mm", "cividis"),
    "appendix_a_ratio": Quantity("FEM / Appendix A small-u stiffness", "", "viridis"),
}


def quantity(name: str) -> Quantity:
    """The registered quantity `name` (ValueError naming the known ones)."""
    if name not in QUANTITIES:
        raise ValueError(f"quantity: expected one of {', '.join(QUANTITIES)}, got {name!r}")
    return QUANTITIES[name]


@dataclass(frozen=True)
class DisplayUnit:
    """A displayed unit: value_shown = factor * value_SI; `unit` is its symbol."""

    factor: float
    unit: str

    def label(self, name: str) -> str:
        return f"{name} ({self.unit})" if self.unit else name


_PREFIXED = ("Pa", "N", "J", "W")
_PREFIXES = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "\u00b5"))


def display_unit(si_unit: str, largest: float) -> DisplayUnit:
    """The SI prefix of `si_unit` that puts `largest` (SI) in [1, 1000); other units unchanged."""
    if si_unit not in _PREFIXED or not (math.isfinite(largest) and largest > 0):
        return DisplayUnit(1.0, si_unit)
    for scale, prefix in _PREFIXES:
        if largest >= scale * (1 - 1e-12):
            return DisplayUnit(1.0 / scale, prefix + si_unit)
    return DisplayUnit(1e6, "\u00b5" + si_unit)


def plain_number(value: float, _pos=None) -> str:
    """A tick label as a plain number (0.05, 20, 1500); powers of ten beyond 1e-4 .. 1e6."""
    if value == 0 or not math.isfinite(value):
        return "0" if value == 0 else ""
    if 1e-4 <= abs(value) < 1e6:
        return f"{value:.6g}"
    exp = int(math.floor(math.log10(abs(value)) + 1e-9))
    mant = value / 10 ** exp
    return f"$10^{{{exp}}}$" if abs(mant - 1) < 1e-6 else f"${mant:.3g}\\times10^{{{exp}}}$"


def _locator_base():
    from matplotlib.ticker import Locator
    return Locator


class ReadableLogLocator(_locator_base()):
    """Major ticks of a log axis that read as numbers: decades if three fit, else 1-2-5 per decade,
    else evenly spaced round numbers, else 1-2-3-5 or 1..9 per decade; at most `max_ticks`."""

    def __init__(self, max_ticks: int = 6):
        self.max_ticks = max_ticks

    def __call__(self):
        lo, hi = self.axis.get_view_interval()
        return self.tick_values(lo, hi)

    def tick_values(self, vmin: float, vmax: float):
        from matplotlib.ticker import MaxNLocator

        lo, hi = sorted((float(vmin), float(vmax)))
        if not hi > 0:
            return np.array([])
        lo = lo if lo > 0 else hi * 1e-3
        k0, k1 = math.floor(math.log10(lo)), math.ceil(math.log10(hi))

        def inside(ticks):
            t = np.asarray([x for x in ticks if lo * (1 - 1e-9) <= x <= hi * (1 + 1e-9)])
            return t

        decades = inside([10.0 ** k for k in range(k0, k1 + 1)])
        if decades.size >= 3:
            step = math.ceil(decades.size / self.max_ticks)
            return decades[::step]
        per_decade = [inside([s * 10.0 ** k for k in range(k0, k1 + 1) for s in subs])
                      for subs in ((1, 2, 5), (1, 2, 3, 5), range(1, 10))]
        round_numbers = [inside(MaxNLocator(nbins=n, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)) for n in (4, 5, 6)]
        candidates = per_decade[:1] + round_numbers + per_decade[1:]
        for candidate in candidates:
            if 3 <= candidate.size <= self.max_ticks:
                return candidate
        fitting = [c for c in candidates if c.size <= self.max_ticks]
        return max(fitting, key=len) if fitting else decades


def log_axis(ax, which: str = "y") -> None:
    """Make the x, y or both axes of `ax` logarithmic with readable ticks (`ReadableLogLocator`,
    plain-number labels, unlabelled minor ticks)."""
    from matplotlib.ticker import LogLocator, NullFormatter

    if which not in ("x", "y", "both"):
        raise ValueError(f"which: expected 'x', 'y' or 'both', got {which!r}")
    for name in ("x", "y") if which == "both" else (which,):
        axis = getattr(ax, f"{name}axis")
        if axis.get_scale() != "log":
            getattr(ax, f"set_{name}scale")("log")
        _readable(axis)
        axis.set_minor_locator(LogLocator(subs="auto"))
        axis.set_minor_formatter(NullFormatter())


def _readable(axis) -> None:
    from matplotlib.ticker import FuncFormatter
    axis.set_major_locator(ReadableLogLocator())
    axis.set_major_formatter(FuncFormatter(plain_number))


def readable_log_axes(fig) -> None:
    """Give every log-scaled axis of `fig` (colour bars too) the readable ticks of `log_axis`."""
    from matplotlib.ticker import LogLocator, NullFormatter

    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() == "log":
                _readable(axis)
                axis.set_minor_locator(LogLocator(subs="auto"))
                axis.set_minor_formatter(NullFormatter())


def colorbar(fig, mappable, name: str, unit: DisplayUnit | None = None, **kw):
    """A colour bar titled with the quantity's name and displayed unit (the mappable's values must
    already be in that unit), its ticks plain numbers."""
    from matplotlib.ticker import ScalarFormatter

    q = QUANTITIES.get(name)
    label = (unit or DisplayUnit(1.0, q.si_unit if q else "")).label(q.label if q else name)
    cbar = fig.colorbar(mappable, label=label, **kw)
    if cbar.ax.yaxis.get_scale() == "log" or cbar.ax.xaxis.get_scale() == "log":
        readable_log_axes(cbar.ax.figure)
    else:                        # plain numbers: no offset, no exponent in [1e-4, 1e6)
        plain = ScalarFormatter(useOffset=False, useMathText=False)
        plain.set_powerlimits((-4, 6))
        cbar.ax.yaxis.set_major_formatter(plain) if cbar.orientation == "vertical" else \
            cbar.ax.xaxis.set_major_formatter(plain)
    return cbar


def nice_length(largest_m: float) -> float:
    """The largest 1, 2 or 5 times a power of ten not above `largest_m` [m]."""
    if not largest_m > 0:
        raise ValueError(f"largest_m: must be > 0, got {largest_m!r}")
    k = math.floor(math.log10(largest_m))
    for s in (5, 2, 1):
        if s * 10.0 ** k <= largest_m * (1 + 1e-12):
            return s * 10.0 ** k
    return 10.0 ** k


def length_label(length_m: float) -> str:
    """'5 mm', '200 \u00b5m', '1 cm' style label of a length [m]."""
    for scale, unit in ((1e-2, "cm"), (1e-3, "mm"), (1e-6, "\u00b5m")):
        if length_m >= scale * (1 - 1e-9) and unit != "cm":
            return f"{length_m / scale:g} {unit}"
    return f"{length_m / 1e-6:g} \u00b5m"


def scale_bar(ax, length_m: float, *, mm_per_unit: float = 1.0, loc: str = "lower left"):
    """A scale bar of `length_m` on axes whose data unit is `mm_per_unit` mm (image axes in mm:
    1), labelled in mm or um (matplotlib's AnchoredSizeBar)."""
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

    bar = AnchoredSizeBar(ax.transData, 1e3 * length_m / mm_per_unit, length_label(length_m), loc,
                          pad=0.4, borderpad=0.4, sep=3, frameon=False, color="black", size_vertical=0)
    bar.size_bar.get_children()[0].set_linewidth(2.0)
    ax.add_artist(bar)
    return bar


def save_figure(fig, path: str | Path, **kw) -> Path:
    """Write `fig` (readable log axes first) and close it; the style sheet's dpi unless given."""
    import matplotlib.pyplot as plt

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    readable_log_axes(fig)
    try:
        fig.savefig(path, **kw)
    finally:
        plt.close(fig)
    return path


def clipped_texts(fig) -> list[str]:
    """The drawn, non-empty texts of `fig` whose rendered box leaves the canvas (tick labels only
    of ticks inside the view limits, as matplotlib draws them)."""
    from matplotlib.text import Text

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    hidden = set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            for tick in (*axis.get_major_ticks(), *axis.get_minor_ticks()):
                if not lo - 1e-9 * abs(hi - lo) <= tick.get_loc() <= hi + 1e-9 * abs(hi - lo):
                    hidden.update({id(tick.label1), id(tick.label2)})
    canvas, out = fig.bbox, []
    for text in fig.findobj(Text):
        if id(text) in hidden or not str(text.get_text()).strip() or not _drawn(text):
            continue
        box = text.get_window_extent(renderer)
        if box.x0 < canvas.x0 - 0.5 or box.y0 < canvas.y0 - 0.5 or box.x1 > canvas.x1 + 0.5 \
                or box.y1 > canvas.y1 + 0.5:
            out.append(text.get_text())
    return out


def _drawn(text) -> bool:
    """Whether a text and the axes holding it are visible."""
    ax = text.axes
    return text.get_visible() and (ax is None or ax.get_visible())
