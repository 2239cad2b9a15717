"""Headless 3D scenes of the axisymmetric cup (pyvista, off-screen through EGL).

- this module: the child-process GL probe, `revolve_cross_section` and `render_cup` (an outline);
- `frames`: a deformed state as plain data (`CupFrame`: positions, cells, nodal fields recovered
  by `fem.recovery`, contact zones), from a FEM response or a ``--fields-out`` file;
- `views`: the cut-away coloured by a chosen field, the footprint from below at a fixed scale,
  the squeeze sequence (frames and an animated GIF).

A missing OpenGL stack does not raise in VTK: it aborts the whole process. So before the first render
window of a process, `require_offscreen_rendering` runs a tiny render in a *child* process. If that
fails, it raises a `RuntimeError` that names the Debian packages to install, instead of crashing.
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: VTK's EGL window renders without a display (PyPI vtk >= 9.4.2 ships it)
EGL_WINDOW = "vtkEGLRenderWindow"
GL_PACKAGES = "libegl1 libgl1-mesa-dri"

_PROBE = """
import os
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", {window!r})
import pyvista as pv
p = pv.Plotter(off_screen=True, window_size=(64, 48))
p.add_mesh(pv.Cube())
img = p.screenshot(return_img=True)
p.close()
assert img.shape[0] == 48 and img.std() > 0, "blank image"
print("ok")
"""


@dataclass(frozen=True)
class RenderProbe:
    ok: bool
    message: str


@functools.lru_cache(maxsize=1)
def probe_offscreen_rendering(timeout_s: float = 60.0) -> RenderProbe:
    """Render a cube in a child process; report whether off-screen rendering works here."""
    env = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW=os.environ.get("VTK_DEFAULT_OPENGL_WINDOW", EGL_WINDOW))
    try:
        run = subprocess.run([sys.executable, "-c", _PROBE.format(window=env["VTK_DEFAULT_OPENGL_WINDOW"])],
                             capture_output=True, text=True, timeout=timeout_s, env=env)
    except subprocess.TimeoutExpired:
        return RenderProbe(False, f"off-screen rendering probe timed out after {timeout_s:.0f} s")
    if run.returncode == 0 and run.stdout.strip().endswith("ok"):
        return RenderProbe(True, f"off-screen rendering works ({env['VTK_DEFAULT_OPENGL_WINDOW']})")
    tail = (run.stderr.strip().splitlines() or [f"exit status {run.returncode}"])[-1]
    return RenderProbe(False, f"off-screen rendering failed ({tail}); on Debian install: "
                              f"apt-get install {GL_PACKAGES}")


def require_offscreen_rendering() -> None:
    """Raise `RuntimeError` (naming the packages to install) unless off-screen rendering works."""
    probe = probe_offscreen_rendering()
    if not probe.ok:
        raise RuntimeError(probe.message)
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", EGL_WINDOW)


def revolve_cross_section(r_m: np.ndarray, z_m: np.ndarray, scalar: np.ndarray | None = None,
                          angle_deg: float = 270.0, resolution: int = 90):
    """A pyvista surface of the closed (r, z) outline revolved about the z axis (mm in the scene).

    A 270° sweep shows the wall's cross-section in the cut-away quarter.
    """
    import pyvista as pv

    r_m, z_m = np.asarray(r_m, float), np.asarray(z_m, float)
    if r_m.shape != z_m.shape or r_m.ndim != 1 or r_m.size < 3:
        raise ValueError("r_m, z_m: need two 1D arrays of the same length >= 3 (a closed outline)")
    if np.any(r_m < 0):
        raise ValueError("r_m: radii must be >= 0")
    points = np.column_stack([1e3 * r_m, np.zeros_like(r_m), 1e3 * z_m])
    n = len(points)
    lines = np.hstack([[n + 1], np.arange(n), [0]])
    outline = pv.PolyData(points, lines=lines)
    if scalar is not None:
        outline.point_data["value"] = np.asarray(scalar, float)
    return outline.extrude_rotate(resolution=resolution, angle=angle_deg, capping=False)


def render_cup(r_m: np.ndarray, z_m: np.ndarray, png: str | os.PathLike, *, scalar: np.ndarray | None = None,
               scalar_name: str = "", title: str = "", window_size: tuple[int, int] = (900, 700)) -> Path:
    """Render the revolved cup outline (optionally coloured by a scalar) with a substrate plane to PNG."""
    require_offscreen_rendering()
    import pyvista as pv

    surface = revolve_cross_section(r_m, z_m, scalar)
    extent = 1.3e3 * float(np.max(r_m))
    plane = pv.Plane(center=(0, 0, 0), direction=(0, 0, 1), i_size=2 * extent, j_size=2 * extent)
    p = pv.Plotter(off_screen=True, window_size=window_size)
    try:
        p.add_mesh(plane, color="lightsteelblue", opacity=0.5)
        kw = dict(scalars="value", cmap="viridis", scalar_bar_args={"title": scalar_name}) \
            if scalar is not None else dict(color="tan")
        p.add_mesh(surface, smooth_shading=True, **kw)
        if title:
            p.add_text(title, font_size=10)
        p.camera_position = [(1.6 * extent, -2.2 * extent, 1.3 * extent), (0, 0, 0.25 * extent), (0, 0, 1)]
        png = Path(png)
        png.parent.mkdir(parents=True, exist_ok=True)
        p.screenshot(str(png))
    finally:
        p.close()
    return png
