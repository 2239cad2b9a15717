"""The main job, `cupcheck example`: FEM stiffness -> lifetime against F1 on pmma-1.89 (profile route)."""

import math

import numpy as np
import pytest

from validation.cli import main


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    out = tmp_path_factory.mktemp("ex") / "main"
    assert main(["example", "--out", str(out)]) == 0
    return out


def _table(path):
    lines = path.read_text().splitlines()
    cols = lines[0].split(",")
    return [dict(zip(cols, line.split(","))) for line in lines[1:]]


def test_lifetimes_decrease_with_pull_force(example):
    rows = _table(example / "lifetime_vs_force.csv")
    forces = [float(r["force_N"]) for r in rows]
    lives = [float(r["lifetime_s"]) for r in rows]
    assert forces == [float(f) for f in range(5, 85, 5)]
    assert all(math.isfinite(t) and t > 0 for t in lives)
    # more pull force: lower cavity pressure at the start and a lower contact pressure, faster leak
    assert all(b < a for a, b in zip(lives, lives[1:]))
    png = (example / "lifetime_vs_force.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def test_fem_stiffness_is_a_direct_compress_cup_run(example):
    """The hand-off CSV holds the FEM curve at the default level: re-run compress_cup directly."""
    from fem.cup import compress_cup
    from fem.geometry import cup_geometry
    from fem.material import NeoHookean
    from fem.mesh import cup_mesh
    from reduced.stiffness_curve import StiffnessCurve

    curve = StiffnessCurve.from_csv(example / "stiffness_fem.csv")
    g = cup_geometry("A")
    direct = compress_cup(cup_mesh(g, "medium"), NeoHookean(E_Pa=4e6, nu=0.49), contact="frictionless",
                          u_max_m=0.9 * g.h1_m)
    # the CSV keeps 10 significant digits; the run is deterministic
    np.testing.assert_allclose(curve.u_m, direct.u_m, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(curve.F0_N, direct.F0_N, rtol=1e-9, atol=1e-12)
    assert curve.provenance["contact"] == "frictionless" and curve.provenance["fidelity"] == "medium"
    # the profile route's input travels with the curve: one contact-pressure profile per step
    assert curve.profiles is not None and len(curve.profiles) == curve.u_m.size
    assert all(p.force_N > 0 for p in curve.profiles[1:] if p is not None)


@pytest.mark.parametrize("argv,message", [
    (["--cup", "Z"], "argument --cup: invalid cup 'Z'"),
    (["--surface", "glass"], "surface: unknown preset 'glass'"),
    (["--uc-table", "/nonexistent/uc.csv"], "uc-table: no such file"),
])
def test_bad_input_exits_2_without_output(capsys, tmp_path, argv, message):
    try:
        code = main(["example", "--out", str(tmp_path / "ex"), *argv])
    except SystemExit as exc:               # argparse's own errors
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and message in err
    assert list(tmp_path.iterdir()) == []


def test_the_main_scene_writes_the_examples_table_and_curve(example, tmp_path):
    """scripts/main runs scenes/main.toml: the same lifetimes and FEM curve as `cupcheck example`."""
    from pathlib import Path

    import pandas as pd

    from validation.scenes.outputs import run_scene

    scene = Path(__file__).resolve().parents[1] / "scenes" / "main.toml"
    run_scene(scene, tmp_path / "main")
    for name, cols in (("lifetime_vs_force.csv", ["force_N", "lifetime_s", "r_final_mm", "p_b_final_Pa"]),
                       ("stiffness_fem.csv", ["u_mm", "F0_N", "r_c_mm", "l_mm", "V_mm3"])):
        a, b = pd.read_csv(tmp_path / "main" / name), pd.read_csv(example / name)
        assert list(a["reason"] if "reason" in a else []) == list(b["reason"] if "reason" in b else [])
        np.testing.assert_allclose(a[cols].to_numpy(), b[cols].to_numpy(), rtol=1e-9, atol=0)
    # the ballistic share is a quadrature over the stored trajectory, which the scene samples more
    # coarsely (refine 2, the example 4): 0.12 % apart at most
    a, b = pd.read_csv(tmp_path / "main" / "lifetime_vs_force.csv"), pd.read_csv(example / "lifetime_vs_force.csv")
    np.testing.assert_allclose(a["ballistic_share"], b["ballistic_share"], rtol=2e-3)
