"""The scene outputs drawn in 3D from FEM states: render (cut-away), footprint, squeeze.

Each pulls only the deformed states it shows (`Products.fem_frames`: the FEM run only to the
largest u asked for) and draws them with `validation.render.views`. The footprint's scale (metres
per pixel, the axis pixel and the contact zones drawn) goes into a JSON file beside the image, so
the image can be measured, with the provenance the title names (design, contact law, mesh level)
and the wall's material, keyed as a fields file's record (`validation.render.caption.view_record`).
"""

from __future__ import annotations

import json
from pathlib import Path

from validation.bridge.products import Products

__all__ = ["write_view", "view_caption", "view_provenance"]


def write_view(output: dict, products: Products, tmp: Path | None) -> list[dict[str, str]]:
    """Compute the states of a render, footprint or squeeze output and (with `tmp`) draw them."""
    kind, name, u_mm = output["kind"], output["name"], output["u_mm"]
    frames = products.fem_frames(u_mm, output["frames"] if kind == "squeeze" else 1)
    if tmp is None:
        return []
    from validation.render import views

    law = view_caption(products)
    files = []
    if kind == "render":
        image = views.cutaway(frames[-1], output["field"], tmp / f"{name}.png",
                              title=f"{law}, u = {1e3 * frames[-1].u_m:.3g} mm")
        files.append(_file(name, kind, image.path))
    elif kind == "footprint":
        image = views.footprint(frames[-1], tmp / f"{name}.png",
                                title=f"{law}, from below, u = {1e3 * frames[-1].u_m:.3g} mm")
        scale = tmp / f"{name}.json"
        scale.write_text(json.dumps({**view_provenance(products), "m_per_px": image.m_per_px,
                                     "centre_px": image.centre_px, "view_box_px": image.view_box_px,
                                     "scale_bar_m": image.scale_bar_m, "contact_zones_m": image.zones_m,
                                     "u_m": frames[-1].u_m}, indent=1) + "\n")
        files += [_file(name, kind, image.path), _file(name, kind, scale)]
    else:
        seq = views.squeeze(frames, output["field"], tmp / name, title=law)
        files += [_file(name, kind, p) for p in seq.frames] + [_file(name, kind, seq.gif)]
    return files


def view_caption(products: Products) -> str:
    """What a 3D view shows: the design, the FEM's contact law (with mu) and its mesh level."""
    from validation.render.caption import provenance_caption

    return provenance_caption(view_provenance(products))


def view_provenance(products: Products) -> dict[str, str]:
    """The provenance of the states a 3D view draws (`validation.render.caption.view_record`): the
    design, the contact law, the mesh level and the wall's material (its formulation by nu, as
    the FEM ran it)."""
    from validation.bridge.pipeline import neo_hookean
    from validation.render.caption import material_label, view_record

    s = products.study
    formulation = neo_hookean(s.material.E_MPa * 1e6, s.material.nu).formulation
    return view_record(s.design.label, s.contact.label(), s.fidelity,
                       material_label(s.material.E_MPa, s.material.nu, formulation))


def _file(name: str, kind: str, path: Path) -> dict[str, str]:
    return {"name": name, "kind": kind, "path": str(path)}
