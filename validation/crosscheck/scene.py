"""One 3D scene: cup A (sticking) at the last load step, cut through the axis and seen side-on,
the wall coloured by the von Mises stress and the contact pressure's profile below the plane."""

from __future__ import annotations

from validation.crosscheck.context import CROSSCHECK_FIDELITY, Context
from validation.crosscheck.runs import FemRun


def deformed_cup_scene(ctx: Context) -> None:
    """Render `deformed_cup.png` and `deformed_cup_pressure.png` if off-screen rendering works,
    else say why in the report. The memo keeps only plain arrays, so the state drawn is the same
    request run once more here (the nodal fields need the mesh and the displacements)."""
    from validation.render import probe_offscreen_rendering

    probe = probe_offscreen_rendering()
    if not probe.ok:
        ctx.report.text("scene", f"Scene skipped: {probe.message}")
        ctx.report.summary["scene"] = f"skipped: {probe.message}"
        return
    from fem.cup import compress_cup
    from fem.mesh import cup_mesh
    from validation.render.frames import frame_from_response
    from validation.render.views import section

    request = FemRun(cup="A", contact="sticking", fidelity=CROSSCHECK_FIDELITY)
    ctx.progress(0.0, f"{request.label()} (scene)")
    geometry = request.geometry()
    resp = compress_cup(cup_mesh(geometry, request.fidelity, element=request.element), request.material(),
                        contact=request.contact, u_max_m=request.u_max_over_h1 * geometry.h1_m,
                        max_step=request.max_step)
    frame = frame_from_response(resp, -1)
    what = f"cup A, {request.contact}, {request.fidelity} mesh, u = {1e3 * frame.u_m:.2f} mm"
    paths = [section(frame, "von_mises", ctx.report.root / "deformed_cup.png", title=what).path,
             section(frame, "contact_pressure", ctx.report.root / "deformed_cup_pressure.png", title=what).path]
    ctx.report.files.extend(p.name for p in paths)
    ctx.report.text("scene", f"![deformed cup A]({paths[0].name}) ![contact pressure]({paths[1].name})\n\n"
                             f"*{what[0].upper() + what[1:]}, cut through the axis and seen side-on: the wall "
                             "coloured by the von Mises stress; the contact pressure's profile p(r) below "
                             "the plane.*")
    ctx.report.summary["scene"] = paths[0].name
