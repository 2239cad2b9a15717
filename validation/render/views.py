"""The 3D views of a deformed cup (`validation.render.frames.CupFrame`), off-screen to PNG and GIF.

* `cutaway`: the cup revolved through 270 deg, the missing quarter showing the cross-section, both
  coloured by a chosen nodal field (`fem.recovery.FIELDS`), above the substrate plane; a parallel
  projection, so the scale bar holds for lengths in the image plane.
* `footprint`: the contact seen from below through the substrate (the sealing annulus), in a
  parallel projection whose scale is fixed by the cup's undeformed size (the same for every state
  of one cup), so that a pixel is a known length (`FootprintImage`).
* `section`: the half cup (cut through the axis) seen side-on; the contact pressure, which is zero
  inside the wall, is drawn as its profile p(r) hanging below the plane under a grey wall.
* `squeeze`: `section` frames at a fixed scale and a colour range fixed over the sequence, and the
  animated GIF of them (pillow).

Every image is composed by `validation.render.compose` (title, colour bar in a sensible unit with
the quantity's colormap of `validation.style.QUANTITIES`, scale bar). All go through
`require_offscreen_rendering` (the child-process GL probe) before the first window.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from validation import style
from validation.render import require_offscreen_rendering
from validation.render.compose import ColourKey, Placed, compose
from validation.render.frames import CupFrame

__all__ = ["cutaway", "footprint", "section", "squeeze", "FootprintImage", "SqueezeImages", "field_display"]

#: the fields of `fem.recovery.FIELDS` the views colour by
FIELDS = ("contact_pressure", "von_mises", "min_stretch")
# the 9-node quad (VTK order) as 4 bilinear quads, the 6-node triangle as 4 triangles
_SUB = {9: ((0, 4, 8, 7), (4, 1, 5, 8), (8, 5, 2, 6), (7, 8, 6, 3)), 6: ((0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5))}


@dataclass(frozen=True)
class FootprintImage:
    """A footprint image: its path, the length of one pixel [m], the pixel (column, row) of the axis,
    the contact zones drawn [(r_in, r_out)] [m], the box of the view in the PNG and the scale bar [m]."""

    path: Path
    m_per_px: float
    centre_px: tuple[float, float]
    zones_m: tuple[tuple[float, float], ...]
    view_box_px: tuple[int, int, int, int] = (0, 0, 0, 0)
    scale_bar_m: float = 0.0


@dataclass(frozen=True)
class SqueezeImages:
    """A squeeze sequence: the frames (PNG), the animated GIF, the plate displacement of each frame
    [m], the length of one pixel [m], the box of the view in each frame and the scale bar [m]."""

    frames: tuple[Path, ...]
    gif: Path
    u_m: tuple[float, ...]
    m_per_px: float
    view_box_px: tuple[int, int, int, int] = (0, 0, 0, 0)
    scale_bar_m: float = 0.0


def field_display(field: str) -> tuple[float, str]:
    """(factor from SI to the displayed unit, colour-bar title) of a field at its typical size
    (the views choose the unit from the range drawn: `validation.style.display_unit`)."""
    if field not in FIELDS:
        raise ValueError(f"field: expected one of {', '.join(FIELDS)}, got {field!r}")
    q = style.quantity(field)
    unit = style.display_unit(q.si_unit, 1e3 if q.si_unit else 1.0)
    return unit.factor, unit.label(q.label)


def _surfaces(frame: CupFrame, field: str, start_deg: float, angle_deg: float, resolution: int):
    """The revolved boundary and the two cut faces (cross-sections at start and start + angle),
    in mm, with the field [SI] as point data 'value'."""
    import pyvista as pv

    if field not in FIELDS:
        raise ValueError(f"field: expected one of {', '.join(FIELDS)}, got {field!r}")
    value = np.asarray(frame.fields[field], float)
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
    p = pv.Plotter(off_screen=True, window_size=window_size)
    p.set_background("white")
    return p


def _image(plotter) -> np.ndarray:
    """The plotter's screenshot (rows x cols x 3), the plotter closed."""
    try:
        return np.asarray(plotter.screenshot(return_img=True))[..., :3]
    finally:
        plotter.close()


