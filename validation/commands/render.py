"""Render a 3D view of a stiffness run's fields (the file written by `cupcheck stiffness --fields-out`).

Views (pyvista off-screen, the child-process GL probe first):
  cutaway    the deformed cup revolved through 270 deg and cut open, coloured by --field (PNG)
  footprint  the contact seen from below through the substrate, at a fixed scale (PNG; the pixel
             size and the contact zones go to a JSON beside it)
  squeeze    --frames views of the half cup side-on from the first to the last step of an .xdmf
             series, as an animated GIF
Fields: contact_pressure (recovered smoothly from the nodal reactions), von_mises (L2 projection of
the file's element-mean Cauchy stress), min_stretch (from the file's displacement). A .vtu/.vtk
holds one step; from an .xdmf series --u-mm picks the step nearest u (default the last).
Every image is captioned with the design, contact law and mesh level the fields file records
(an older file without that record: captioned as unknown).

Bad input (a missing or foreign file, a suffix that does not fit the view, --u-mm or --frames out
of range) stops with one line naming the option and exit status 2, before anything is written.

examples:
  cupcheck stiffness --cup A --u-max-mm 6 --fields-out out/cupA.xdmf --out out/cupA.csv
  cupcheck render out/cupA.xdmf --view cutaway --field von_mises --out out/cupA_vm.png
  cupcheck render out/cupA.xdmf --view footprint --u-mm 5 --out out/cupA_footprint.png
  cupcheck render out/cupA.xdmf --view squeeze --frames 8 --out out/cupA_squeeze.gif
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from pathlib import Path

NAME = "render"
HELP = "3D view (cut-away, footprint from below, squeeze GIF) of a stiffness run's fields file"

VIEWS = {"cutaway": ".png", "footprint": ".png", "squeeze": ".gif"}
FIELDS = ("contact_pressure", "von_mises", "min_stretch")
MAX_FRAMES = 60


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("fields", type=Path, metavar="FIELDS",
                   help="a fields file of cupcheck stiffness --fields-out (.vtu, .vtk, or an .xdmf series)")
    p.add_argument("--view", choices=tuple(VIEWS), default="cutaway", help="what to draw (default cutaway)")
    p.add_argument("--field", choices=FIELDS, default="contact_pressure",
                   help="the colouring of cutaway and squeeze (default contact_pressure)")
    p.add_argument("--u-mm", type=float, default=None, dest="u_mm",
                   help="plate displacement u [mm] of the step shown, > 0 (an .xdmf series: the nearest step)")
    p.add_argument("--frames", type=int, default=8, help=f"frames of the squeeze, in [2, {MAX_FRAMES}] (default 8)")
    p.add_argument("--out", type=Path, required=True, metavar="FILE", help="the image: .png (cutaway, footprint), .gif (squeeze)")


def run(args: argparse.Namespace) -> int:
    from validation.output import atomic_file

    _check(args)
    from validation.output import check_outputs, command_inputs
    check_outputs(files={"--out": args.out}, inputs=command_inputs(args),
                  companions={"--out's scale": (args.out.with_suffix(".json") if args.view == "footprint" else None, "m_per_px")})
    from validation.render import views
    from validation.render.frames import fields_file_steps, frame_from_fields_file

    if args.view == "squeeze":
        steps = fields_file_steps(args.fields)
        if len(steps) < 2:
            raise ValueError(f"fields: the squeeze needs an .xdmf series of several steps; '{args.fields.name}' "
                             "holds one (write it with --fields-out NAME.xdmf)")
        caption = _caption(args.fields)
        targets = [steps[0] + (steps[-1] - steps[0]) * k / (args.frames - 1) for k in range(args.frames)]
        frames = [frame_from_fields_file(args.fields, u_mm=1e3 * t, fields=(args.field,)) for t in targets]
        with atomic_file(args.out) as tmp, tempfile.TemporaryDirectory() as d:
            seq = views.squeeze(frames, args.field, Path(d) / "frame", title=caption)
            Path(tmp).write_bytes(seq.gif.read_bytes())
        print(f"cupcheck render: wrote {args.out} ({len(frames)} frames, u = {1e3 * seq.u_m[0]:.3g} .. "
              f"{1e3 * seq.u_m[-1]:.3g} mm)")
        return 0
    frame = frame_from_fields_file(args.fields, u_mm=args.u_mm)
    if args.view == "footprint" and not frame.zones_m:
        raise ValueError(f"u_mm: no contact at u = {1e3 * frame.u_m:.4g} mm in '{args.fields.name}'; choose a "
                         "later step")
    scale = args.out.with_suffix(".json")
    caption = _caption(args.fields)
    with atomic_file(args.out) as tmp:
        if args.view == "cutaway":
            views.cutaway(frame, args.field, tmp, title=f"{caption}, u = {1e3 * frame.u_m:.3g} mm")
        else:
            image = views.footprint(frame, tmp, title=f"{caption}, from below, u = {1e3 * frame.u_m:.3g} mm")
            with atomic_file(scale) as tmp_scale:
                tmp_scale.write_text(json.dumps({"m_per_px": image.m_per_px, "centre_px": image.centre_px,
                                                 "contact_zones_m": image.zones_m, "u_m": frame.u_m}) + "\n")
    extra = f" and {scale.name}" if args.view == "footprint" else ""
    print(f"cupcheck render: wrote {args.out}{extra} ({args.view}, u = {1e3 * frame.u_m:.3g} mm)")
    return 0


def _caption(fields: Path) -> str:
    """The caption of the fields file's provenance record (its parts unknown without one)."""
    from xml.etree.ElementTree import ParseError

    from fem.fields import read_provenance
    from validation.render.caption import provenance_caption

    try:
        return provenance_caption(read_provenance(fields))
    except (ValueError, ParseError, UnicodeError) as exc:
        raise ValueError(f"fields: cannot read the provenance of '{fields.name}': {exc}".replace("\n", " ")) from None


def _check(args: argparse.Namespace) -> None:
    """Every check before any work (one line naming the option)."""
    if not args.fields.is_file():
        raise ValueError(f"fields: no such file '{args.fields}'")
    suffix = args.fields.suffix.lower()
    if suffix not in (".vtu", ".vtk", ".xdmf"):
        raise ValueError(f"fields: expected a .vtu, .vtk or .xdmf file of cupcheck stiffness --fields-out, "
                         f"got '{args.fields.name}'")
    want = VIEWS[args.view]
    if args.out.suffix.lower() != want:
        raise ValueError(f"out: the {args.view} view writes a {want} file, got '{args.out}'")
    if args.out.is_dir():
        raise ValueError(f"out: '{args.out}' is a directory; give a file name")
    if args.u_mm is not None:
        if not (math.isfinite(args.u_mm) and args.u_mm > 0):
            raise ValueError(f"u_mm: the plate displacement must be > 0 mm, got {args.u_mm:g}")
        if suffix != ".xdmf":
            raise ValueError(f"u_mm: '{args.fields.name}' holds one step; --u-mm picks a step of an .xdmf series")
        if args.view == "squeeze":
            raise ValueError("u_mm: the squeeze runs over the whole series; drop --u-mm")
    if not 2 <= args.frames <= MAX_FRAMES:
        raise ValueError(f"frames: must be in [2, {MAX_FRAMES}], got {args.frames}")
    if args.frames != 8 and args.view != "squeeze":
        raise ValueError("frames: only for --view squeeze")
