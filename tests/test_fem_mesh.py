"""Structured cup meshes (fem.mesh): tags, exact geometry, grading, nesting, meshio round trips."""

import math

import meshio
import numpy as np
import pytest
from skfem import Basis, Functional, MeshQuad2, MeshTri2

from fem.geometry import TabulatedThickness, cup_geometry
from fem.mesh import (BOUNDARY_NAMES, FIDELITIES, MeshSpec, boundary_path, check_cup_mesh,
                      cup_mesh, mesh_spec)
from fem.mesh_files import read_mesh, write_mesh

MM = 1e-3


@pytest.fixture(scope="module", params=["quad", "tri"])
def mesh_a(request):
    return cup_geometry("A"), cup_mesh(cup_geometry("A"), "coarse", element=request.param)


def _polygon_area_and_volume(poly):
    """Area and volume of revolution (Pappus, exact for a polygon) of a closed polygon."""
    x0, y0 = poly[:, 0], poly[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    cross = x0 * y1 - x1 * y0
    area = 0.5 * cross.sum()
    first_moment_r = (cross * (x0 + x1)).sum() / 6.0      # integral of r dA
    return area, 2 * math.pi * first_moment_r


def _integrals(mesh):
    basis = Basis(mesh, mesh.elem())
    area = Functional(lambda w: 1.0 + 0.0 * w.x[0]).assemble(basis)
    volume = Functional(lambda w: 2 * math.pi * w.x[0]).assemble(basis)
    return area, volume


def test_mesh_type_and_counts(mesh_a):
    _, mesh = mesh_a
    spec = FIDELITIES["coarse"]
    assert isinstance(mesh, (MeshQuad2, MeshTri2))
    per_quad = 1 if isinstance(mesh, MeshQuad2) else 2
    assert mesh.t.shape[1] == per_quad * spec.n_along * spec.n_through
    sizes = {name: len(mesh.boundaries[name]) for name in BOUNDARY_NAMES}
    assert sizes == {"top_plate": spec.n_through, "cavity": spec.n_along,
                     "outer": spec.n_along, "rim": spec.n_through}
    tagged = np.sort(np.concatenate([mesh.boundaries[n] for n in BOUNDARY_NAMES]))
    assert np.array_equal(tagged, np.sort(mesh.boundary_facets()))   # each boundary facet once
    check_cup_mesh(mesh)


def test_tags_lie_on_their_curves(mesh_a):
    g, mesh = mesh_a
    a = g.alpha_rad
    for name in BOUNDARY_NAMES:
        nodes = np.unique(np.concatenate([mesh.facets[:, mesh.boundaries[name]].ravel(),
                                          mesh.dofs.facet_dofs[0, mesh.boundaries[name]]]))
        r, z = mesh.doflocs[:, nodes]
        # signed distance above the cone line through (r0, h1), measured along its normal
        above = (r - g.r0_m) * math.sin(a) + (z - g.h1_m) * math.cos(a)
        d = g.thickness(g.r0_m + ((r - g.r0_m) * math.cos(a) - (z - g.h1_m) * math.sin(a)) * math.cos(a))
        if name == "cavity":
            assert np.abs(above).max() < 1e-15
        elif name == "outer":
            assert above == pytest.approx(d, rel=1e-12)
        else:   # the end edges: along the normal from the lower-surface end point
            end = (g.r0_m, g.h1_m) if name == "top_plate" else (g.r1_m, 0.0)
            along = (r - end[0]) * math.cos(a) - (z - end[1]) * math.sin(a)
            assert np.abs(along).max() < 1e-15


def test_mesh_reproduces_area_and_volume_of_revolution_exactly(mesh_a):
    # linear thickness: straight-sided elements with centred mid-side nodes, so the
    # isoparametric integrals are exact to round-off
    g, mesh = mesh_a
    area, volume = _integrals(mesh)
    area_exact, volume_exact = _polygon_area_and_volume(g.boundary_polygon(2))
    assert area == pytest.approx(area_exact, rel=1e-12)
    assert volume == pytest.approx(volume_exact, rel=1e-12)


def test_curved_outer_surface_converges_at_the_isoparametric_rate():
    # d(r) curved, n constant: the quadratic outer edge is P(s) + d_h(s) n with d_h the quadratic
    # interpolant of d, so the mesh area is L times Simpson's rule for int d ds: error O(h^4)
    g = cup_geometry("A", thickness=lambda r: 0.4 * MM + 2.0 * MM * np.exp(-(r - 5 * MM) / (3 * MM)))
    exact = g.slant_length_m * (0.4 * MM + 2.0 * MM * 3 / 14 * (1 - math.exp(-14 / 3)))
    errors = [abs(_integrals(cup_mesh(g, MeshSpec(n, 1, 0.0)))[0] - exact) / exact for n in (4, 8, 16)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 4.0) < 0.3), (errors, orders)


