"""Fields on the 3D views (issue 13): nodal recovery, the footprint measured in pixels, the squeeze GIF.

The recovery is checked against closed forms (a quadratic field projected exactly; the von Mises
stress of a homogeneous stretch); the smooth contact pressure against the plate reaction F0 and
against the odd-even oscillation of the lumped nodal pressure. The images are measured: the
footprint's inner and outer radii in pixels against the FEM's r_c and the deformed radius of the
outermost loaded node; the squeeze frames' top edge drops by the plate displacement in pixels.
"""

import numpy as np
import pytest
from matplotlib.image import imread

from fem.cup import compress_cup
from fem.geometry import cup_geometry
from fem.kinematics import Kinematics
from fem.material import NeoHookean
from fem.mesh import boundary_path, cup_mesh
from fem.postprocess import contact_force
from fem.recovery import nodal_field, project_to_nodes, smooth_contact_pressure
from validation.render import probe_offscreen_rendering

GEOMETRY = cup_geometry("A")
MATERIAL = NeoHookean(E_Pa=4e6, nu=0.49)


@pytest.fixture(scope="module")
def pressed():
    """Cup A (coarse, frictionless) pressed to 0.84 h1: the wall flat on the plane from r ~ 10 mm
    to the rim, a gap, and the rim corner (two contact zones)."""
    return compress_cup(cup_mesh(GEOMETRY, "coarse"), MATERIAL, u_max_m=0.84 * GEOMETRY.h1_m)


def _gl():
    probe = probe_offscreen_rendering()
    if not probe.ok:
        pytest.skip(probe.message)


def test_l2_projection_is_exact_for_a_quadratic_field():
    kin = Kinematics.of(cup_mesh(GEOMETRY, "coarse"))
    R, Z = np.asarray(kin.basis.global_coordinates())
    quad = lambda r, z: 1.0 + 30 * r - 40 * z + 900 * r * z - 500 * r**2 + 700 * z**2      # noqa: E731
    nodes = project_to_nodes(kin, quad(R, Z))
    x = kin.mesh.doflocs
    assert np.max(np.abs(nodes - quad(x[0], x[1]))) < 1e-9 * np.max(np.abs(quad(x[0], x[1])))


def test_von_mises_of_a_homogeneous_stretch_is_the_closed_form():
    """u_r = a R, u_z = b Z: F = diag(1 + a, 1 + b, 1 + a); neo-Hookean sigma = mu/J (B - I) +
    lambda ln J / J I, so von Mises = |s_rr - s_zz| = mu/J |(1 + a)^2 - (1 + b)^2| at every node."""
    from types import SimpleNamespace

    mesh = cup_mesh(GEOMETRY, "coarse")
    a, b = 0.05, -0.12
    u = np.zeros(2 * mesh.doflocs.shape[1])
    u[0::2], u[1::2] = a * mesh.doflocs[0], b * mesh.doflocs[1]
    resp = SimpleNamespace(mesh=mesh, material=MATERIAL, displacements=(u,), nodal_pressure_Pa=(0 * u[0::2],))
    J = (1 + a) ** 2 * (1 + b)
    expected = MATERIAL.mu / J * abs((1 + a) ** 2 - (1 + b) ** 2)
    vm = nodal_field(resp, "von_mises", 0)
    assert np.max(np.abs(vm / expected - 1)) < 1e-9
    assert np.max(np.abs(nodal_field(resp, "min_stretch", 0) - (1 + b))) < 1e-9


def test_recovered_contact_pressure_is_smooth_and_carries_the_plate_force(pressed):
    """The lumped nodal pressure alternates between vertex and midpoint nodes (element-scale
    stripes); the recovered one does not, and its 2 pi int p r dr is the plate reaction F0."""
    mesh, u = pressed.mesh, pressed.displacements[-1]
    raw = pressed.nodal_pressure_Pa[-1]
    smooth = smooth_contact_pressure(mesh, u, raw)
    path = boundary_path(mesh, "cavity")
    r = (mesh.doflocs[0] + u[0::2])[path]

    inner = np.flatnonzero((raw[path][:-2] > 0) & (raw[path][1:-1] > 0) & (raw[path][2:] > 0)) + 1

    def wiggle(p):            # inside the contact: the part of p a line through its neighbours misses
        return np.sum(np.abs(p[inner] - 0.5 * (p[inner - 1] + p[inner + 1]))) / np.sum(p[inner])

    print(f"wiggle: lumped {wiggle(raw[path]):.3f}, recovered {wiggle(smooth[path]):.3f}")
    assert wiggle(smooth[path]) < 0.3 * wiggle(raw[path])
    order = np.argsort(r)
    F = contact_force(r[order], smooth[path][order])
    assert F == pytest.approx(pressed.F0_N[-1], rel=0.01)          # measured 0.2 %
    assert smooth.min() >= 0.0 and smooth.max() <= raw.max()


