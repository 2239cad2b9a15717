"""Writing a scene's outputs: curves, lifetimes, trajectories, 2D figures, and the manifest.

Each output pulls only the products it needs (`validation.bridge.products.Products` of the scene's
`validation.bridge.study.Study`). Figures (`validation.scenes.figures`) are drawn in the toolkit's style,
PNG and SVG, axes labelled with units; tables name design, contact law, mesh, route and surface.
`run_scene` is the Python entry point (a scene file, a dict or a `Scene`; the results in memory,
and on disk when given a directory, written atomically with ``manifest.json``). `cupcheck run` has
the figures drawn in a second process while the products are computed (`validation.scenes.drawing`).

A rerun into the same directory does no work for what has not changed: the manifest records, for
every file, the key of what its output was made from (`made_from`) and the sha256 of its bytes;
an output whose key is unchanged and whose files are present and intact is kept as it is (its
files linked into the new directory, mtimes unchanged), any other is drawn again; a rerun that
changes nothing writes nothing.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from validation.bridge.cache import file_digest, source_hash
from validation.bridge.products import Products
from validation.bridge.study import Study
from validation.scenes.schema import STATE_KINDS, Scene, load_scene, scene_from_mapping

__all__ = ["run_scene", "SceneResult", "made_from", "partial_records", "partial_lines"]

#: the manifest's name in a scene's output directory
MANIFEST = "manifest.json"
#: what an FEM state (render, footprint, squeeze) is made from; an FEM curve adds the stiffness
#: source and its end (u_max); every other output (tables, figures) depends on the whole study
_FEM_PARTS = ("design", "material", "contact", "fidelity")


@dataclass
class SceneResult:
    """What a scene produced: the products in memory, the files written (name, kind, path), and
    of those the files kept unchanged from the previous run into the same directory."""

    scene: Scene
    products: dict[str, Any]
    files: list[dict[str, str]] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    kept: list[dict[str, str]] = field(default_factory=list)
    up_to_date: bool = False        # the directory was left as it was: nothing written
    partial: dict[str, dict[str, Any]] = field(default_factory=dict)   # partial curves, by study (`partial_records`)


def made_from(output: Mapping[str, Any], study: Study) -> dict[str, Any]:
    """What `output` is made from, for the manifest: ``key``, a content key of its own keys, the part
    of the study it depends on (input files by path and by the sha256 of their bytes) and the
    sources of fem, reduced and validation (like the products' cache keys: no package versions);
    ``made_from``, the study parts by name; ``sources``, the sources' hash."""
    record = study.describe()
    record["design"]["file_sha256"] = file_digest(study.design.file)
    record["surface"]["uc_table_sha256"] = file_digest(study.surface.uc_table)
    record["suction_table_sha256"] = file_digest(study.suction_table)
    if output["kind"] in STATE_KINDS:
        parts = _FEM_PARTS
    elif output["kind"] == "curve" and study.stiffness == "fem":
        parts = (*_FEM_PARTS, "stiffness", "u_max_mm")
    else:
        parts = tuple(record)
    sources = source_hash("fem", "reduced", "validation")
    inputs = {"output": dict(output), "study": {p: record[p] for p in parts}, "sources": sources}
    key = hashlib.sha256(json.dumps(inputs, sort_keys=True, default=str).encode()).hexdigest()[:32]
    return {"key": key, "made_from": list(parts), "sources": sources}


def run_scene(scene: str | Path | dict | Scene, out: str | Path | None = None,
              cache_dir: str | Path | None = None, progress=None, reuse: bool = True,
              figure_process: bool = False) -> SceneResult:
    """Compute a scene's outputs; with `out`, write them (atomically) and ``out/manifest.json``.

    reuse: keep the outputs of an earlier run in `out` whose key and files are unchanged (False:
    draw every output afresh). figure_process: draw the figures in a second process while the
    products are computed (`validation.scenes.drawing`; where the platform allows), those that
    need no lifetimes as soon as their products are there (the command line's way)."""
    from validation.output import atomic_directory, software_versions

    if not isinstance(scene, Scene):
        scene = scene_from_mapping(scene) if isinstance(scene, dict) else load_scene(scene)
    from validation.output import check_file_names
    check_file_names(planned_files(scene), reserved={MANIFEST: "the scene's manifest"})
    study = scene.study()
    t0 = time.perf_counter()
    n = len(scene.outputs)
    if out is None:
        products = Products(study, cache_dir=cache_dir, progress=progress, keep_partial=True)
        for k, o in enumerate(scene.outputs):
            if progress is not None:
                progress(f"output {k + 1} of {n}: {o['name']}")
            _write(o, products, None)
        return SceneResult(scene, products.computed(), [], _timings(products), partial=partial_records(products))

    out = Path(out)
    made = [made_from(o, study) for o in scene.outputs]
    previous = _manifest(out) if reuse else None
    intact = [_intact_files(o, m["key"], previous, out) for o, m in zip(scene.outputs, made)]
    if previous is not None and _up_to_date(previous, scene, intact, out):
        files = [{**f, "path": str(out / f["path"])} for kept in intact for f in kept]
        return SceneResult(scene, {}, files, {}, kept=list(files), up_to_date=True,
                           partial=previous.get("partial") or {})
    from validation.scenes.drawing import FigureDrawer, can_fork
    from validation.scenes.figures import NEEDS

    drawn = [k for k, (o, old) in enumerate(zip(scene.outputs, intact)) if o["kind"] == "figure" and not old]
    with FigureDrawer(forked=figure_process and bool(drawn) and can_fork()) as drawer, \
            atomic_directory(out) as tmp:
        products = Products(study, cache_dir=cache_dir, progress=progress, keep_partial=True)
        try:
            # a figure needing no lifetimes is drawn aside while they are computed
            early = {k: _write(scene.outputs[k], products, Path(tmp), drawer) for k in drawn
                     if drawer.forked and "lifetimes" not in NEEDS[scene.outputs[k]["figure"]]}
            files, kept = [], []
            for k, (o, origin, old) in enumerate(zip(scene.outputs, made, intact)):
                if progress is not None:
                    progress(f"output {k + 1} of {n}: {o['name']}")
                linked = _link(old, out, Path(tmp)) if old else None
                if linked is not None:
                    kept += linked
                    files += linked
                    continue
                written = early[k] if k in early else _write(o, products, Path(tmp), drawer)
                files += [{**f, **origin} for f in written]
            drawer.wait()
        except BaseException:
            drawer.close()                 # nothing is drawn into the directory once it is removed
            raise
        files = [f if "sha256" in f else {**f, "sha256": file_digest(f["path"])} for f in files]
        partial = partial_records(products)
        if any(old for old in intact):     # an output kept from the previous run keeps its partial record
            partial = {**(previous or {}).get("partial", {}), **partial}
        manifest = {"files": [{**f, "path": Path(f["path"]).name} for f in files],
                    "scene": scene.resolved(), "source": scene.source, **({"partial": partial} if partial else {}),
                    "versions": software_versions(),
                    "timings_s": {**_timings(products), "total": time.perf_counter() - t0}}
        (Path(tmp) / MANIFEST).write_text(json.dumps(manifest, indent=1, default=str) + "\n")
    rename = lambda f: {**f, "path": str(out / Path(f["path"]).name)}    # noqa: E731
    return SceneResult(scene, products.computed(), [rename(f) for f in files], _timings(products),
                       kept=[rename(f) for f in kept], partial=partial)


def _timings(products: Products) -> dict[str, float]:
    """The time [s] of each product computed, a swept value's own as "<value>: <product>" (the
    sweep's "variants" only gathers them)."""
    timings = {k: v for k, v in products.timings.items() if k != "variants"}
    if "variants" in products.computed():
        for value, p in products.variants():
            timings.update({f"{value}: {k}": v for k, v in p.timings.items()})
    return timings


def partial_records(products: Products) -> dict[str, dict[str, Any]]:
    """The partial stiffness curves the scene's outputs used (`Products.partial`), by study: "study"
    for the scene's own, "<sweep key> = <value>" for a swept one; {} when every curve is complete."""
    records = {"study": products.partial()}
    if products.study.sweep is not None and "variants" in products.computed():
        records.update({f"{products.study.sweep.key} = {value}": p.partial() for value, p in products.variants()})
    return {k: v for k, v in records.items() if v is not None}


def partial_lines(records: Mapping[str, Mapping[str, Any]], spelling: str = "scene") -> list[str]:
    """One line per partial curve: where and why its FEM path stopped, what it converged to, the
    u_max that runs (the setting as `spelling` writes it) and the forces refused."""
    from validation.bridge.pipeline import runnable_u_max_mm
    from validation.study_schema import field_of

    lines = []
    for study, r in records.items():
        where = "" if study == "study" else f" ({study})"
        runs = field_of("stiffness.u_max_mm").setting(spelling, runnable_u_max_mm(r["u_max_mm_that_runs"]))
        line = (f"partial{where}: the FEM path stopped at u = {r['failed_at_u_mm']:.4g} mm ({r['failure_reason']}); "
                f"the stiffness curve is its converged part, u = 0 to {r['u_max_mm_that_runs']:.4g} mm (flagged "
                f"partial); {runs} runs")
        if r.get("refused"):
            forces = ", ".join(f"{x['force_N']:g}" for x in r["refused"])
            line += f"; lifetimes refused at F1 = {forces} N, beyond the curve: {r['refused'][0]['message']}"
        lines.append(line)
    return lines


def _manifest(out: Path) -> dict | None:
    """The manifest of the previous run into `out` (None: no readable one)."""
    try:
        manifest = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return manifest if isinstance(manifest, dict) and isinstance(manifest.get("files"), list) else None


def _intact_files(output: Mapping[str, Any], key: str, manifest: dict | None, out: Path) -> list[dict]:
    """The previous run's files of `output` if it was made from the same key and every file is
    present with the bytes the manifest recorded; else [] (the output is drawn again)."""
    if manifest is None:
        return []
    files = [f for f in manifest["files"]
             if isinstance(f, dict) and (f.get("name"), f.get("kind")) == (output["name"], output["kind"])]
    if not files or any(f.get("key") != key or not _same_bytes(out, f) for f in files):
        return []
    return files


def _same_bytes(directory: Path, entry: Mapping[str, Any]) -> bool:
    """`entry`'s file (a plain name in `directory`) is there and its sha256 is the recorded one."""
    name, digest = entry.get("path"), entry.get("sha256")
    if not (isinstance(name, str) and isinstance(digest, str)) or Path(name).name != name or name in ("", ".", ".."):
        return False
    path = directory / name
    return path.is_file() and not path.is_symlink() and file_digest(path) == digest


def _up_to_date(manifest: dict, scene: Scene, intact: list[list[dict]], out: Path) -> bool:
    """Every output intact, the manifest lists no other file, `out` holds no file it does not list
    and it records this very scene: nothing to write."""
    if not all(intact) or sum(map(len, intact)) != len(manifest["files"]):
        return False
    if {p.name for p in out.iterdir()} != {f["path"] for f in manifest["files"]} | {MANIFEST}:
        return False                       # a file the manifest does not list: the rerun replaces the directory
    resolved = json.loads(json.dumps(scene.resolved(), default=str))
    return manifest.get("scene") == resolved and manifest.get("source") == scene.source


def _link(entries: list[dict], out: Path, tmp: Path) -> list[dict] | None:
    """Link an intact output's files from the previous directory into the new one (a copy keeping
    the mtime where links are not possible); None if one changed meanwhile (draw it again)."""
    done = []
    for entry in entries:
        source, target = out / entry["path"], tmp / entry["path"]
        try:
            os.link(source, target)
        except OSError:
            try:
                shutil.copy2(source, target)
            except OSError:
                break
        done.append(target)
        if file_digest(target) != entry["sha256"]:
            break
    else:
        return [{**e, "path": str(tmp / e["path"])} for e in entries]
    for target in done:
        target.unlink(missing_ok=True)
    return None


def _write(output: dict, products: Products, tmp: Path | None, drawer=None) -> list[dict[str, str]]:
    """Write `output` into `tmp` (None: compute only): its files (name, kind, path); a figure is
    drawn by `drawer` (`validation.scenes.drawing.FigureDrawer`; None: here), its files there once
    the drawer has waited."""
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
    paths = [] if tmp is None else [tmp / f"{name}.{suffix}" for suffix in ("png", "svg")]
    table = None if tmp is None else tmp / f"{name}_data.csv"
    (draw if drawer is None else drawer.submit)(output["figure"], products, paths, table)
    return [_file(name, "figure", path) for path in (*paths, *([table] if table else []))]


#: the files of each output kind, by suffix (as `_write` and `write_view` name them)
_SUFFIXES = {"curve": (".csv", ".json"), "lifetimes": (".csv",), "figure": (".png", ".svg", "_data.csv"),
             "render": (".png",), "footprint": (".png", ".json"), "squeeze": (".gif",)}


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
        "route": s.route, "stiffness": s.stiffness, **{k: v for k, v in s.record().items() if k != "route"},
        **_force_columns(products)})


