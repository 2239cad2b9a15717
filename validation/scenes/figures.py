"""The 2D figures a scene can ask for, drawn in the toolkit's style (`validation.style`).

Each takes the scene's `validation.bridge.products.Products` and returns a figure (drawn inside
`cupcheck_style()`; `draw` writes it with `save_figure`). Every figure's title names what it was
computed for: the design, the stiffness (the FEM's contact law and mesh level, or Appendix A), the
route and the surface (`caption`); a swept parameter gives one line per value. Everything drawn is
also a table: `figure_table` reads every line back from the figure, point by point, so the table
is what the figure shows (e.g. the Appendix A-fed lifetimes drawn beside the FEM-fed ones).
"""

from __future__ import annotations

import math
from pathlib import Path

from validation.bridge.products import Products

__all__ = ["FIGURES", "NEEDS", "appendix_a_reference", "caption", "draw", "figure_table", "write_figure_table"]


def caption(products: Products) -> str:
    """design; stiffness (FEM contact law, mesh level, or Appendix A); route; surface; a swept
    parameter by its values."""
    s = products.study
    key = s.sweep.key if s.sweep is not None else None
    values = ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in s.sweep.values) if key else ""
    design = f"cups {values}" if key == "cup.preset" else s.design.label
    contact = f"coulomb mu = {values}" if key == "contact.friction" else s.contact.label()
    stiffness = f"FEM {contact} ({s.fidelity} mesh)" if s.stiffness == "fem" else "Appendix A (d0 2 mm)"
    surface = f"surfaces {values}" if key == "surface.preset" else s.surface.label
    parts = [design, stiffness, f"{s.route} route", surface]
    if key in ("loads.kappa", "loads.r_start_mm"):
        parts.append(f"{key.split('.')[1]} = {values}")
    return "; ".join(parts)


def draw(name: str, products: Products, paths: list[Path], table: Path | None = None) -> None:
    """Draw the figure `name` (one of `FIGURES`) and write it to each of `paths` (none: only draw),
    laid out for the first (the finest: a 300 dpi PNG before an SVG), and what it draws to `table`
    (`figure_table`)."""
    from validation.style import cupcheck_style, readable_log_axes, save_figure

    with cupcheck_style():
        fig = FIGURES[name](products)
        fig.suptitle(caption(products), fontsize=6)
        readable_log_axes(fig)
        if table is not None:
            write_figure_table(fig, table, caption(products))
        for k, path in enumerate(paths[:-1]):
            fig.savefig(path)
            if k == 0:                   # laid out once, for the first path; the others take that layout
                fig.set_layout_engine("none")
        if paths:
            save_figure(fig, paths[-1])
        else:
            import matplotlib.pyplot as plt
            plt.close(fig)


#: subscript digits of plain-text labels (F₁, drawn without mathtext) as the tables spell them (F_1)
_SUBSCRIPTS = str.maketrans({chr(0x2080 + d): f"_{d}" for d in range(10)})


def figure_table(fig) -> dict[str, list]:
    """Every labelled line of `fig`, one row per point: its panel (the axes' quantities with their
    units, TeX marks dropped, subscript digits as _1), its legend label, and x, y as drawn."""
    plain = lambda text: text.replace("$", "").replace("\\", "").translate(_SUBSCRIPTS)   # noqa: E731
    rows: dict[str, list] = {"series": [], "x_quantity": [], "x": [], "y_quantity": [], "y": []}
    for ax in fig.axes:
        for line in ax.get_lines():
            label = line.get_label()
            x, y = line.get_xdata(), line.get_ydata()
            rows["series"] += [plain(label) if not label.startswith("_") else ""] * len(x)
            rows["x_quantity"] += [plain(ax.get_xlabel())] * len(x)
            rows["y_quantity"] += [plain(ax.get_ylabel())] * len(x)
            rows["x"] += [float(v) for v in x]
            rows["y"] += [float(v) for v in y]
    return rows


def write_figure_table(fig, path: Path, title: str) -> Path:
    """`figure_table` of `fig` as a CSV, its first column the figure's title (what it was computed for)."""
    from validation.output import write_table

    return write_table(path, {"figure": title, **figure_table(fig)}, stage=f"figure data {Path(path).name}")


def _axes(xlabel: str, ylabel: str):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    ax.set(xlabel=xlabel, ylabel=ylabel)
    return fig, ax


def _lines(products: Products) -> list[tuple[str, Products]]:
    """(label, products) per line: one per swept value ("cup A", "kappa = 2"), or the study itself."""
    s = products.study
    if s.sweep is None:
        return [("", products)]
    key = s.sweep.key.split(".")[1]
    name = {"preset": "cup" if s.sweep.key == "cup.preset" else "", "friction": "mu"}.get(key, key)
    return [(f"{name} {v:g}" if isinstance(v, float) and name == "mu" else
             f"{name} = {v:g}" if isinstance(v, float) else f"{name} {v}".strip(), p)
            for v, p in products.variants()]


def _held(results) -> list[tuple[float, float]]:
    return [(r.force_N, r.lifetime_s) for r in results if math.isfinite(r.lifetime_s) and r.lifetime_s > 0]


def appendix_a_reference(products: Products):
    """The same cup fed by Appendix A, drawn beside a lifetime figure's FEM-fed lines: for a study
    of a Table 1 cup that sweeps nothing (`Products.appendix_a`, None for an Appendix A study)."""
    s = products.study
    return products.appendix_a() if not s.design.file and s.sweep is None else None