def test_footprint_radii_measured_in_pixels_are_the_fem_contact_radii(pressed, tmp_path):
    """From below at a fixed scale: the coloured (saturated) pixels' nearest and farthest
    distance from the axis pixel are r_c (the FEM's CupResponse.r_c_m) and the deformed radius of
    the outermost loaded node (taken here from the displacements), within 2 pixels."""
    _gl()
    from validation.render.frames import frame_from_response
    from validation.render.views import footprint

    image = footprint(frame_from_response(pressed, -1, ("contact_pressure",)), tmp_path / "f.png")
    c0, r0, c1, r1 = image.view_box_px                                 # the view, not the colour bar
    img = imread(image.path)[r0:r1, c0:c1, :3]
    hi, lo = img.max(-1), img.min(-1)
    contact = (hi - lo) / np.maximum(hi, 1e-9) > 0.25                 # grey cup, white-blue background: < 0.1
    rows, cols = np.nonzero(contact)
    d = np.hypot(cols + c0 + 0.5 - image.centre_px[0], rows + r0 + 0.5 - image.centre_px[1])
    u = pressed.displacements[-1]
    loaded = np.flatnonzero(pressed.nodal_pressure_Pa[-1] > 0)
    r_outer = float(np.max(pressed.mesh.doflocs[0, loaded] + u[0::2][loaded]))
    px = image.m_per_px
    print(f"footprint: inner {d.min():.2f} px against r_c {pressed.r_c_m[-1] / px:.2f} px, outer {d.max():.2f} px "
          f"against {r_outer / px:.2f} px ({1e6 * px:.1f} um per pixel)")
    assert abs(d.min() - pressed.r_c_m[-1] / px) <= 2.0               # measured -0.3 px
    assert abs(d.max() - r_outer / px) <= 2.0                         # measured -0.05 px
    assert len(image.zones_m) == 2                                    # the strip and the rim corner


def test_squeeze_gif_has_its_frames_and_the_plate_moves_down_by_u(pressed, tmp_path):
    """N frames in the GIF; between the first and the last frame the top edge of the cup (the
    plate, moved rigidly by u) drops by u / (metres per pixel) within 2 pixels, and the pixels
    that change lie in the rows the cup occupies (above the plane line, below the first top edge)."""
    _gl()
    from PIL import Image

    from validation.render.frames import frame_from_response
    from validation.render.views import squeeze

    steps = [int(np.argmin(np.abs(pressed.u_m - t))) for t in np.linspace(0, pressed.u_m[-1], 4)]
    seq = squeeze([frame_from_response(pressed, k, ("von_mises",)) for k in steps], "von_mises", tmp_path / "sq")
    with Image.open(seq.gif) as gif:
        assert gif.n_frames == 4
    c0, r0, c1, r1 = seq.view_box_px                                          # the view alone
    first, last = (imread(p)[r0:r1, c0:c1, :3] for p in (seq.frames[0], seq.frames[-1]))
    plane_row = int(np.argmax((first.max(-1) < 0.2).sum(1)))              # the black plane line

    def top(img):
        ink = img.min(-1) < 0.9
        ink[plane_row - 1:] = False
        return int(np.argmax(ink.any(1)))

    drop = top(last) - top(first)
    assert abs(drop - (seq.u_m[-1] - seq.u_m[0]) / seq.m_per_px) <= 2.0
    changed = np.abs(last - first).max(-1) > 0.1
    rows = np.flatnonzero(changed[:plane_row - 1].any(1))
    assert rows.size and rows.min() >= top(first) - 1 and changed[:plane_row - 1].sum() > 1000
