"""Writing a scene's outputs: curves, lifetimes, trajectories, 2D figures, and the manifest.

Each output pulls only the products it needs (`validation.products.Products` of the scene's
`validation.study.Study`). Figures are
matplotlib (Agg) at the paper's column width (3.4 in), PNG and SVG, axes labelled with units.
`run_scene` is the Python entry point (a scene file, a dict or a `Scene`; the results in memory,
and on disk when given a directory, written atomically with ``manifest.json``).
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from validation.products import Products
from validation.scenes.schema import Scene, load_scene, scene_from_mapping

__all__ = ["run_scene", "SceneResult"]

COLUMN_IN = (3.4, 2.6)


@dataclass
class SceneResult:
    """What a scene produced: the products in memory, the files written (name, kind, path)."""

    scene: Scene
    products: dict[str, Any]
    files: list[dict[str, str]] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)


def run_scene(scene: str | Path | dict | Scene, out: str | Path | None = None,
              cache_dir: str | Path | None = None, progress=None) -> SceneResult:
    """Compute a scene's outputs; with `out`, write them (atomically) and ``out/manifest.json``."""
    from validation.output import atomic_directory, software_versions

    if not isinstance(scene, Scene):
        scene = scene_from_mapping(scene) if isinstance(scene, dict) else load_scene(scene)
    from validation.output import check_file_names
    check_file_names(planned_files(scene), reserved={"manifest.json": "the scene's manifest"})
    products = Products(scene.study(), cache_dir=cache_dir, progress=progress)
    t0 = time.perf_counter()
    def each(tmp):
        n = len(scene.outputs)
        for k, o in enumerate(scene.outputs):
            if progress is not None:
                progress(f"output {k + 1} of {n}: {o['name']}")
            yield from _write(o, products, tmp)

    if out is None:
        files = list(each(None))
        return SceneResult(scene, products.computed(), files, dict(products.timings))
    with atomic_directory(out) as tmp:
        files = list(each(Path(tmp)))
        manifest = {"files": [{**f, "path": Path(f["path"]).name} for f in files],
                    "scene": scene.resolved(), "source": scene.source,
                    "versions": software_versions(), "timings_s": {**products.timings,
                                                                   "total": time.perf_counter() - t0}}
        (Path(tmp) / "manifest.json").write_text(json.dumps(manifest, indent=1, default=str) + "\n")
    files = [{**f, "path": str(Path(out) / Path(f["path"]).name)} for f in files]
    return SceneResult(scene, products.computed(), files, dict(products.timings))


def _write(output: dict, products: Products, tmp: Path | None) -> list[dict[str, str]]:
    kind, name = output["kind"], output["name"]
    if kind == "curve":
        curve = products.curve()
        if tmp is None:
            return []
        csv = curve.to_csv(tmp / f"{name}.csv")
        return [_file(name, kind, csv), _file(name, kind, csv.with_suffix(".json"))]
    if kind == "lifetimes" and products.study.sweep is not None:
        for _, variant in products.variants():
            variant.lifetimes()
        return [_file(name, kind, _sweep_table(products, tmp / f"{name}.csv"))] if tmp else []
    if kind in ("lifetimes", "trajectories"):
        results = products.lifetimes()
        if tmp is None:
            return []
        if kind == "lifetimes":
            return [_file(name, kind, _lifetime_table(results, products, tmp / f"{name}.csv"))]
        return [_file(name, kind, _trajectory(r, tmp / f"{name}_F1_{r.force_N:g}N.csv")) for r in results]
    if kind in ("render", "footprint", "squeeze"):
        from validation.scenes.views3d import write_view
        return write_view(output, products, tmp)
    figure = {"lifetime_vs_force": _lifetime_figure, "uc_vs_pressure": _uc_figure, "F0_vs_u": _F0_figure,
              "lifetime_vs_parameter": _parameter_figure, "r_pb_vs_time": _r_pb_figure,
              "p_Ndot_vs_time": _p_Ndot_figure}
    fig = figure[output["figure"]](products)
    if tmp is None:
        import matplotlib.pyplot as plt
        plt.close(fig)
        return []
    paths = []
    for suffix in ("png", "svg"):
        path = tmp / f"{name}.{suffix}"
        fig.savefig(path, dpi=200)
        paths.append(_file(name, "figure", path))
    import matplotlib.pyplot as plt
    plt.close(fig)
    return paths


