"""The 3D views of a deformed cup (`validation.render.frames.CupFrame`), off-screen to PNG and GIF.

* `cutaway`: the cup revolved through 270 deg, the missing quarter showing the cross-section, both
  coloured by a chosen nodal field (`fem.recovery.FIELDS`), above the substrate plane.
* `footprint`: the contact seen from below through the substrate (the sealing annulus), in a
  parallel projection whose scale is fixed, so that a pixel is a known length (`FootprintImage`).
* `squeeze`: frames of the half cup (cut through the axis) seen side-on, at a fixed scale and a
  colour range fixed over the sequence, and the animated GIF of them (pillow).

All go through `require_offscreen_rendering` (the child-process GL probe) before the first window.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from validation.render import require_offscreen_rendering
from validation.render.frames import CupFrame

__all__ = ["cutaway", "footprint", "squeeze", "FootprintImage", "SqueezeImages", "field_display"]

#: per field: the factor to the displayed unit, and the colour bar's title
_DISPLAY = {"contact_pressure": (1e-3, "contact pressure (kPa)"), "von_mises": (1e-3, "von Mises stress (kPa)"),
            "min_stretch": (1.0, "smallest principal stretch")}
# the 9-node quad (VTK order) as 4 bilinear quads, the 6-node triangle as 4 triangles
_SUB = {9: ((0, 4, 8, 7), (4, 1, 5, 8), (8, 5, 2, 6), (7, 8, 6, 3)), 6: ((0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5))}


@dataclass(frozen=True)
class FootprintImage:
    """A footprint image: its path, the length of one pixel [m], the pixel (column, row) of the axis,
    and the contact zones drawn [(r_in, r_out)] [m]."""

    path: Path
    m_per_px: float
    centre_px: tuple[float, float]
    zones_m: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class SqueezeImages:
    """A squeeze sequence: the frames (PNG), the animated GIF, the plate displacement of each frame
    [m], and the length of one pixel [m]."""

    frames: tuple[Path, ...]
    gif: Path
    u_m: tuple[float, ...]
    m_per_px: float


def field_display(field: str) -> tuple[float, str]:
    """(factor from SI to the displayed unit, colour-bar title) of a field."""
    if field not in _DISPLAY:
        raise ValueError(f"field: expected one of {', '.join(_DISPLAY)}, got {field!r}")
    return _DISPLAY[field]


def _surfaces(frame: CupFrame, field: str, start_deg: float, angle_deg: float, resolution: int):
    """The revolved boundary and the two cut faces (cross-sections at start and start + angle),
    in mm, with the field (display units) as point data 'value'."""
    import pyvista as pv

    factor, _ = field_display(field)
    value = factor * np.asarray(frame.fields[field], float)
    rz = 1e3 * frame.points_m
    loop = frame.loop
    t0 = np.radians(start_deg)
    pts = np.column_stack([rz[loop, 0] * np.cos(t0), rz[loop, 0] * np.sin(t0), rz[loop, 1]])
    outline = pv.PolyData(pts, lines=np.hstack([[loop.size + 1], np.arange(loop.size), [0]]))
    outline.point_data["value"] = value[loop]
    shell = outline.extrude_rotate(resolution=resolution, angle=angle_deg, capping=False)
    sub = np.array(_SUB[frame.cells.shape[1]])
    conn = frame.cells[:, sub].reshape(-1, sub.shape[1])        # [4 nel, 4 or 3] node ids
    faces = np.column_stack([np.full(len(conn), sub.shape[1]), conn]).ravel()
    caps = []
    for theta in (t0, t0 + np.radians(angle_deg)):
        cap = pv.PolyData(np.column_stack([rz[:, 0] * np.cos(theta), rz[:, 0] * np.sin(theta), rz[:, 1]]), faces)
        cap.point_data["value"] = value
        caps.append(cap)
    return shell, caps


def _plotter(window_size: tuple[int, int]):
    require_offscreen_rendering()
    import pyvista as pv
    return pv.Plotter(off_screen=True, window_size=window_size)


def _save(plotter, png: str | Path) -> Path:
    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    try:
        plotter.screenshot(str(png))
    finally:
        plotter.close()
    return png


def cutaway(frame: CupFrame, field: str, png: str | Path, *, title: str = "",
            clim: tuple[float, float] | None = None, window_size: tuple[int, int] = (900, 700)) -> Path:
    """The cup revolved through 270 deg and cut open, coloured by `field`, above the substrate
    (seen from above; the contact pressure, which acts on the underside, from below through the
    translucent substrate)."""
    import pyvista as pv

    _, bar = field_display(field)
    shell, caps = _surfaces(frame, field, 0.0, 270.0, 90)
    extent = 1.3e3 * float(frame.points_m[:, 0].max())
    p = _plotter(window_size)
    p.add_mesh(pv.Plane(center=(0, 0, 0), direction=(0, 0, 1), i_size=2 * extent, j_size=2 * extent),
               color="lightsteelblue", opacity=0.5 if field != "contact_pressure" else 0.15)
    kw = dict(scalars="value", cmap="viridis", clim=clim or _range(frame, field))
    if field == "contact_pressure":                          # the underside: lit from the camera
        import pyvista as pv
        p.add_light(pv.Light(light_type="headlight", intensity=0.8))
    p.add_mesh(shell, smooth_shading=True, scalar_bar_args={"title": bar, "fmt": "%.3g"}, **kw)
    for cap in caps:
        p.add_mesh(cap, show_scalar_bar=False, **kw)
    if title:
        p.add_text(title, font_size=10)
    elevation = 1.3 if field != "contact_pressure" else -1.3
    p.camera_position = [(1.6 * extent, -2.2 * extent, elevation * extent), (0, 0, 0.25 * extent), (0, 0, 1)]
    return _save(p, png)


def _range(frame: CupFrame, field: str) -> tuple[float, float]:
    factor, _ = field_display(field)
    v = factor * np.asarray(frame.fields[field], float)
    lo, hi = (0.0, float(v.max())) if field != "min_stretch" else (float(v.min()), 1.0)
    return (lo, hi if hi > lo else lo + 1.0)


def footprint(frame: CupFrame, png: str | Path, *, half_height_m: float | None = None, size_px: int = 600,
              title: str = "") -> FootprintImage:
    """The contact seen from below through the substrate: each contact zone an annulus coloured by
    the recovered contact pressure (plasma), the rest of the cup grey, the substrate translucent.
    Parallel projection with the axis at the image centre: the image's height is 2 half_height_m
    (default 1.15 times the cup's largest radius), so one pixel is 2 half_height_m / size_px.
    A zone of zero width (a line contact at the rim corner) is drawn one pixel wide."""
    import pyvista as pv

    if not frame.zones_m:
        raise ValueError(f"footprint: no contact at u = {1e3 * frame.u_m:.4g} mm; choose a larger u_mm")
    half = half_height_m or 1.15 * float(frame.points_m[:, 0].max())
    m_per_px = 2 * half / size_px
    width = size_px + 200                                      # room for the colour bar on the right
    shell, _ = _surfaces(frame, "contact_pressure", 0.0, 360.0, 180)
    p = _plotter((width, size_px))
    p.set_background("white")
    p.add_mesh(shell, color="silver", smooth_shading=True)
    on_plane = _plane_profile(frame)
    pmax = max(1e-3 * float(on_plane[1].max()), 1e-9)
    for r_in, r_out in frame.zones_m:
        if r_out - r_in < m_per_px:                            # a line contact: one pixel wide
            mid = 0.5 * (r_in + r_out)
            r_in, r_out = mid - 0.5 * m_per_px, mid + 0.5 * m_per_px
        disc = pv.Disc(center=(0, 0, -0.05), inner=1e3 * r_in, outer=1e3 * r_out, normal=(0, 0, -1),
                       r_res=max(int((r_out - r_in) / m_per_px), 2), c_res=720)
        disc.point_data["value"] = 1e-3 * np.interp(1e-3 * np.hypot(disc.points[:, 0], disc.points[:, 1]),
                                                    *on_plane)
        p.add_mesh(disc, scalars="value", cmap="plasma", clim=(0.0, pmax), lighting=False,
                   scalar_bar_args={"title": "contact pressure (kPa)", "vertical": True,
                                    "position_x": 0.89, "position_y": 0.1, "height": 0.8, "width": 0.04,
                                    "color": "black", "fmt": "%.3g"})
    extent = 2.5e3 * half
    p.add_mesh(pv.Plane(center=(0, 0, -0.1), direction=(0, 0, 1), i_size=extent, j_size=extent),
               color="lightsteelblue", opacity=0.2, lighting=False)
    if title:
        p.add_text(title, font_size=9, color="black")
    p.enable_parallel_projection()
    top_mm = 1e3 * float(frame.points_m[:, 1].max())
    p.camera.position, p.camera.focal_point, p.camera.up = (0.0, 0.0, -20.0), (0.0, 0.0, 0.0), (0, 1, 0)
    p.camera.parallel_scale = 1e3 * half
    p.camera.clipping_range = (10.0, 30.0 + top_mm)          # tight: the depth buffer resolves 0.05 mm
    path = _save(p, png)
    return FootprintImage(path=path, m_per_px=m_per_px, centre_px=(width / 2, size_px / 2), zones_m=frame.zones_m)


def _plane_profile(frame: CupFrame) -> tuple[np.ndarray, np.ndarray]:
    """(r [m], recovered contact pressure [Pa]) of the boundary nodes on the plane, by radius."""
    loop = frame.loop
    r, z = frame.points_m[loop, 0], frame.points_m[loop, 1]
    p = np.asarray(frame.fields["contact_pressure"], float)[loop]
    near = z <= 1e-6 * max(float(frame.points_m[:, 1].max()), 1e-12)
    order = np.argsort(r[near])
    return r[near][order], p[near][order]


def squeeze(frames: Sequence[CupFrame], field: str, stem: str | Path, *, size_px: tuple[int, int] = (640, 360),
            duration_ms: int = 250) -> SqueezeImages:
    """The half cup seen side-on at each frame (stem_00.png, ...) and the animated GIF (stem.gif):
    parallel projection, the axis at the centre column, the plane at a fixed row, the same colour
    range on every frame (so a colour means one value throughout)."""
    import pyvista as pv
    from PIL import Image

    if len(frames) < 2:
        raise ValueError(f"frames: a squeeze sequence needs at least 2 frames, got {len(frames)}")
    stem = Path(stem)
    r_max = max(float(f.points_m[:, 0].max()) for f in frames)
    z_max = max(float(f.points_m[:, 1].max()) for f in frames)
    width, height = size_px
    half_w = 1.1 * r_max                                     # world half-width shown [m]
    m_per_px = 2 * half_w / width
    half_h = 0.5 * height * m_per_px                          # parallel scale: half the height
    z_centre = 0.5 * z_max
    ranges = [_range(f, field) for f in frames]
    clim = (min(r[0] for r in ranges), max(r[1] for r in ranges))
    _, bar = field_display(field)
    paths = []
    for i, frame in enumerate(frames):
        shell, caps = _surfaces(frame, field, 0.0, 180.0, 60)
        p = _plotter((width, height))
        p.set_background("white")
        kw = dict(scalars="value", cmap="viridis", clim=clim)
        p.add_mesh(shell, smooth_shading=True, show_scalar_bar=False, **kw)
        for k, cap in enumerate(caps):
            p.add_mesh(cap, show_scalar_bar=k == 0, scalar_bar_args={"title": bar, "color": "black", "fmt": "%.3g"}, **kw)
        p.add_mesh(pv.Line((-1e3 * half_w, 0, 0), (1e3 * half_w, 0, 0)), color="black", line_width=1)
        p.add_text(f"u = {1e3 * frame.u_m:.2f} mm", position="upper_left", font_size=9, color="black")
        p.enable_parallel_projection()
        p.camera.position, p.camera.focal_point = (0.0, -1e5, 1e3 * z_centre), (0.0, 0.0, 1e3 * z_centre)
        p.camera.up = (0, 0, 1)
        p.camera.parallel_scale = 1e3 * half_h
        p.camera.clipping_range = (1.0, 1e6)
        paths.append(_save(p, stem.parent / f"{stem.name}_{i:02d}.png"))
    images = [Image.open(path).convert("RGB") for path in paths]
    gif = stem.parent / f"{stem.name}.gif"
    images[0].save(gif, save_all=True, append_images=images[1:], duration=duration_ms, loop=0)
    return SqueezeImages(frames=tuple(paths), gif=gif, u_m=tuple(f.u_m for f in frames), m_per_px=m_per_px)
