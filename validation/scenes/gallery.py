"""The gallery of the shipped scenes: run each one, keep its GIF or first image, write scenes/README.md.

    python -m validation.scenes.gallery [--scenes scenes] [--no-cache]

Every image in the gallery is reproduced by the `cupcheck run` command printed under it.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
from pathlib import Path

from validation.bridge.cache import user_cache_dir
from validation.scenes.outputs import run_scene
from validation.scenes.schema import load_scene


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=Path, default=Path("scenes"))
    ap.add_argument("--no-cache", action="store_true")
    args = ap.parse_args()
    images = args.scenes / "gallery"
    images.mkdir(exist_ok=True)
    lines = ["# Scene gallery", "",
             "Each shipped scene, its animation or first image and the command that made it (regenerate this page with",
             "`python -m validation.scenes.gallery`). Scene keys: `docs/scenes.md`. Cold and warm run times",
             "of every scene: the README (`python benchmarks/bench_scenes.py`).", ""]
    for scene_path in sorted(args.scenes.glob("*.toml")):
        if scene_path.name.startswith("sweep_"):
            continue
        scene = load_scene(scene_path)
        with tempfile.TemporaryDirectory() as tmp:
            cache = None if args.no_cache else user_cache_dir("scenes")
            result = run_scene(scene, Path(tmp) / "out", cache_dir=cache)
            paths = [Path(f["path"]) for f in result.files]
            image = next((p for p in paths if p.suffix == ".gif"), None) or \
                next((p for p in paths if p.suffix == ".png"), None)        # an animation first
            kept = None
            if image is not None:
                kept = images / f"{scene_path.stem}{image.suffix}"
                shutil.copyfile(image, kept)
        head = []
        for ln in scene_path.read_text().splitlines():
            if not ln.startswith("#"):
                break
            if "cupcheck run" not in ln:
                head.append(ln.lstrip("# ").strip())
        comment = " ".join(head)
        lines += [f"## {scene_path.stem}", "", comment, "",
                  f"    cupcheck run scenes/{scene_path.name} --out out/{scene_path.stem}", "",
                  f"outputs: {', '.join(sorted({Path(f['path']).name for f in result.files}))}", ""]
        if kept is not None:
            lines += [f"![{scene_path.stem}](gallery/{kept.name})", ""]
        print(f"{scene_path.name}: {len(result.files)} files")
    lines += ["## sweep_alpha_thickness", "", "A design sweep (not a scene): see the README's Design sweeps.", "",
              "    cupcheck sweep scenes/sweep_alpha_thickness.toml --out out/sweep", ""]
    (args.scenes / "README.md").write_text("\n".join(lines))


if __name__ == "__main__":
    main()