def _lifetime_figure(products: Products):
    """Lifetime against F1: one line per swept value (every cup of a cup.preset sweep), and for a
    FEM study of a Table 1 cup the same cup fed by Appendix A beside it."""
    from validation.style import log_axis
    s = products.study
    fig, ax = _axes("pull force F\u2081 (N)", "lifetime (s)")
    for label, p in _lines(products):
        pts = _held(p.lifetimes())
        if pts:
            ax.plot(*zip(*pts), "o-", label=label or f"{s.stiffness}-fed, {s.route} route")
    reference = appendix_a_reference(products)
    if reference is not None:
        ref = _held(reference.lifetimes())
        if ref:
            ax.plot(*zip(*ref), "s--", label="appendix-a-fed, paper route")
    ax.set_yscale("log")
    log_axis(ax, "y")
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    return fig


def _parameter_figure(products: Products):
    from validation.style import log_axis
    key = products.study.sweep.key.split(".")[1]
    variants = products.variants()
    numeric = all(isinstance(v, (int, float)) for v, _ in variants)
    fig, ax = _axes(key, "lifetime (s)")
    for i, F in enumerate(products.study.loads.forces_N):
        pts = [(j if not numeric else v, p.lifetimes()[i].lifetime_s) for j, (v, p) in enumerate(variants)]
        pts = [(x, t) for x, t in pts if math.isfinite(t) and t > 0]
        if pts:
            ax.plot(*zip(*pts), "o-", ms=3, label=f"F\u2081 = {F:g} N")
    ax.set_yscale("log")
    log_axis(ax, "y")
    if not numeric:
        ax.set_xticks(range(len(variants)), [str(v) for v, _ in variants], rotation=30)
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    return fig


def _uc_figure(products: Products):
    import numpy as np

    from validation.style import log_axis
    fig, ax = _axes("$p/E$", "$u_c$ (nm)")
    x = np.geomspace(1e-4, 0.1, 200)
    for label, p in _lines(products):
        table = p.uc_table()
        u = np.array([table(v) for v in x])
        ax.plot(x[u > 0], 1e9 * u[u > 0], label=label or None)
    ax.set_xscale("log")
    ax.set_yscale("log")
    log_axis(ax, "both")
    if products.study.sweep is not None:
        ax.legend()
    return fig


def _F0_figure(products: Products):
    from reduced.appendix_a import appendix_a_curve
    from reduced.cup import CUPS
    fig, ax = _axes("plate displacement u (mm)", "stiffness force F\u2080 (N)")
    for label, p in _lines(products):
        curve, s = p.curve(), p.study
        name = f"{label}: " if label else ""
        line, = ax.plot(1e3 * curve.u_m, curve.F0_N, label=f"{name}{s.stiffness}")
        if curve.design is None or not s.design.file:
            ref = appendix_a_curve(CUPS[s.design.preset])
            keep = ref.u_m <= curve.u_m[-1]
            ax.plot(1e3 * ref.u_m[keep], ref.F0_N[keep], "--", color=line.get_color(), label=f"{name}Appendix A")
    ax.legend()
    return fig


def _time_figure(products: Products, top: tuple[str, str, float], bottom: tuple[str, str, float]):
    """Two panels over time, one line per F1: (column, axis label, factor) each."""
    import matplotlib.pyplot as plt

    from validation.style import COLUMN_WIDTH_IN, log_axis
    results = products.lifetimes()
    fig, axes = plt.subplots(2, 1, figsize=(COLUMN_WIDTH_IN, 1.6 * 2.6), sharex=True)
    water = products.study.loads.fluid == "water"
    for r in results:
        cols = r.trajectory_columns()
        t = cols["t_s"]
        for ax, (col, label, factor) in zip(axes, (top, bottom)):
            col = {"N_dot_per_s": "V_dot_mm3_per_s"}.get(col, col) if water else col
            keep = t > 0
            ax.plot(t[keep], factor * cols[col][keep], label=f"F\u2081 = {r.force_N:g} N")
            ax.set_ylabel(label if not water or col == top[0] else "$\\dot V$ (mm$^3$/s)")
    axes[0].set_xscale("log")
    log_axis(axes[1], "x")
    axes[1].set_xlabel("time t (s)")
    axes[0].legend(fontsize=5)
    return fig


def _r_pb_figure(products: Products):
    return _time_figure(products, ("r_mm", "contact radius r (mm)", 1.0),
                        ("p_b_Pa", "cavity pressure $p_b$ (kPa)", 1e-3))


def _p_Ndot_figure(products: Products):
    from validation.style import log_axis
    fig = _time_figure(products, ("p_Pa", "contact pressure p (kPa)", 1e-3),
                       ("N_dot_per_s", "leak rate $\\dot N$ (1/s)", 1.0))
    fig.axes[1].set_yscale("log")
    log_axis(fig.axes[1], "y")
    return fig


#: figure name (a scene's ``figure = ...``) -> the function drawing it
FIGURES = {"lifetime_vs_force": _lifetime_figure, "uc_vs_pressure": _uc_figure, "F0_vs_u": _F0_figure,
           "lifetime_vs_parameter": _parameter_figure, "r_pb_vs_time": _r_pb_figure,
           "p_Ndot_vs_time": _p_Ndot_figure}
#: the products each figure draws (of each swept value in a sweep; "appendix_a": the lifetimes of
#: `appendix_a_reference`), computed before it is drawn in another process (validation.scenes.drawing)
NEEDS = {"lifetime_vs_force": ("lifetimes", "appendix_a"), "uc_vs_pressure": ("uc_table",), "F0_vs_u": ("curve",),
         "lifetime_vs_parameter": ("lifetimes",), "r_pb_vs_time": ("lifetimes",), "p_Ndot_vs_time": ("lifetimes",)}
