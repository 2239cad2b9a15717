"""What a sweep shows: maps of a quantity over two axes, and the Pareto front of lifetime vs cost.

Both read the tidy table (`results.parquet`) and write PNGs with matplotlib's Agg backend. A map
colours each design at its (x, y) axis values by the quantity (one force's lifetime, the small-u
stiffness, the Appendix A ratio); failed designs are drawn as crosses. The Pareto front is the set
of designs no other design beats in both a longer lifetime and a smaller material volume.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["pareto_front", "map_figure", "pareto_figure", "sweep_figures"]

MAP_QUANTITIES = {"lifetime_s": "lifetime (s)", "small_u_stiffness_N_per_mm": "small-u stiffness (N/mm)",
                  "appendix_a_ratio": "FEM / Appendix A small-u stiffness"}


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


def map_figure(frame, x: str, y: str, quantity: str, force_N: float, path: Path) -> Path:
    """One map: designs at (x, y) coloured by `quantity` at pull force `force_N` (log colour for
    lifetimes)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    rows = frame[frame["F1_N"] == force_N]
    ok = rows[rows["failure"].isna()] if "failure" in rows else rows
    values = ok[quantity].astype(float)
    shown = ok[np.isfinite(values) & (values > 0)] if quantity == "lifetime_s" else ok[np.isfinite(values)]
    fig, ax = plt.subplots(figsize=(3.5, 2.9), constrained_layout=True)
    if len(shown):
        norm = LogNorm() if quantity == "lifetime_s" else None
        sc = ax.scatter(shown[x], shown[y], c=shown[quantity].astype(float), s=60, norm=norm, cmap="viridis")
        fig.colorbar(sc, ax=ax, label=MAP_QUANTITIES[quantity])
    bad = rows[rows["failure"].notna()] if "failure" in rows else rows.iloc[:0]
    if len(bad):
        ax.scatter(bad[x], bad[y], marker="x", c="crimson", label="failed")
        ax.legend(fontsize=7)
    ax.set(xlabel=x, ylabel=y, title=f"F1 = {force_N:g} N" if quantity == "lifetime_s" else "")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def pareto_figure(frame, force_N: float, path: Path) -> Path:
    """Lifetime at `force_N` against material volume, the Pareto front joined."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = frame[(frame["F1_N"] == force_N) & frame["lifetime_s"].notna()]
    life, vol = rows["lifetime_s"].astype(float).to_numpy(), rows["volume_mm3"].astype(float).to_numpy()
    fig, ax = plt.subplots(figsize=(3.5, 2.9), constrained_layout=True)
    ax.scatter(vol, life, s=18, c="0.6", label="designs")
    front = pareto_front(life, vol)
    if front.size:
        ax.plot(vol[front], life[front], "o-", c="C3", label="Pareto front")
    ax.set(xscale="log", yscale="log", xlabel="material volume (mm$^3$)", ylabel="lifetime (s)",
           title=f"F1 = {force_N:g} N")
    ax.legend(fontsize=7)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def sweep_figures(table_path: Path, axes: list[str], out: Path) -> list[Path]:
    """Maps over the first two numeric axes (or one axis against the design index) and the Pareto
    front, for the first pull force."""
    frame = _frame(table_path)
    if frame.empty:
        return []
    force = float(frame["F1_N"].iloc[0])
    numeric = [a for a in axes if a in frame and np.issubdtype(frame[a].dtype, np.number)]
    x, y = (numeric + ["volume_mm3", "volume_mm3"])[:2]
    if x == y:
        y = "small_u_stiffness_N_per_mm" if x != "small_u_stiffness_N_per_mm" else "volume_mm3"
    paths = []
    for q in MAP_QUANTITIES:
        if q in frame:
            paths.append(map_figure(frame, x, y, q, force, out / f"map_{q}.png"))
    if "lifetime_s" in frame and "volume_mm3" in frame:
        paths.append(pareto_figure(frame, force, out / "pareto_lifetime_volume.png"))
    return paths
