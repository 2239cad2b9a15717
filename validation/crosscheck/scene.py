"""One 3D scene: cup A (sticking) at the last load step, revolved, coloured by contact pressure."""

from __future__ import annotations

from validation.crosscheck.context import CROSSCHECK_FIDELITY, Context
from validation.crosscheck.runs import FemRun


def deformed_cup_scene(ctx: Context) -> None:
    """Render `deformed_cup.png` if off-screen rendering works, else say why in the report."""
    from validation.render import probe_offscreen_rendering, render_cup

    probe = probe_offscreen_rendering()
    if not probe.ok:
        ctx.report.text("scene", f"Scene skipped: {probe.message}")
        ctx.report.summary["scene"] = f"skipped: {probe.message}"
        return
    res = ctx.fem(FemRun(cup="A", contact="sticking", fidelity=CROSSCHECK_FIDELITY))
    path = render_cup(res.outline_r_m, res.outline_z_m, ctx.report.root / "deformed_cup.png",
                      scalar=res.outline_p_Pa / 1e3, scalar_name="contact pressure (kPa)",
                      title=f"cup A, sticking, u = {1e3 * res.u_m[-1]:.2f} mm")
    ctx.report.files.append(path.name)
    ctx.report.text("scene", f"![deformed cup A]({path.name})\n\n*Cup A (sticking) at u = "
                             f"{1e3 * res.u_m[-1]:.2f} mm, coloured by the contact pressure.*")
    ctx.report.summary["scene"] = path.name
