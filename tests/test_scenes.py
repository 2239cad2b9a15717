"""Scenes (issue 13, first step): the scene file, the lazy cached pipeline, the shipped scenes."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from validation.cli import main
from validation.bridge import products as pipeline
from validation.scenes.outputs import run_scene
from validation.scenes.schema import scene_from_mapping

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = sorted(p for p in (ROOT / "scenes").glob("*.toml") if not p.name.startswith("sweep_"))


@pytest.mark.parametrize("data,message", [
    ({"outputs": [{"kind": "movie"}]}, "outputs[0].kind: expected one of curve, lifetimes, trajectories, figure"),
    ({"outputs": [{"kind": "figure", "figure": "pie"}]}, "outputs[0].figure: expected one of lifetime_vs_force"),
    ({"material": {"E_MPa": -4}, "outputs": [{"kind": "curve"}]}, "material.E_MPa: must be > 0"),
    ({"loads": {"F1_N": [10, "x"]}, "outputs": [{"kind": "lifetimes"}]}, "loads.F1_N[1]: expected a finite number"),
    ({"stiffness": {"route": "profile", "source": "appendix-a"}, "outputs": [{"kind": "lifetimes"}]},
     "stiffness.route: 'profile' needs source = \"fem\""),
    ({"cup": {"presett": "A"}, "outputs": [{"kind": "curve"}]}, "cup.presett: unknown key; allowed: preset, geometry"),
    ({"camera": {}, "outputs": [{"kind": "curve"}]}, "camera: unknown table"),
    ({}, "outputs: a scene needs a non-empty list of [[outputs]]"),
    ({"outputs": [{"kind": "curve"}, {"kind": "curve"}]}, "outputs: two outputs would write the same file 'curve'"),
    ({"outputs": [{"kind": "render", "u_mm": 3, "field": "stress"}]},
     "outputs[0].field: expected one of contact_pressure, von_mises, min_stretch, got 'stress'"),
    ({"outputs": [{"kind": "curve", "field": "von_mises"}]}, "outputs[0].field: only for kind = \"render\" or \"squeeze\""),
    ({"outputs": [{"kind": "footprint"}]}, "outputs[0].u_mm: render, footprint, squeeze need u_mm"),
    ({"outputs": [{"kind": "squeeze", "u_mm": 3, "frames": 1}]}, "outputs[0].frames: expected a whole number in [2, 60], got 1"),
    ({"outputs": [{"kind": "squeeze", "u_mm": 3, "frames": 2.5}]}, "outputs[0].frames: expected a whole number in [2, 60]"),
    ({"contact": {"law": "sticking", "friction": 0.3}, "outputs": [{"kind": "curve"}]},
     "contact.friction: applies to law = \"coulomb\" only, got 0.3 with law = \"sticking\""),
    ({"contact": {"law": "coulomb"}, "outputs": [{"kind": "curve"}]},
     "contact.friction: law = \"coulomb\" needs friction = MU, in [0, 100]"),
    ({"contact": {"law": "coulomb", "friction": 101}, "outputs": [{"kind": "curve"}]},
     "contact.friction: Coulomb's friction coefficient must be in [0, 100], got 101"),
    ({"contact": {"law": "coulomb", "friction": -0.1}, "outputs": [{"kind": "curve"}]},
     "contact.friction: Coulomb's friction coefficient must be in [0, 100], got -0.1"),
    ({"contact": {"law": "coulomb", "friction": 0.3}, "stiffness": {"source": "appendix-a"},
      "outputs": [{"kind": "lifetimes"}]}, "contact.law: Coulomb friction is a FEM contact law"),
    ({"sweep": {"key": "contact.friction", "values": [0.1]}, "outputs": [{"kind": "lifetimes"}]},
     "sweep.key: contact.friction needs contact.law = \"coulomb\""),
    ({"contact": {"law": "coulomb"}, "sweep": {"key": "contact.friction", "values": [0.1, 200]},
      "outputs": [{"kind": "lifetimes"}]}, "sweep.values[1]: Coulomb's friction coefficient must be in [0, 100]"),
])
def test_bad_scenes_are_refused_with_the_key_path(data, message):
    with pytest.raises(ValueError) as exc:
        scene_from_mapping(data)
    assert message in str(exc.value) and "\n" not in str(exc.value)


def test_a_bad_scene_exits_2_and_writes_nothing(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text('[[outputs]]\nkind = "figure"\nfigure = "pie"\n')
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--cache-dir", str(tmp_path / "c")]) == 2
    assert "outputs[0].figure: expected one of" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


@pytest.mark.parametrize("scene", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_every_shipped_scene_runs_and_its_manifest_lists_every_file(scene, tmp_path, capsys):
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--no-cache", "--quiet"]) == 0
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    written = sorted(p.name for p in (tmp_path / "out").iterdir() if p.name != "manifest.json")
    assert sorted(f["path"] for f in manifest["files"]) == written and written
    assert manifest["scene"]["outputs"] and "numpy" in manifest["versions"]
    for f in manifest["files"]:
        if f["path"].endswith(".png"):
            assert (tmp_path / "out" / f["path"]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_second_run_computes_nothing_and_a_corrupt_entry_is_recomputed(tmp_path):
    scene = ROOT / "scenes" / "lifetime_vs_force_cupA.toml"
    cache = tmp_path / "cache"
    pipeline.COMPUTED.clear()
    first = run_scene(scene, tmp_path / "a", cache_dir=cache)
    once = {"fem_path": 1, "fem_curve": 1, "uc_table": 1, "lifetimes": 2}     # FEM-fed and Appendix A-fed
    assert dict(pipeline.COMPUTED) == once
    run_scene(scene, tmp_path / "b", cache_dir=cache)
    assert dict(pipeline.COMPUTED) == once      # nothing new
    assert (tmp_path / "a" / "lifetime_vs_force.csv").read_text() == (tmp_path / "b" / "lifetime_vs_force.csv").read_text()
    for entry in cache.rglob("output.pkl"):            # damage every stored product
        entry.write_bytes(b"not a pickle")
    third = run_scene(scene, tmp_path / "c", cache_dir=cache)
    assert dict(pipeline.COMPUTED) == {"fem_path": 2, "fem_curve": 2, "uc_table": 2, "lifetimes": 4}
    assert [r.lifetime_s for r in third.products["lifetimes"]] == [r.lifetime_s for r in first.products["lifetimes"]]


def test_the_cache_keys_input_files_by_content(tmp_path, capsys):
    # an edited design file or u_c table is a new product (the path is the same); unchanged
    # inputs recompute nothing; the design's curve goes through the cache, the table through the lifetimes
    import numpy as np

    from reduced.critical_gap import ILLUSTRATIVE_UC_CSV
    design, table, cache = tmp_path / "cup.toml", tmp_path / "uc.csv", tmp_path / "cache"
    thick = 'cup = "A"\n[thickness]\nr_mm = [5, 20]\nd_mm = [2.5, 0.3]\n'
    design.write_text(thick)
    table.write_bytes(ILLUSTRATIVE_UC_CSV.read_bytes())
    scene = {"cup": {"geometry": str(design)}, "surface": {"uc_table": str(table)},
             "loads": {"F1_N": [10]}, "outputs": [{"kind": "curve"}, {"kind": "lifetimes"}]}

    def run(name):
        pipeline.COMPUTED.clear()
        result = run_scene(dict(scene), tmp_path / name, cache_dir=cache)
        return result.products["curve"].F0_N[-1], result.products["lifetimes"][0].lifetime_s, dict(pipeline.COMPUTED)

    F_thick, life, computed = run("a")
    assert computed == {"fem_path": 1, "fem_curve": 1, "uc_table": 1, "lifetimes": 1}
    assert run("b") == (F_thick, life, {})                              # nothing recomputed
    design.write_text(thick.replace("2.5, 0.3", "1.5, 0.3"))            # a thinner wall, same path
    F_thin, life_thin, computed = run("c")
    assert computed == {"fem_path": 1, "fem_curve": 1, "lifetimes": 1} and F_thin < 0.8 * F_thick
    rows = table.read_text().splitlines()
    head = [r for r in rows if not r[:1].isdigit()]
    table.write_text("\n".join(head + [f"{p},{2 * float(u)!r}" for p, u in
                                        (r.split(",") for r in rows if r[:1].isdigit())]) + "\n")
    F_again, life_wide, computed = run("d")                             # twice the gap: a faster leak
    assert computed == {"uc_table": 1, "lifetimes": 1} and F_again == F_thin and life_wide < life_thin
    for entry in cache.rglob("output.pkl"):                             # damage every stored product
        entry.write_bytes(b"not a pickle")
    capsys.readouterr()
    assert run("e")[:2] == (F_again, life_wide)
    err = capsys.readouterr().err
    assert "Traceback" not in err and np.all([line.startswith("cupcheck: cache ") for line in err.splitlines()])


_LAZY = """
import sys
from validation.scenes.outputs import run_scene
from validation.bridge import products as pipeline
run_scene({scene!r}, None)
print(",".join(sorted(m for m in ("fem", "skfem") if m in sys.modules)), dict(pipeline.COMPUTED))
"""


@pytest.mark.parametrize("scene,computed", [
    ("appendix_a_lifetimes.toml", "{'uc_table': 1, 'lifetimes': 1}"),
    ("uc_pmma_1_89.toml", "{'uc_table': 1}"),
])
def test_a_scene_computes_only_what_it_needs(scene, computed):
    """Appendix A lifetimes and a u_c figure never import fem; the u_c figure computes no lifetime."""
    out = subprocess.run([sys.executable, "-c", _LAZY.format(scene=str(ROOT / "scenes" / scene))],
                         cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
    assert out == computed          # no "fem" or "skfem" before the dict: neither was imported


@pytest.mark.parametrize("data,message", [
    ({"sweep": {"key": "material.E_MPa", "values": [1]}, "outputs": [{"kind": "lifetimes"}]},
     "sweep.key: expected one of loads.kappa"),
    ({"sweep": {"key": "loads.kappa", "values": [1, -2]}, "outputs": [{"kind": "lifetimes"}]},
     "sweep.values[1]: must be > 0"),
    ({"outputs": [{"kind": "figure", "figure": "lifetime_vs_parameter"}]},
     "outputs: the figure lifetime_vs_parameter needs a [sweep] table"),
    ({"sweep": {"key": "cup.preset", "values": ["A", "C"]}, "outputs": [{"kind": "lifetimes"}]},
     "sweep.values: expected A, B, got 'C'"),
])
def test_bad_sweeps_in_scenes_are_refused(data, message):
    with pytest.raises(ValueError) as exc:
        scene_from_mapping(data)
    assert message in str(exc.value)


def test_a_swept_scene_is_the_same_model_as_the_command_line(tmp_path, capsys):
    """The kappa sweep's lifetime at kappa = 2, 10 N equals `cupcheck lifetime --kappa 2` with the
    same surface (Appendix A, the paper's route, no relaxation): two paths to one model."""
    result = run_scene(ROOT / "scenes" / "kappa_sweep.toml", tmp_path / "out")
    value, products = next((v, p) for v, p in result.products["variants"] if v == 2.0)
    scene_life = products.lifetimes()[1].lifetime_s                      # F1 = 10 N
    assert main(["lifetime", "--kappa", "2", "--force", "10", "--surface", "pmma-1.89", "--json"]) == 0
    cli_life = json.loads(capsys.readouterr().out)[0]["lifetime_s"]
    assert scene_life == pytest.approx(cli_life, rel=1e-9)


def test_a_render_runs_the_fem_only_to_its_displacement_and_shows_the_contact(tmp_path):
    """The render at u = 3 mm: the FEM stops at 3 mm (no stiffness curve is computed), and the
    image (seen from below through the substrate) shows the contact strip in the colour map's top (yellow)."""
    import numpy as np
    from matplotlib.image import imread

    from validation.render import probe_offscreen_rendering

    probe = probe_offscreen_rendering()
    if not probe.ok:
        pytest.skip(probe.message)
    pipeline.COMPUTED.clear()
    result = run_scene(ROOT / "scenes" / "render_cupA_3mm.toml", tmp_path / "out")
    state = result.products["fem_state_3mm"][-1]
    assert state.u_m == pytest.approx(3e-3, rel=1e-12) and dict(pipeline.COMPUTED) == {"fem_path": 1, "fem_frames": 1}
    img = imread(tmp_path / "out" / "cupA_3mm.png")[..., :3]
    assert img.shape[0] >= 700 and img.shape[1] >= 900 and img.std() > 0.05     # the 900 x 700 view, titled
    # the colour map's top, shaded by the lights: red and green well above blue (the plane is
    # grey-blue, the unloaded cup dark)
    yellow = (img[..., 0] > 0.6) & (img[..., 1] > 0.55) & (img[..., 2] < 0.3)
    left_of_bar = yellow[:, :900]              # the colour bar sits right of the view
    assert left_of_bar.sum() > 3               # the contact strip, coloured by its peak pressure


def test_a_coulomb_scene_is_the_command_lines_coulomb_curve(tmp_path, capsys):
    """[contact] law = "coulomb", friction = 0.3: the scene's FEM curve is `cupcheck stiffness
    --contact coulomb --friction 0.3` at the same level, to round-off."""
    import pandas as pd

    scene = {"contact": {"law": "coulomb", "friction": 0.3}, "loads": {"F1_N": [10]},
             "outputs": [{"kind": "curve", "name": "c"}]}
    run_scene(scene, tmp_path / "scene")
    assert main(["stiffness", "--cup", "A", "--contact", "coulomb", "--friction", "0.3", "--fidelity", "coarse",
                 "--out", str(tmp_path / "cli.csv")]) == 0
    a, b = pd.read_csv(tmp_path / "scene" / "c.csv"), pd.read_csv(tmp_path / "cli.csv")
    assert len(a) == len(b) and abs(a["F0_N"] - b["F0_N"]).max() <= 1e-9 * b["F0_N"].abs().max()


def test_views_of_one_cup_at_one_u_share_one_fem_run(tmp_path):
    """A render, a footprint and a squeeze ending at the same u (and the same cup, material,
    contact, fidelity) draw on one FEM path: one run, one stored path product; another u is
    another path; a second run computes nothing. Counted by the products, not by timing."""
    scene = {"outputs": [{"kind": "render", "u_mm": 2}, {"kind": "footprint", "u_mm": 2},
                         {"kind": "squeeze", "u_mm": 2, "frames": 3}, {"kind": "render", "name": "r1", "u_mm": 1}]}
    cache = tmp_path / "cache"
    stored = lambda: sorted(p.parent.parent.name for p in cache.rglob("output.pkl"))   # noqa: E731
    pipeline.COMPUTED.clear()
    result = run_scene(scene, None, cache_dir=cache)
    assert dict(pipeline.COMPUTED) == {"fem_path": 2, "fem_frames": 3}       # 2 mm and 1 mm
    assert stored() == ["_fem_frames"] * 3 + ["_fem_path"] * 2
    assert sorted(k for k in result.products if k.startswith("fem_path")) == ["fem_path_1mm", "fem_path_2mm"]
    assert result.products["fem_state_2mm"][-1].u_m == pytest.approx(2e-3, rel=1e-12)
    assert result.products["fem_state_2mm_3frames"][-1].u_m == result.products["fem_state_2mm"][-1].u_m
    run_scene(scene, None, cache_dir=cache)
    assert dict(pipeline.COMPUTED) == {"fem_path": 2, "fem_frames": 3}       # nothing new


@pytest.mark.parametrize("tty,quiet", [(True, False), (True, True), (False, False)])
def test_the_progress_bar_shows_on_a_terminal_only(tmp_path, monkeypatch, capsys, tty, quiet):
    """On a terminal a tqdm bar over the outputs names what runs (the product, the lifetimes k of n);
    with --quiet or without a terminal stderr stays empty."""
    import io

    class Term(io.StringIO):
        def isatty(self):
            return tty

    err = Term()
    monkeypatch.setattr(sys, "stderr", err)
    argv = ["run", str(ROOT / "scenes" / "appendix_a_lifetimes.toml"), "--out", str(tmp_path / "o"), "--no-cache"]
    assert main(argv + (["--quiet"] if quiet else [])) == 0
    text = err.getvalue()
    if tty and not quiet:
        assert "run" in text and "output" in text and "lifetime 2 of 2 done" in text
    else:
        assert text == ""


def test_a_view_beyond_h1_exits_2_and_writes_nothing(tmp_path, capsys):
    """u_mm past the cup's height: one line naming the key and its range, exit 2, no FEM run, no files."""
    path = tmp_path / "s.toml"
    path.write_text('[[outputs]]\nkind = "squeeze"\nu_mm = 50\n')
    pipeline.COMPUTED.clear()
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--cache-dir", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "u_mm must be in (0, h1] = (0, 9.092] mm, got 50" in err[0]
    assert not (tmp_path / "out").exists() and "fem_path" not in pipeline.COMPUTED


def test_everything_a_figure_draws_is_in_its_data_table(tmp_path):
    """The lifetime figure of a FEM study of cup A draws the FEM-fed lifetimes and, beside them,
    the Appendix A-fed ones: its <name>_data.csv has both series, point by point, equal to the
    lifetime table and to the Appendix A study's own lifetimes; the F0(u) figure's has the curve."""
    import pandas as pd

    scene = {"loads": {"F1_N": [10, 40]}, "outputs": [
        {"kind": "lifetimes"}, {"kind": "figure", "figure": "lifetime_vs_force"}, {"kind": "curve"},
        {"kind": "figure", "figure": "F0_vs_u"}]}
    result = run_scene(scene, tmp_path / "out")
    out = tmp_path / "out"
    data = pd.read_csv(out / "lifetime_vs_force_data.csv")
    assert set(data["series"]) == {"fem-fed, paper route", "appendix-a-fed, paper route"}
    assert set(data["x_quantity"]) == {"pull force F_1 (N)"} and set(data["y_quantity"]) == {"lifetime (s)"}
    fem = data[data["series"] == "fem-fed, paper route"]
    table = pd.read_csv(out / "lifetimes.csv")
    assert list(fem["x"]) == list(table["force_N"]) and list(fem["y"]) == pytest.approx(list(table["lifetime_s"]), rel=1e-9)
    from validation.bridge.products import Products
    reference = Products(scene_from_mapping(scene).study()).appendix_a().lifetimes()
    appendix = data[data["series"] == "appendix-a-fed, paper route"]
    assert list(appendix["y"]) == pytest.approx([r.lifetime_s for r in reference], rel=1e-9)
    F0 = pd.read_csv(out / "F0_vs_u_data.csv")
    curve = pd.read_csv(out / "curve.csv")
    drawn = F0[F0["series"] == "fem"]
    assert list(drawn["x"]) == pytest.approx(list(curve["u_mm"])) and list(drawn["y"]) == pytest.approx(list(curve["F0_N"]))
    assert {f["path"].rsplit("/", 1)[-1] for f in result.files} >= {"lifetime_vs_force_data.csv", "F0_vs_u_data.csv"}