#: the files of each output kind, by suffix (as `_write` and `write_view` name them)
_SUFFIXES = {"curve": (".csv", ".json"), "lifetimes": (".csv",), "figure": (".png", ".svg"), "render": (".png",),
             "footprint": (".png", ".json"), "squeeze": (".gif",)}


def planned_files(scene: Scene) -> dict[str, list[str]]:
    """The file names each output will write, before any work (`check_file_names` refuses two
    outputs writing one file): a trajectory per force, a squeeze's numbered frames."""
    plan: dict[str, list[str]] = {}
    for i, o in enumerate(scene.outputs):
        name, kind = o["name"], o["kind"]
        label = f"outputs[{i}] ({kind} '{name}')"
        if kind == "trajectories":
            for force in scene["loads"]["F1_N"]:
                plan[f"{label} at F1 = {force!r} N"] = [f"{name}_F1_{force:g}N.csv"]
            continue
        frames = [f"{name}_{k:02d}.png" for k in range(o["frames"])] if kind == "squeeze" else []
        plan[label] = [name + s for s in _SUFFIXES[kind]] + frames
    return plan


def _file(name: str, kind: str, path: Path) -> dict[str, str]:
    return {"name": name, "kind": kind, "path": str(path)}


def _lifetime_table(results, products: Products, path: Path) -> Path:
    from validation.output import write_table

    s = products.study
    return write_table(path, {
        "route": s.route, "stiffness": s.stiffness,
        "force_N": [r.force_N for r in results],
        "lifetime_s": [r.lifetime_s for r in results], "reason": [r.reason for r in results],
        "ballistic_share": [r.details["ballistic_share"] for r in results],
        "r_final_mm": [float(r.trajectory["r_mm"][-1]) for r in results],
        "p_b_final_Pa": [float(r.trajectory["p_b_Pa"][-1]) for r in results]})


def _sweep_table(products: Products, path: Path) -> Path:
    from validation.output import write_table

    key = products.study.sweep.key.split(".")[1]
    rows = [(value, r) for value, p in products.variants() for r in p.lifetimes()]
    return write_table(path, {key: [v for v, _ in rows], "force_N": [r.force_N for _, r in rows],
                              "lifetime_s": [r.lifetime_s for _, r in rows], "reason": [r.reason for _, r in rows],
                              "ballistic_share": [r.details["ballistic_share"] for _, r in rows]}, stage="scene sweep")


def _parameter_figure(products: Products):
    key = products.study.sweep.key.split(".")[1]
    variants = products.variants()
    numeric = all(isinstance(v, (int, float)) for v, _ in variants)
    fig, ax = _axes(key, "lifetime (s)")
    for i, F in enumerate(products.study.loads.forces_N):
        pts = [(j if not numeric else v, p.lifetimes()[i].lifetime_s) for j, (v, p) in enumerate(variants)]
        pts = [(x, t) for x, t in pts if math.isfinite(t) and t > 0]
        if pts:
            ax.semilogy(*zip(*pts), "o-", ms=3, label=f"$F_1$ = {F:g} N")
    if not numeric:
        ax.set_xticks(range(len(variants)), [str(v) for v, _ in variants], rotation=30, fontsize=6)
    ax.legend(fontsize=6)
    return fig


def _trajectory(result, path: Path) -> Path:
    from validation.output import write_table
    return write_table(path, dict(result.trajectory_columns()))


def _axes(xlabel: str, ylabel: str):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=COLUMN_IN, constrained_layout=True)
    ax.set(xlabel=xlabel, ylabel=ylabel)
    return fig, ax


