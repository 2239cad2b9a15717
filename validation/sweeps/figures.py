"""What a sweep shows: maps of a quantity over two axes, and the Pareto front of lifetime vs cost.

Both read the tidy table (`results.parquet`) and write PNGs with matplotlib's Agg backend. A map
colours each design at its (x, y) axis values by the quantity (one force's lifetime, the small-u
stiffness, the Appendix A ratio); failed designs are drawn as crosses. The Pareto front is the set
of designs no other design beats in both a longer lifetime and a smaller material volume.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["pareto_front", "map_figure", "pareto_figure", "sweep_figures", "sweep_caption", "axis_label",
           "AXIS_LABELS"]

MAP_QUANTITIES = {"lifetime_s": "lifetime (s)", "small_u_stiffness_N_per_mm": "small-u stiffness (N/mm)",
                  "appendix_a_ratio": "FEM / Appendix A small-u stiffness"}
#: the axis labels of the sweep's keys and table columns: name, symbol and unit
AXIS_LABELS = {"alpha_deg": "cone angle \u03b1 (deg)", "r0_mm": "inner radius r0 (mm)", "r1_mm": "rim radius r1 (mm)",
               "d0_mm": "wall thickness d0 at r0 (mm)", "d1_mm": "wall thickness d1 at r1 (mm)",
               "E_MPa": "Young's modulus E (MPa)", "nu": "Poisson's ratio \u03bd",
               "r_start_mm": "start radius r_start (mm)", "l0_mm": "strip width l0 (mm)",
               "l1_mm": "strip width l1 (mm)", "friction": "Coulomb friction \u03bc", "contact": "contact law",
               "surface": "surface", "volume_mm3": "material volume (mm$^3$)", "F1_N": "pull force F1 (N)",
               **MAP_QUANTITIES}
_UNITS = {"mm": "mm", "mm3": "mm$^3$", "deg": "deg", "MPa": "MPa", "N": "N", "s": "s", "N_per_mm": "N/mm"}


def axis_label(key: str) -> str:
    """The label of a sweep key or table column: its name and unit (alpha_deg: cone angle (deg));
    an unknown key with a unit suffix keeps its stem and gets the unit in brackets."""
    if key in AXIS_LABELS:
        return AXIS_LABELS[key]
    for suffix, unit in sorted(_UNITS.items(), key=lambda kv: -len(kv[0])):
        if key.endswith("_" + suffix):
            return f"{key[:-len(suffix) - 1].replace('_', ' ')} ({unit})"
    return key.replace("_", " ")


def sweep_caption(base: dict, axes: list[str]) -> str:
    """What every design of a sweep shares and what it varies, in the scenes' wording: "base cup A;
    FEM sticking (coarse mesh); paper route; pmma-1.89; varied: cone angle α (deg), ..."."""
    varied = set(axes)
    law = "contact law varied" if varied & {"contact", "friction"} else (
        f"coulomb mu = {base.get('friction') or 0:g}" if base["contact"] == "coulomb" else base["contact"])
    parts = [f"base cup {base['cup']}", f"FEM {law} ({base['fidelity']} mesh)",
             f"{base.get('route') or 'paper'} route", "surface varied" if "surface" in varied else base["surface"]]
    return "; ".join(parts) + "\nvaried: " + ", ".join(axis_label(a) for a in axes)


def pareto_front(benefit: np.ndarray, cost: np.ndarray) -> np.ndarray:
    """Indices of the points that no other point dominates (benefit >=, cost <=, one strictly),
    sorted by cost."""
    b, c = np.asarray(benefit, float), np.asarray(cost, float)
    keep = []
    for i in range(b.size):
        dominated = np.any((b >= b[i]) & (c <= c[i]) & ((b > b[i]) | (c < c[i])))
        if not dominated:
            keep.append(i)
    return np.array(sorted(keep, key=lambda i: c[i]), dtype=int)


def _frame(table_path: Path):
    import pyarrow.parquet as pq
    return pq.read_table(table_path).to_pandas()


def _categories(column) -> list[str] | None:
    """The sorted category names of a categorical column (strings, pandas' string dtype), None
    for a numeric one."""
    from pandas.api.types import is_bool_dtype, is_numeric_dtype

    if is_numeric_dtype(column.dtype) and not is_bool_dtype(column.dtype):
        return None
    return sorted({str(v) for v in column})