def _rest_radius_m(frame: CupFrame) -> float:
    """The cup's largest undeformed radius (the deformed one for a frame without rest positions)."""
    points = frame.rest_points_m if frame.rest_points_m is not None else frame.points_m
    return float(np.max(points[:, 0]))


def _range(frame: CupFrame, field: str) -> tuple[float, float]:
    """The colour range [SI] of a field on a frame: from 0 (a stretch: from its least to 1)."""
    v = np.asarray(frame.fields[field], float)
    lo, hi = (0.0, float(v.max())) if field != "min_stretch" else (float(v.min()), 1.0)
    return (lo, hi if hi > lo else lo + (1.0 if field == "min_stretch" else 1e3))


def cutaway(frame: CupFrame, field: str, png: str | Path, *, title: str = "",
            clim: tuple[float, float] | None = None, window_size: tuple[int, int] = (900, 700)) -> Placed:
    """The cup revolved through 270 deg and cut open, coloured by `field` ([SI] `clim`, default
    0 .. the frame's largest), above the substrate (seen obliquely from above; the contact pressure,
    which acts on the underside, from below through the translucent substrate)."""
    import pyvista as pv

    cmap = style.quantity(field).cmap
    clim = clim or _range(frame, field)
    shell, caps = _surfaces(frame, field, 0.0, 270.0, 90)
    extent = 1.3e3 * _rest_radius_m(frame)
    p = _plotter(window_size)
    p.add_mesh(pv.Plane(center=(0, 0, 0), direction=(0, 0, 1), i_size=2 * extent, j_size=2 * extent),
               color="lightsteelblue", opacity=0.5 if field != "contact_pressure" else 0.15)
    kw = dict(scalars="value", cmap=cmap, clim=clim, show_scalar_bar=False)
    if field == "contact_pressure":                          # the underside: lit from the camera
        p.add_light(pv.Light(light_type="headlight", intensity=0.8))
    p.add_mesh(shell, smooth_shading=True, **kw)
    for cap in caps:
        p.add_mesh(cap, **kw)
    elevation = 1.3 if field != "contact_pressure" else -1.3
    p.camera_position = [(1.6 * extent, -2.2 * extent, elevation * extent), (0, 0, 0.25 * extent), (0, 0, 1)]
    p.enable_parallel_projection()
    p.camera.parallel_scale = 0.8 * extent                    # half the view's height [mm]
    p.reset_camera_clipping_range()
    m_per_px = 2e-3 * p.camera.parallel_scale / window_size[1]
    return compose(_image(p), png, m_per_px=m_per_px, title=title, colour=ColourKey(field, clim))