def test_grading_along_the_wall_follows_the_thickness():
    g = cup_geometry("A")
    mesh = cup_mesh(g, MeshSpec(n_along=40, n_through=1, along_grading=1.0))
    r, z = mesh.doflocs[:, boundary_path(mesh, "cavity")[::2]]
    lengths = np.hypot(np.diff(r), np.diff(z))
    d_mid = g.thickness(0.5 * (r[1:] + r[:-1]))
    ratio = lengths / d_mid        # constant up to the O(h) variation of d within an element
    assert np.ptp(ratio) / ratio.mean() < 0.03
    uniform = cup_mesh(g, MeshSpec(n_along=40, n_through=1, along_grading=0.0))
    r, z = uniform.doflocs[:, boundary_path(uniform, "cavity")[::2]]
    assert np.ptp(np.hypot(np.diff(r), np.diff(z))) < 1e-12


def test_grading_through_the_thickness():
    g = cup_geometry("A")
    mesh = cup_mesh(g, MeshSpec(n_along=2, n_through=4, through_ratio=8.0))
    r, z = mesh.doflocs[:, boundary_path(mesh, "top_plate")[::2]]
    layers = np.hypot(np.diff(r), np.diff(z))
    if z[0] > z[-1]:
        layers = layers[::-1]      # order from the cavity face outwards
    # t = (q^eta - 1)/(q - 1) on a uniform eta grid: each layer q^(1/4) times the previous one
    assert layers[1:] / layers[:-1] == pytest.approx(np.full(3, 8.0 ** 0.25), rel=1e-12)


def test_end_zones_equidistribute_the_closed_form_density():
    # rho(s) = 1 + A_p exp(-s/w_p) + A_r exp(-(1-s)/w_r) (along_grading 0) integrates to
    # C(s) = s + A_p w_p (1 - exp(-s/w_p)) + A_r w_r (exp(-(1-s)/w_r) - exp(-1/w_r)); the nodes
    # must split C(1) into equal parts (the mesh integrates rho numerically on a fine grid)
    g = cup_geometry("A")
    spec = MeshSpec(n_along=24, n_through=1, along_grading=0.0, plate_refinement=10.0, plate_width=0.02,
                    rim_refinement=3.0, rim_width=0.05)
    mesh = cup_mesh(g, spec)
    r, _ = mesh.doflocs[:, boundary_path(mesh, "cavity")[::2]]
    s = (r - g.r0_m) / (g.r1_m - g.r0_m)
    C = lambda x: (x + 10.0 * 0.02 * (1 - np.exp(-x / 0.02))                  # noqa: E731
                   + 3.0 * 0.05 * (np.exp(-(1 - x) / 0.05) - np.exp(-1 / 0.05)))
    assert C(s) / C(1.0) == pytest.approx(np.linspace(0, 1, 25), abs=1e-6)
    lengths = np.diff(s)        # the first element ~(1 + A_p) times shorter than the middle ones
    assert lengths[0] < lengths[12] / 5 and lengths[-1] < lengths[12] / 2.5


def test_through_clustering_gives_cosine_layers():
    g = cup_geometry("A")
    mesh = cup_mesh(g, MeshSpec(n_along=2, n_through=4, through_clustering=1.0))
    r, z = mesh.doflocs[:, boundary_path(mesh, "top_plate")[::2]]
    layers = np.hypot(np.diff(r), np.diff(z))
    d = g.thickness_at(np.array([0.0]))[0]
    # t_k = (1 - cos(pi k / 4)) / 2: layers 0.146, 0.354, 0.354, 0.146 of the thickness
    expected = np.diff(0.5 * (1 - np.cos(np.pi * np.arange(5) / 4)))
    assert np.sort(layers / d) == pytest.approx(np.sort(expected), rel=1e-12)


