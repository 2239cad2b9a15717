"""Headless rendering: the child-process probe, and a revolved cup scene written to PNG."""

import numpy as np
import pytest

from validation import render


def _outline():
    # a thin truncated cone wall (cup A-like), closed outline in (r, z) [m]
    r = np.array([5e-3, 19e-3, 19.2e-3, 5.5e-3])
    z = np.array([9.09e-3, 0.0, 0.3e-3, 11e-3])
    return r, z


def test_revolved_surface_has_the_swept_extent():
    r, z = _outline()
    surf = render.revolve_cross_section(r, z, angle_deg=360.0, resolution=64)
    xmin, xmax, ymin, ymax, zmin, zmax = surf.bounds
    assert xmax == pytest.approx(19.2, rel=1e-3) and ymin == pytest.approx(-19.2, rel=2e-3)
    assert zmin == pytest.approx(0.0, abs=1e-9) and zmax == pytest.approx(11.0, rel=1e-9)


def test_bad_outline_names_the_field():
    with pytest.raises(ValueError, match="r_m"):
        render.revolve_cross_section([0.0, 1.0], [0.0, 1.0])


def test_probe_reports_and_scene_renders(tmp_path):
    probe = render.probe_offscreen_rendering()
    assert isinstance(probe.ok, bool) and probe.message
    if not probe.ok:
        assert render.GL_PACKAGES in probe.message
        pytest.skip(probe.message)
    r, z = _outline()
    png = render.render_cup(r, z, tmp_path / "cup.png", scalar=z, scalar_name="z", title="test")
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000