def footprint(frame: CupFrame, png: str | Path, *, half_height_m: float | None = None, size_px: int = 600,
              title: str = "") -> FootprintImage:
    """The contact seen from below through the substrate: each contact zone an annulus coloured by
    the recovered contact pressure, the rest of the cup grey, the substrate translucent.
    Parallel projection with the axis at the view's centre: the view's height is 2 half_height_m
    (default 1.25 times the cup's undeformed largest radius, rounded up to a whole mm: one scale
    for every state of a cup), so one pixel is 2 half_height_m / size_px.
    A zone of zero width (a line contact at the rim corner) is drawn one pixel wide."""
    import pyvista as pv

    if not frame.zones_m:
        raise ValueError(f"footprint: no contact at u = {1e3 * frame.u_m:.4g} mm; choose a larger u_mm")
    half = half_height_m or 1e-3 * math.ceil(1.25e3 * _rest_radius_m(frame))
    m_per_px = 2 * half / size_px
    shell, _ = _surfaces(frame, "contact_pressure", 0.0, 360.0, 180)
    p = _plotter((size_px, size_px))
    p.add_mesh(shell, color="silver", smooth_shading=True)
    on_plane = _plane_profile(frame)
    clim = (0.0, max(float(on_plane[1].max()), 1e-6))
    cmap = style.quantity("contact_pressure").cmap
    for r_in, r_out in frame.zones_m:
        if r_out - r_in < m_per_px:                            # a line contact: one pixel wide
            mid = 0.5 * (r_in + r_out)
            r_in, r_out = mid - 0.5 * m_per_px, mid + 0.5 * m_per_px
        disc = pv.Disc(center=(0, 0, -0.05), inner=1e3 * r_in, outer=1e3 * r_out, normal=(0, 0, -1),
                       r_res=max(int((r_out - r_in) / m_per_px), 2), c_res=720)
        disc.point_data["value"] = np.interp(1e-3 * np.hypot(disc.points[:, 0], disc.points[:, 1]), *on_plane)
        p.add_mesh(disc, scalars="value", cmap=cmap, clim=clim, lighting=False, show_scalar_bar=False)
    extent = 2.5e3 * half
    p.add_mesh(pv.Plane(center=(0, 0, -0.1), direction=(0, 0, 1), i_size=extent, j_size=extent),
               color="lightsteelblue", opacity=0.2, lighting=False)
    p.enable_parallel_projection()
    top_mm = 1e3 * float(frame.points_m[:, 1].max())
    p.camera.position, p.camera.focal_point, p.camera.up = (0.0, 0.0, -20.0), (0.0, 0.0, 0.0), (0, 1, 0)
    p.camera.parallel_scale = 1e3 * half
    p.camera.clipping_range = (10.0, 30.0 + top_mm)          # tight: the depth buffer resolves 0.05 mm
    placed = compose(_image(p), png, m_per_px=m_per_px, title=title, colour=ColourKey("contact_pressure", clim))
    c0, r0, c1, r1 = placed.view_box_px
    return FootprintImage(path=placed.path, m_per_px=placed.m_per_px, centre_px=(0.5 * (c0 + c1), 0.5 * (r0 + r1)),
                          zones_m=frame.zones_m, view_box_px=placed.view_box_px, scale_bar_m=placed.scale_bar_m)


def _plane_profile(frame: CupFrame) -> tuple[np.ndarray, np.ndarray]:
    """(r [m], recovered contact pressure [Pa]) of the boundary nodes on the plane, by radius."""
    loop = frame.loop
    r, z = frame.points_m[loop, 0], frame.points_m[loop, 1]
    p = np.asarray(frame.fields["contact_pressure"], float)[loop]
    near = z <= 1e-6 * max(float(frame.points_m[:, 1].max()), 1e-12)
    order = np.argsort(r[near])
    return r[near][order], p[near][order]


@dataclass(frozen=True)
class _SideView:
    """The fixed window of a side-on view: half its width and the heights shown [m], its pixels."""

    half_w_m: float
    z_top_m: float
    z_bottom_m: float
    size_px: tuple[int, int]

    @property
    def m_per_px(self) -> float:
        return 2 * self.half_w_m / self.size_px[0]


def _side_view(frames: Sequence[CupFrame], size_px: tuple[int, int]) -> _SideView:
    """A window that holds every frame, the plane a third of the way up from the bottom."""
    r_max = max(float(f.points_m[:, 0].max()) for f in frames)
    z_max = max(float(f.points_m[:, 1].max()) for f in frames)
    half_w = 1.1 * r_max
    height_m = size_px[1] * 2 * half_w / size_px[0]
    top = max(1.06 * z_max, 2 / 3 * height_m)
    return _SideView(half_w, top, top - height_m, size_px)


