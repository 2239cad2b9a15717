"""The gallery of the shipped scenes: run each one, keep its GIF or first image, write scenes/README.md;
with --paper, the paper's figure set instead: docs/paper-figures.md and its images.

    python -m validation.scenes.gallery [--scenes scenes] [--no-cache]
    python -m validation.scenes.gallery --paper [--docs docs] [--no-cache]

Every image in a gallery is reproduced by the `cupcheck run` or `cupcheck paper` command printed
with it. The paper set's images are kept as 64-colour PNGs (journal column width, < 150 kB each).
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
    ap.add_argument("--paper", action="store_true", help="the paper's figure set (docs/paper-figures.md)")
    ap.add_argument("--docs", type=Path, default=Path("docs"))
    args = ap.parse_args()
    if args.paper:
        paper_gallery(args.docs, cache_dir=None if args.no_cache else user_cache_dir("scenes"))
        return
    images = args.scenes / "gallery"
    images.mkdir(exist_ok=True)
    lines = ["# Scene gallery", "",
             "Each shipped scene, its animation or first image and the command that made it (regenerate this page with",
             "`python -m validation.scenes.gallery`). Scene keys: `docs/scenes.md`. Cold and warm run times",
             "of every scene: the README (`python benchmarks/bench_scenes.py`). The paper's calculated figures,",
             "FEM-fed beside the paper's inputs, in one command (`cupcheck paper --out DIR`): docs/paper-figures.md.", ""]
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



def paper_gallery(docs: Path, fidelity: str = "coarse", cache_dir: Path | None = None) -> Path:
    """Draw the paper set (`validation.scenes.paper.run_paper`) and write docs/paper-figures.md with
    each image (docs/paper-figures/NAME.png), its command, the paper's numbers marked on it and the
    sentence on what agrees; return the page."""
    from validation.scenes.paper import run_paper
    from validation.scenes.paper_marks import paper_numbers

    images = docs / "paper-figures"
    images.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        results = run_paper(Path(tmp) / "paper", fidelity=fidelity, cache_dir=cache_dir)
        for r in results:
            png = next(p for p in r.files if p.suffix == ".png")
            small_png(png, images / png.name)
    lines = ["# The paper's figures, drawn by cupcheck", "",
             "Each calculated figure of Tiwari & Persson's Sec. 5, drawn by one command:", "",
             f"    cupcheck paper --out out/paper            # all eight, {fidelity} FEM; --only NAME for one", "",
             "A command rather than a folder of scenes: each figure overlays two studies (the FEM-fed case and the "
             "same case on the paper's inputs) and the paper's numbers, which one scene file does not express, "
             "and `cupcheck paper --out DIR` is the shortest thing to type.", "",
             f"Solid lines are fed by the FEM (the cup's frictionless FEM at the {fidelity} level through the profile "
             "route: its F0, contact radius, volume and contact-pressure profile); dashed lines by the paper's own "
             "inputs (Appendix A's F0 with d0 = 2 mm, Table 1's rigid cone and eq (6)'s strip: the paper route; the "
             "paper's measured F0 is published only as a plot, so Appendix A's formula stands in for it). "
             "Both use what the paper's lifetimes used: air at 293.15 K and 1e5 Pa, the relaxation modulus "
             "E_eff(t) (in water E = 4 MPa, the paper's dashed lines of Fig. 1rStart) and the calibrated surfaces. "
             "Black marks are the numbers the paper states (text and Table 1 only, none read off its plots), "
             "kept with their sources in `validation/data/paper_numbers.toml`. Beside each PNG the command writes "
             "an SVG and a CSV of everything drawn (columns design, contact, mesh, route, surface, ...).", "",
             "Regenerate this page and its images with `python -m validation.scenes.gallery --paper`; the "
             "sentences are computed from the drawn numbers.", ""]
    for r in results:
        f = r.figure
        marks = [_number_text(n) for n in paper_numbers(f.name) if n.kind != "input"]
        lines += [f"## {f.name}", "", f"{f.shows}; the paper's {f.paper}.", "",
                  f"    cupcheck paper --out out/paper --only {f.name}", "",
                  f"![{f.name}](paper-figures/{f.name}.png)", "",
                  f"**Against the paper.** {r.sentence}", "",
                  f"Paper numbers: {'; '.join(marks) if marks else 'none stated for this figure'}.", ""]
        print(f"{f.name}: {(images / f'{f.name}.png').stat().st_size // 1024} kB")
    page = docs / "paper-figures.md"
    page.write_text("\n".join(lines))
    return page


def _number_text(n) -> str:
    """A paper number for the page: its label, its value where the label has none, its source."""
    text = f"{n.label}: {n.value:g} {n.unit}" if n.kind == "point" else n.label     # the other labels hold it
    return text if n.source in text else f"{text} ({n.source})"


def small_png(src: Path, dst: Path, colours: int = 64) -> Path:
    """`src` as a palette PNG of `colours` colours (line figures lose nothing visible; 3-4x smaller)."""
    from PIL import Image

    with Image.open(src) as im:
        im.convert("RGB").quantize(colors=colours).save(dst, optimize=True)
    return dst


if __name__ == "__main__":
    main()