def _force_columns(products: Products) -> dict[str, Any]:
    """The lifetime columns of one study, a row per force in the study's order: the force, the
    lifetime, the reason, the route's end state (`end_state_columns`); a force refused on a
    partial curve has the reason "beyond_partial_curve" and blank values, and every row of a
    partial curve says where the curve ends (``curve_partial_to_u_mm``)."""
    from validation.bridge.lifetimes import end_state_columns

    results, refused = products.lifetimes(), {r.force_N for r in products.refused()}
    at = {r.force_N: i for i, r in enumerate(results)}
    forces = [f for f in products.study.loads.forces_N if f in at or f in refused]
    rows = [at.get(f) for f in forces]
    pick = lambda values: [values[i] if i is not None else "" for i in rows]          # noqa: E731
    columns = {"force_N": forces, "lifetime_s": pick([r.lifetime_s for r in results]),
               "reason": [results[i].reason if i is not None else "beyond_partial_curve" for i in rows],
               **{k: pick(v) for k, v in end_state_columns(results).items()}}
    partial = products.partial()
    if partial is not None:
        columns["curve_partial_to_u_mm"] = partial["u_max_mm_that_runs"]
    return columns


def _sweep_table(products: Products, path: Path) -> Path:
    from validation.output import write_table

    key = products.study.sweep.key.split(".")[1]
    parts = [(value, p.study.record(), _force_columns(p)) for value, p in products.variants()]
    own = ("largest_force_N", "u_final_mm", "p_b_final_Pa", "seal_r_final_mm") if products.study.route == "fem" \
        else ("ballistic_share",)
    names = ["force_N", "lifetime_s", "reason", *own]
    if any("curve_partial_to_u_mm" in c for _, _, c in parts):
        names.append("curve_partial_to_u_mm")
    table = {key: [v for v, _, c in parts for _ in c["force_N"]]}
    table.update({k: [r[k] for _, r, c in parts for _ in c["force_N"]] for k in products.study.record()})
    for name in names:
        table[name] = [x for _, _, c in parts for x in _column(c, name)]
    return write_table(path, table, stage="scene sweep")


def _column(columns: Mapping[str, Any], name: str) -> list:
    """A column of `_force_columns` as a list of its rows (a value for every row repeated; blank if absent)."""
    value = columns.get(name, "")
    return value if isinstance(value, list) else [value] * len(columns["force_N"])


def _trajectory(result, path: Path) -> Path:
    from validation.output import write_table
    return write_table(path, dict(result.trajectory_columns()))


