"""The caption of a 3D view: which design, contact law and mesh level the drawn states are of.

One wording for the scene views (`validation.scenes.views3d`) and for ``cupcheck render`` of a
fields file (its provenance record, `fem.fields.read_provenance`); what a record lacks (an older
fields file has none) is named as unknown rather than left out. `view_record` is that record for a
scene's view (the footprint's scale file repeats it), with the fields file's keys and wording.
"""

from __future__ import annotations

from collections.abc import Mapping

__all__ = ["view_caption_of", "provenance_caption", "material_label", "view_record"]


def view_caption_of(design: str | None, contact: str | None, mesh_level: str | None) -> str:
    """"cup A, coulomb mu = 0.5, coarse mesh"; a part given as None reads as unknown."""
    return (f"{design or 'design unknown'}, {contact or 'contact law unknown'}, "
            f"{mesh_level + ' mesh' if mesh_level else 'mesh level unknown'}")


def provenance_caption(record: Mapping[str, str]) -> str:
    """The caption of a fields file's provenance record (keys design, contact, mesh)."""
    return view_caption_of(record.get("design"), record.get("contact"), record.get("mesh"))


def material_label(E_MPa: float, nu: float, formulation: str) -> str:
    """"neo-Hookean E = 4 MPa, nu = 0.49 (displacement)": the wall's material as a fields file records it."""
    return f"neo-Hookean E = {E_MPa:g} MPa, nu = {nu:g} ({formulation})"


def view_record(design: str, contact: str, mesh_level: str, material: str) -> dict[str, str]:
    """The provenance of a drawn state, keyed as a fields file's (design, contact, mesh, material):
    `provenance_caption` of it is the view's caption."""
    return {"design": design, "contact": contact, "mesh": mesh_level, "material": material}
