"""`fem.integrity`: a converged state that violates the contact conditions ends the path and says
where and why. The geometry is checked against closed forms (the h/8 dip of a quadratic facet, a
crossing polyline); the cup case against the state the solver reaches without the check."""

import numpy as np
import pytest

from fem.cup import compress_cup
from fem.integrity import PENETRATION_TOL, StateRejected, facet_dip, outline_crossing, rim_thickness
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from fem.solver import ConvergenceError
from validation.crosscheck.runs import FemRun


def test_quadratic_facet_dips_an_eighth_of_its_lifted_end():
    """A facet with one vertex h up and its mid-side node and other vertex on the plane is the
    parabola z(s) = h s (2 s - 1): its minimum, -h/8 at s = 1/4, between the nodes."""
    g = FemRun(cup="A").geometry()
    mesh = cup_mesh(g, "coarse")
    x = mesh.doflocs.copy()
    x[1] = 1.0                                         # everything well above the plane
    f = np.asarray(mesh.boundaries["cavity"])[5]
    nv = int(mesh.t.max()) + 1
    a, b = mesh.facets[:, f]
    h = 8e-6
    x[1, a], x[1, b], x[1, nv + f] = 0.0, h, 0.0
    depth, name, j = facet_dip(mesh, x)
    assert name == "cavity" and j == 5
    assert depth == pytest.approx(h / 8, rel=1e-12)     # s = 1/4 is one of the 33 samples


def test_outline_crossing():
    square = np.array([[0, 1, 1, 0], [0, 0, 1, 1]], float)
    assert outline_crossing(square) is None
    bow_tie = np.array([[0, 1, 0, 1], [0, 1, 1, 0]], float)   # segments 0 and 2 cross at (0.5, 0.5)
    assert outline_crossing(bow_tie) == (0, 2)
    # the undeformed cup's outline (cavity -> rim -> outer -> plate) does not cross itself
    from fem.integrity import _outline
    mesh = cup_mesh(FemRun(cup="A").geometry(), "coarse")
    loop, names = _outline(mesh)
    assert loop.size > 0 and set(names) == {"cavity", "rim", "outer", "top_plate"}
    assert outline_crossing(mesh.doflocs[:, loop]) is None



def _all_pairs_crossing(points):
    """The first crossing pair by testing every pair of non-adjacent segments (the reference)."""
    n = points.shape[1]
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue
            p, r = points[:, i], points[:, (i + 1) % n] - points[:, i]
            q, s = points[:, j], points[:, (j + 1) % n] - points[:, j]
            denom = r[0] * s[1] - r[1] * s[0]
            if denom == 0:
                continue
            a = ((q - p)[0] * s[1] - (q - p)[1] * s[0]) / denom
            b = ((q - p)[0] * r[1] - (q - p)[1] * r[0]) / denom
            if 0 < a < 1 and 0 < b < 1:
                return i, j
    return None


def test_outline_crossing_finds_the_first_pair_of_all_pairs():
    """The sweep over overlapping r-extents finds the same first crossing as all pairs, on
    random polygons (many crossings), perturbed circles (few or none) and grid points (shared
    coordinates: vertical segments, equal extents)."""
    rng = np.random.default_rng(7)
    found = 0
    for k in range(300):
        n = int(rng.integers(3, 40))
        if k % 3 == 0:
            pts = rng.normal(size=(2, n))
        elif k % 3 == 1:
            th = np.sort(rng.uniform(0, 2 * np.pi, n))
            pts = np.stack([np.cos(th), np.sin(th)]) * (1 + 0.2 * rng.normal(size=n))
        else:
            pts = np.round(3 * rng.normal(size=(2, n))) / 3
        expected = _all_pairs_crossing(pts)
        found += expected is not None
        assert outline_crossing(pts) == expected
    assert 50 < found < 300

def _thin_cone():
    req = FemRun(cup="A", alpha_deg=45.0, d_root_mm=0.5)
    g = req.geometry()
    return g, cup_mesh(g, "coarse")


def test_thin_cone_that_turns_over_fails_fast_with_its_cause():
    """alpha 45 deg, root 0.5 mm, frictionless, coarse: the rim lifts while the wall lies on the
    plane further in, and the contact edge falls inside a facet that dips below the plane. The
    path ends at the first such state, naming it (without the check the solver goes on to
    0.9 h1 through states that penetrate up to 0.15 rim thicknesses: the extremes report)."""
    g, mesh = _thin_cone()
    with pytest.raises(StateRejected) as info:
        compress_cup(mesh, NeoHookean(), "frictionless", u_max_m=0.9 * g.h1_m)
    exc = info.value
    assert isinstance(exc, ConvergenceError)
    assert "turned over" in str(exc) and "dips" in str(exc) and "cavity face" in str(exc)
    assert 0.0 < exc.t_from < exc.t_to < 0.5 * g.h1_m


@pytest.mark.slow
def test_the_refused_state_is_the_first_beyond_the_tolerance():
    """The same path without the check (same steps): every state before the refused one lies
    within the tolerance, the refused one beyond it, by the same measure (~15 s)."""
    g, mesh = _thin_cone()
    with pytest.raises(StateRejected) as info:
        compress_cup(mesh, NeoHookean(), "frictionless", u_max_m=0.9 * g.h1_m)
    free = compress_cup(mesh, NeoHookean(), "frictionless", u_max_m=0.9 * g.h1_m, admissible_only=False)
    tol = PENETRATION_TOL * rim_thickness(mesh)
    dips = np.array([facet_dip(mesh, mesh.doflocs + np.stack([u[0::2], u[1::2]]))[0]
                     for u in free.displacements])
    first = int(np.flatnonzero(dips > tol)[0])
    assert free.u_m[first] == pytest.approx(info.value.t_to, rel=1e-12)
    assert free.u_m[-1] == pytest.approx(0.9 * g.h1_m) and dips.max() > 2 * tol


def test_cup_a_is_admissible_for_every_law():
    """Cup A, coarse, to 0.9 h1: no state of the frictionless, sticking or Coulomb path is
    refused, and the largest dip between the nodes stays below the tolerance."""
    g = FemRun(cup="A").geometry()
    mesh = cup_mesh(g, "coarse")
    for law, mu in (("frictionless", 0.0), ("sticking", 0.0), ("coulomb", 0.3)):
        r = compress_cup(mesh, NeoHookean(), law, friction=mu)
        assert r.u_m[-1] == pytest.approx(0.9 * g.h1_m)
        assert np.max(r.penetration_m) <= PENETRATION_TOL * rim_thickness(mesh)


def test_command_line_says_where_and_why(tmp_path, capsys):
    """`cupcheck stiffness` on a thin cone that turns over: one line with the u, the place and the
    cause, the record in the failure log; the converged part is written flagged partial (exit 3,
    tests/test_partial_curve.py)."""
    import json

    from validation.cli import main

    design = tmp_path / "thin.toml"
    design.write_text('cup = "A"\nalpha_deg = 45\n[thickness]\nr_mm = [5, 20]\nd_mm = [0.5, 0.06]\n')
    out = tmp_path / "c.csv"
    code = main(["stiffness", "--geometry", str(design), "--fidelity", "coarse", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert code == 3 and json.loads(out.with_suffix(".json").read_text())["provenance"]["partial"]
    assert err.startswith("cupcheck stiffness: partial: the path stopped at u = ") and "turned over" in err
    record = json.loads((tmp_path / "c.failure.json").read_text())
    assert record["residual_history"] == [] and "dips" in record["cause"]