def test_refinement_nests_the_vertices():
    g = cup_geometry("B")
    coarse, fine = (cup_mesh(g, FIDELITIES["coarse"].refined(k)) for k in (1, 2))
    nv = lambda m: m.t.max() + 1
    pc, pf = coarse.doflocs[:, :nv(coarse)].T, fine.doflocs[:, :nv(fine)].T
    dist = np.min(np.linalg.norm(pc[:, None, :] - pf[None, :, :], axis=2), axis=1)
    assert dist.max() < 1e-15


def test_boundary_path_runs_from_the_plate_to_the_rim(mesh_a):
    g, mesh = mesh_a
    path = boundary_path(mesh, "cavity")
    assert len(path) == 2 * FIDELITIES["coarse"].n_along + 1
    r, z = mesh.doflocs[:, path]
    assert (r[0], z[0]) == pytest.approx((g.r0_m, g.h1_m), abs=1e-15)
    assert (r[-1], z[-1]) == pytest.approx((g.r1_m, 0.0), abs=1e-15)
    assert np.all(np.diff(r) > 0)


def test_mesh_spec_validation():
    assert mesh_spec("medium").n_along == 2 * mesh_spec("coarse").n_along
    assert mesh_spec("coarse", n_through=3).n_through == 3
    for bad in ({"n_along": 0}, {"n_through": 2.5}, {"along_grading": -2}, {"through_ratio": 0},
                {"element": "hex"}, {"plate_refinement": -1}, {"rim_width": 0.0},
                {"through_clustering": 1.5}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            mesh_spec("coarse", **bad)
    with pytest.raises(ValueError, match="fidelity"):
        mesh_spec("ultra")


@pytest.mark.parametrize("suffix", ["vtu", "msh"])
def test_round_trip_keeps_nodes_and_tags(mesh_a, tmp_path, suffix):
    _, mesh = mesh_a
    for unit in ("mm", "m"):
        path = write_mesh(mesh, tmp_path / f"cup_{unit}.{suffix}", unit=unit)
        back = read_mesh(path, unit=unit)
        assert type(back) is type(mesh)
        assert np.allclose(back.doflocs, mesh.doflocs, rtol=0, atol=1e-15)
        assert np.array_equal(back.t, mesh.t)
        for name in BOUNDARY_NAMES:
            assert np.array_equal(np.sort(back.boundaries[name]), np.sort(mesh.boundaries[name]))


def _gmsh_like_linear_triangles(tmp_path, clockwise=True, names=BOUNDARY_NAMES):
    """A user's order-1 Gmsh cross-section: linear triangles, line edges, physical names."""
    g = cup_geometry("B", thickness=TabulatedThickness((5 * MM, 17 * MM, 19 * MM),
                                                       (1.5 * MM, 0.5 * MM, 0.9 * MM)))
    m = cup_mesh(g, MeshSpec(8, 2, element="tri"))
    nv = m.t.max() + 1
    tri = m.t.T[:, [0, 2, 1]] if clockwise else m.t.T
    lines, tags = [], []
    for k, name in enumerate(names):
        lines.append(m.facets[:, m.boundaries[name]].T)
        tags.append(np.full(len(m.boundaries[name]), k + 1))
    lines, tags = np.concatenate(lines), np.concatenate(tags)
    out = meshio.Mesh(m.doflocs[:, :nv].T / MM, [("triangle", tri), ("line", lines)],
                      cell_data={"gmsh:physical": [np.full(len(tri), 9), tags],
                                 "gmsh:geometrical": [np.full(len(tri), 9), tags]},
                      field_data={**{n: np.array([k + 1, 1]) for k, n in enumerate(names)},
                                  "wall": np.array([9, 2])})
    path = tmp_path / "user.msh"
    meshio.write(path, out, file_format="gmsh22", binary=False)
    return m, path


def test_a_users_gmsh_cross_section_is_read_with_its_physical_names(tmp_path):
    m, path = _gmsh_like_linear_triangles(tmp_path, clockwise=True)
    user = read_mesh(path)
    assert isinstance(user, MeshTri2)
    for name in BOUNDARY_NAMES:
        assert len(user.boundaries[name]) == len(m.boundaries[name])
    check_cup_mesh(user)
    assert boundary_path(user, "cavity").size == 2 * len(m.boundaries["cavity"]) + 1


def test_optional_tags_may_be_missing_but_required_ones_not(tmp_path):
    _, path = _gmsh_like_linear_triangles(tmp_path, names=("top_plate", "cavity"))
    user = read_mesh(path)
    assert len(user.boundaries["rim"]) == 0 and len(user.boundaries["outer"]) == 0
    _, path = _gmsh_like_linear_triangles(tmp_path, names=("cavity", "outer"))
    with pytest.raises(ValueError, match="top_plate"):
        read_mesh(path)


def test_bad_mesh_files_are_rejected(tmp_path, mesh_a):
    _, mesh = mesh_a
    with pytest.raises(ValueError, match="no such file"):
        read_mesh(tmp_path / "missing.vtu")
    (tmp_path / "junk.msh").write_text("not a mesh")
    with pytest.raises(ValueError, match="cannot read"):
        read_mesh(tmp_path / "junk.msh")
    path = write_mesh(mesh, tmp_path / "cup.vtu", unit="m")
    with pytest.raises(ValueError, match="unit"):
        read_mesh(path, unit="mm")          # a 19 mm cup read as 19 micrometres
    sunk = type(mesh)(mesh.doflocs - np.array([[0.0], [1 * MM]]), mesh.t, mesh.boundaries)
    with pytest.raises(ValueError, match="below the substrate"):
        check_cup_mesh(sunk)


def test_an_inverted_element_is_rejected():
    g = cup_geometry("A")
    mesh = cup_mesh(g, MeshSpec(4, 1))
    x = mesh.doflocs.copy()
    centre = mesh.dofs.interior_dofs[0, 1]
    x[:, centre] = x[:, mesh.t[0, 0]]       # drag an element's centre node outside it
    with pytest.raises(ValueError, match="inverted"):
        check_cup_mesh(type(mesh)(x, mesh.t, mesh.boundaries))


# ------------------------------------------------------------ meshes/ folder
REPO = __import__("pathlib").Path(__file__).resolve().parents[1]


def test_committed_cup_meshes_are_what_the_script_generates(tmp_path):
    import importlib.util
    spec = importlib.util.spec_from_file_location("generate", REPO / "meshes" / "generate.py")
    generate = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generate)
    for path in generate.cup_mesh_files(tmp_path):
        # the same mesh, not the same bytes: the last printed digit of a coordinate may differ
        # between numpy versions (the minimum-versions run)
        new, committed = meshio.read(path), meshio.read(REPO / "meshes" / path.name)
        np.testing.assert_allclose(new.points, committed.points, rtol=0, atol=1e-12, err_msg=path.name)
        assert [(c.type, c.data.tolist()) for c in new.cells] == \
               [(c.type, c.data.tolist()) for c in committed.cells], path.name
        assert {k: [a.tolist() for a in v] for k, v in new.cell_data.items()} == \
               {k: [a.tolist() for a in v] for k, v in committed.cell_data.items()}, path.name
        mesh = read_mesh(path)
        assert len(mesh.boundaries["cavity"]) > 0


