"""Writing a scene's outputs: curves, lifetimes, trajectories, 2D figures, and the manifest.

Each output pulls only the products it needs (`validation.bridge.products.Products` of the scene's
`validation.bridge.study.Study`). Figures (`validation.scenes.figures`) are drawn in the toolkit's style,
PNG and SVG, axes labelled with units; tables name design, contact law, mesh, route and surface.
`run_scene` is the Python entry point (a scene file, a dict or a `Scene`; the results in memory,
and on disk when given a directory, written atomically with ``manifest.json``).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from validation.bridge.products import Products
from validation.scenes.schema import Scene, load_scene, scene_from_mapping

__all__ = ["run_scene", "SceneResult"]



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
    from validation.scenes.figures import draw
    paths = [] if tmp is None else [tmp / f"{name}.{suffix}" for suffix in ("svg", "png")]
    draw(output["figure"], products, paths)
    return [_file(name, "figure", path) for path in reversed(paths)]


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

    from validation.bridge.lifetimes import end_state_columns

    s = products.study
    return write_table(path, {
        "route": s.route, "stiffness": s.stiffness, **{k: v for k, v in s.record().items() if k != "route"},
        "force_N": [r.force_N for r in results],
        "lifetime_s": [r.lifetime_s for r in results], "reason": [r.reason for r in results],
        **end_state_columns(results)})


def _sweep_table(products: Products, path: Path) -> Path:
    from validation.output import write_table

    key = products.study.sweep.key.split(".")[1]
    rows = [(value, p.study.record(), r) for value, p in products.variants() for r in p.lifetimes()]
    record = {k: [c[k] for _, c, _ in rows] for k in products.study.record()}
    rows = [(v, r) for v, _, r in rows]
    if products.study.route == "fem":      # the largest holdable force of each value's cup
        from validation.bridge.lifetimes import end_state_columns
        own = {k: [x for _, p in products.variants() for x in end_state_columns(p.lifetimes())[k]]
               for k in ("largest_force_N", "u_final_mm", "p_b_final_Pa", "seal_r_final_mm")}
    else:
        own = {"ballistic_share": [r.details["ballistic_share"] for _, r in rows]}
    return write_table(path, {key: [v for v, _ in rows], **record, "force_N": [r.force_N for _, r in rows],
                              "lifetime_s": [r.lifetime_s for _, r in rows], "reason": [r.reason for _, r in rows],
                              **own}, stage="scene sweep")


def _trajectory(result, path: Path) -> Path:
    from validation.output import write_table
    return write_table(path, dict(result.trajectory_columns()))