def _positions(column, names: list[str] | None) -> np.ndarray:
    """Where a column's values go: the numbers, or each category's index in `names`."""
    if names is None:
        return column.astype(float).to_numpy()
    return np.array([names.index(str(v)) for v in column], float)


def map_figure(frame, x: str, y: str, quantity: str, force_N: float, path: Path, caption: str = "") -> Path:
    """One map: designs at (x, y) coloured by `quantity` at pull force `force_N` (log colour for
    lifetimes); a categorical axis (contact law, surface) places its categories at 0, 1, ..."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    from validation import style

    rows = frame[frame["F1_N"] == force_N]
    ok = rows[rows["failure"].isna()] if "failure" in rows else rows
    values = ok[quantity].astype(float)
    shown = ok[np.isfinite(values) & (values > 0)] if quantity == "lifetime_s" else ok[np.isfinite(values)]
    bad = rows[rows["failure"].notna()] if "failure" in rows else rows.iloc[:0]
    names = {key: _categories(rows[key]) for key in (x, y)}
    with style.cupcheck_style():
        fig, ax = plt.subplots()
        if len(shown):
            norm = LogNorm() if quantity == "lifetime_s" else None
            sc = ax.scatter(_positions(shown[x], names[x]), _positions(shown[y], names[y]),
                            c=shown[quantity].astype(float), s=36, norm=norm, cmap=style.quantity(quantity).cmap)
            style.colorbar(fig, sc, quantity, ax=ax)
        if len(bad):
            ax.scatter(_positions(bad[x], names[x]), _positions(bad[y], names[y]), marker="x", c="crimson",
                       label="failed")
            ax.legend()
        for axis, key in (("x", x), ("y", y)):
            if names[key]:
                getattr(ax, f"set_{axis}ticks")(range(len(names[key])), names[key])
                getattr(ax, f"set_{axis}lim")(-0.5, len(names[key]) - 0.5)
        ax.set(xlabel=axis_label(x), ylabel=axis_label(y),
               title=f"F1 = {force_N:g} N" if quantity == "lifetime_s" else "")
        fig.suptitle(caption, fontsize=6)
        return style.save_figure(fig, path)


def pareto_figure(frame, force_N: float, path: Path, caption: str = "") -> Path:
    """Lifetime at `force_N` against material volume, the Pareto front joined."""
    import matplotlib.pyplot as plt

    from validation import style

    rows = frame[(frame["F1_N"] == force_N) & frame["lifetime_s"].notna()]
    life, vol = rows["lifetime_s"].astype(float).to_numpy(), rows["volume_mm3"].astype(float).to_numpy()
    with style.cupcheck_style():
        fig, ax = plt.subplots()
        ax.scatter(vol, life, s=14, c="0.6", label="designs")
        front = pareto_front(life, vol)
        if front.size:
            ax.plot(vol[front], life[front], "o-", c="C1", label="Pareto front")
        style.log_axis(ax, "both")
        ax.set(xlabel=axis_label("volume_mm3"), ylabel=axis_label("lifetime_s"), title=f"F1 = {force_N:g} N")
        ax.legend()
        fig.suptitle(caption, fontsize=6)
        return style.save_figure(fig, path)


def sweep_figures(table_path: Path, axes: list[str], out: Path, caption: str = "") -> list[Path]:
    """Maps over the first two axes (numeric or categorical; one axis against the material volume)
    and the Pareto front, for the first pull force; `caption` (`sweep_caption`) heads each figure."""
    frame = _frame(table_path)
    if frame.empty:
        return []
    force = float(frame["F1_N"].iloc[0])
    shown = [a for a in axes if a in frame]
    x, y = (shown + ["volume_mm3", "volume_mm3"])[:2]
    if x == y:
        y = "small_u_stiffness_N_per_mm" if x != "small_u_stiffness_N_per_mm" else "volume_mm3"
    paths = []
    for q in MAP_QUANTITIES:
        if q in frame:
            paths.append(map_figure(frame, x, y, q, force, out / f"map_{q}.png", caption))
    if "lifetime_s" in frame and "volume_mm3" in frame:
        paths.append(pareto_figure(frame, force, out / "pareto_lifetime_volume.png", caption))
    return paths