def _lifetime_figure(products: Products):
    results = products.lifetimes()
    s = products.study
    fig, ax = _axes("pull force $F_1$ (N)", "lifetime (s)")
    pts = [(r.force_N, r.lifetime_s) for r in results if math.isfinite(r.lifetime_s) and r.lifetime_s > 0]
    if pts:
        ax.semilogy(*zip(*pts), "o-", ms=3, label=f"{s.stiffness}-fed, {s.route} route")
    # a FEM scene of a Table 1 cup: Appendix A beside it
    reference = products.appendix_a() if not s.design.file and s.sweep is None else None
    if reference is not None:
        ref = [(r.force_N, r.lifetime_s) for r in reference.lifetimes() if math.isfinite(r.lifetime_s) and r.lifetime_s > 0]
        if ref:
            ax.semilogy(*zip(*ref), "s--", ms=3, label="appendix-a-fed, paper route")
    if pts or reference is not None:
        ax.legend(fontsize=6)
    ax.set_title(f"cup {s.design.preset if not s.design.file else Path(s.design.file).name}, "
                 f"{s.surface.preset if not s.surface.uc_table else 'u_c table'}", fontsize=7)
    return fig


def _lines(products: Products) -> list[tuple[str, Products]]:
    """(label, products) per line: one per swept value, or the scene itself."""
    if products.study.sweep is None:
        return [("", products)]
    return [(str(v), p) for v, p in products.variants()]


def _uc_figure(products: Products):
    import numpy as np
    fig, ax = _axes("$p/E$", "$u_c$ (nm)")
    x = np.geomspace(1e-4, 0.1, 200)
    for label, p in _lines(products):
        table = p.uc_table()
        u = np.array([table(v) for v in x])
        ax.loglog(x[u > 0], 1e9 * u[u > 0], label=label or None)
    if products.study.sweep is not None:
        ax.legend(fontsize=6)
    else:
        ax.set_title(products.study.surface.preset or "u_c table", fontsize=7)
    return fig


def _F0_figure(products: Products):
    from reduced.appendix_a import appendix_a_curve
    from reduced.cup import CUPS
    fig, ax = _axes("plate displacement $u$ (mm)", "stiffness force $F_0$ (N)")
    for i, (label, p) in enumerate(_lines(products)):
        curve, s = p.curve(), p.study
        name = f"cup {label}: " if label else ""
        line, = ax.plot(1e3 * curve.u_m, curve.F0_N, label=f"{name}{s.stiffness}")
        if curve.design is None or not s.design.file:
            ref = appendix_a_curve(CUPS[s.design.preset])
            keep = ref.u_m <= curve.u_m[-1]
            ax.plot(1e3 * ref.u_m[keep], ref.F0_N[keep], "--", color=line.get_color(), label=f"{name}Appendix A")
    ax.legend(fontsize=6)
    return fig


def _time_figure(products: Products, top: tuple[str, str, float], bottom: tuple[str, str, float]):
    """Two panels over time, one line per F1: (column, axis label, factor) each."""
    import matplotlib.pyplot as plt
    results = products.lifetimes()
    fig, axes = plt.subplots(2, 1, figsize=(COLUMN_IN[0], 1.6 * COLUMN_IN[1]), sharex=True, constrained_layout=True)
    water = products.study.loads.fluid == "water"
    for r in results:
        cols = r.trajectory_columns()
        t = cols["t_s"]
        for ax, (col, label, factor) in zip(axes, (top, bottom)):
            col = {"N_dot_per_s": "V_dot_mm3_per_s"}.get(col, col) if water else col
            keep = t > 0
            ax.plot(t[keep], factor * cols[col][keep], label=f"$F_1$ = {r.force_N:g} N")
            ax.set_ylabel(label if not water or col == top[0] else "$\\dot V$ (mm$^3$/s)")
    axes[0].set_xscale("log")
    axes[1].set_xlabel("time $t$ (s)")
    axes[0].legend(fontsize=5)
    return fig


def _r_pb_figure(products: Products):
    return _time_figure(products, ("r_mm", "contact radius $r$ (mm)", 1.0),
                        ("p_b_Pa", "cavity pressure $p_b$ (kPa)", 1e-3))


def _p_Ndot_figure(products: Products):
    fig = _time_figure(products, ("p_Pa", "contact pressure $p$ (kPa)", 1e-3),
                       ("N_dot_per_s", "leak rate $\\dot N$ (1/s)", 1.0))
    fig.axes[1].set_yscale("log")
    return fig