def test_the_gmsh_drawn_user_design_reads_with_its_physical_curves():
    # written by Gmsh 4.15 itself (format 4.1, quad9) from meshes/user_lip.geo
    mesh = read_mesh(REPO / "meshes" / "user_lip.msh")
    assert isinstance(mesh, MeshQuad2)
    assert all(len(mesh.boundaries[name]) > 0 for name in BOUNDARY_NAMES)
    r, z = mesh.doflocs[:, boundary_path(mesh, "cavity")]
    assert (r[0], z[0]) == pytest.approx((5 * MM, 7 * MM)) and (r[-1], z[-1]) == pytest.approx((19 * MM, 0.0))


def test_user_design_meshed_with_quads_and_with_triangles_gives_the_same_force():
    # two independent unstructured Gmsh meshes of meshes/user_lip.geo (quad9 and triangle6): the
    # same F0 at u = 1 mm to well within their discretisation error (< 0.5 %)
    from fem.cup import compress_cup
    from fem.material import NeoHookean
    forces = [compress_cup(read_mesh(REPO / "meshes" / name), NeoHookean(), u_max_m=1e-3).F0_N[-1]
              for name in ("user_lip.msh", "user_lip_tri.msh")]
    assert forces[1] == pytest.approx(forces[0], rel=5e-3)