def _side_image(frame: CupFrame, field: str, clim: tuple[float, float], view: _SideView) -> np.ndarray:
    """The half cup side-on (camera along +y): the cut faces at x = +-r coloured by the field; for
    the contact pressure a grey wall and the profile p(r) hanging below the plane (its height
    proportional to p, the range's top filling 80 % of the room below the plane)."""
    import pyvista as pv

    shell, caps = _surfaces(frame, field, 0.0, 180.0, 60)
    p = _plotter(view.size_px)
    cmap = style.quantity(field).cmap
    kw = dict(scalars="value", cmap=cmap, clim=clim, show_scalar_bar=False)
    if field == "contact_pressure":
        kw = dict(color="silver")
    p.add_mesh(shell, smooth_shading=True, **kw)
    for cap in caps:
        p.add_mesh(cap, **kw)
    if field == "contact_pressure":
        r, pr = _plane_profile(frame)
        if r.size >= 2 and pr.max() > 0:
            depth_mm = 0.8e3 * -view.z_bottom_m / max(clim[1], 1e-12) * pr
            for sign in (1.0, -1.0):
                pts = np.vstack([np.column_stack([sign * 1e3 * r, np.full(r.size, -1e3 * view.half_w_m),
                                                  np.zeros(r.size)]),
                                 np.column_stack([sign * 1e3 * r, np.full(r.size, -1e3 * view.half_w_m),
                                                  -depth_mm])])
                n = r.size
                quads = np.array([[4, i, i + 1, n + i + 1, n + i] for i in range(n - 1)]).ravel()
                strip = pv.PolyData(pts, faces=quads)
                strip.point_data["value"] = np.concatenate([pr, pr])
                p.add_mesh(strip, scalars="value", cmap=cmap, clim=clim, lighting=False, show_scalar_bar=False)
    front = -1.1e3 * view.half_w_m                             # the plane's line, before the profile
    p.add_mesh(pv.Line((-1e3 * view.half_w_m, front, 0), (1e3 * view.half_w_m, front, 0)), color="black", line_width=1)
    z_centre = 0.5e3 * (view.z_top_m + view.z_bottom_m)
    p.enable_parallel_projection()
    p.camera.position, p.camera.focal_point = (0.0, -1e5, z_centre), (0.0, 0.0, z_centre)
    p.camera.up = (0, 0, 1)
    p.camera.parallel_scale = 0.5e3 * (view.z_top_m - view.z_bottom_m)
    p.camera.clipping_range = (1.0, 1e6)
    return _image(p)


def section(frame: CupFrame, field: str, png: str | Path, *, title: str = "",
            clim: tuple[float, float] | None = None, size_px: tuple[int, int] = (640, 400)) -> Placed:
    """The half cup seen side-on (the cut through the axis), coloured by `field` ([SI] `clim`);
    the contact pressure as its profile below the plane."""
    view = _side_view([frame], size_px)
    clim = clim or _range(frame, field)
    return compose(_side_image(frame, field, clim, view), png, m_per_px=view.m_per_px, title=title,
                   colour=ColourKey(field, clim))


def squeeze(frames: Sequence[CupFrame], field: str, stem: str | Path, *, size_px: tuple[int, int] = (640, 400),
            duration_ms: int = 250, title: str = "") -> SqueezeImages:
    """The half cup seen side-on at each frame (stem_00.png, ...; `section`) and the animated GIF
    (stem.gif): parallel projection, the axis at the centre column, the plane at a fixed row, the
    same colour range on every frame (so a colour means one value throughout)."""
    from PIL import Image

    if len(frames) < 2:
        raise ValueError(f"frames: a squeeze sequence needs at least 2 frames, got {len(frames)}")
    stem = Path(stem)
    view = _side_view(frames, size_px)
    ranges = [_range(f, field) for f in frames]
    clim = (min(r[0] for r in ranges), max(r[1] for r in ranges))
    placed = []
    for i, frame in enumerate(frames):
        label = f"u = {1e3 * frame.u_m:.2f} mm" + (f", {title}" if title else "")
        placed.append(compose(_side_image(frame, field, clim, view), stem.parent / f"{stem.name}_{i:02d}.png",
                              m_per_px=view.m_per_px, title=label, colour=ColourKey(field, clim)))
    images = [Image.open(pl.path).convert("RGB") for pl in placed]
    gif = stem.parent / f"{stem.name}.gif"
    images[0].save(gif, save_all=True, append_images=images[1:], duration=duration_ms, loop=0)
    return SqueezeImages(frames=tuple(pl.path for pl in placed), gif=gif, u_m=tuple(f.u_m for f in frames),
                         m_per_px=placed[0].m_per_px, view_box_px=placed[0].view_box_px,
                         scale_bar_m=placed[0].scale_bar_m)
