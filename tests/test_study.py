"""validation.bridge.study and validation.bridge.products: one typed study per case, its products lazy and cached
by content; a scene file is one spelling of it."""

from dataclasses import FrozenInstanceError, replace
from pathlib import Path

import pytest

from validation.bridge import products as products_module
from validation.bridge.products import Products
from validation.scenes.schema import load_scene, scene_from_mapping
from validation.bridge.study import Contact, Loads, Study, Surface

ROOT = Path(__file__).resolve().parents[1]

#: Appendix A on cup A: the reduced model alone (no FEM), fast
APPENDIX = Study(stiffness="appendix-a", loads=Loads(forces_N=(10.0, 40.0)))


def test_a_scene_file_is_a_study():
    study = load_scene(ROOT / "scenes" / "main.toml").study()
    assert (study.route, study.fidelity, study.stiffness, study.design.preset) == ("profile", "medium", "fem", "A")
    assert study.loads.forces_N == tuple(float(f) for f in range(5, 85, 5))
    assert study.contact == Contact("frictionless", None, "scene file main.toml")
    assert study.surface == Surface("pmma-1.89", None)
    with pytest.raises(FrozenInstanceError):
        study.route = "paper"


def test_a_swept_scene_gives_one_study_per_value():
    scene = scene_from_mapping({"stiffness": {"source": "appendix-a"}, "sweep": {"key": "cup.preset", "values": ["A", "B"]},
                                "outputs": [{"kind": "lifetimes"}]})
    variants = scene.study().variants()
    assert [v for v, _ in variants] == ["A", "B"]
    assert [s.design.preset for _, s in variants] == ["A", "B"] and all(s.sweep is None for _, s in variants)
    kappa = replace(APPENDIX).with_value("loads.kappa", 2.0)
    assert kappa.loads.kappa == 2.0 and kappa.loads.forces_N == APPENDIX.loads.forces_N


def test_products_are_lazy_and_cached_by_content(tmp_path):
    products_module.COMPUTED.clear()
    first = Products(APPENDIX, cache_dir=tmp_path)
    assert first.uc_table() is not None and dict(products_module.COMPUTED) == {"uc_table": 1}
    life = first.lifetimes()
    assert dict(products_module.COMPUTED) == {"uc_table": 1, "lifetimes": 1}
    again = Products(replace(APPENDIX), cache_dir=tmp_path).lifetimes()
    assert dict(products_module.COMPUTED) == {"uc_table": 1, "lifetimes": 1}        # nothing new
    assert [r.lifetime_s for r in again] == [r.lifetime_s for r in life]
    Products(replace(APPENDIX, loads=Loads(forces_N=(20.0,))), cache_dir=tmp_path).lifetimes()
    assert products_module.COMPUTED["lifetimes"] == 2                               # other loads: computed


def test_stiffer_study_holds_longer():
    """The paper's stiffness factor (Fig. 1stiffnessFactor): at 10 N a stiffer cup lasts longer."""
    soft, stiff = (Products(APPENDIX.with_value("loads.kappa", k)).lifetimes()[0].lifetime_s for k in (1.0, 2.0))
    assert 0 < soft < stiff


def _cup_sweep(tmp_path=None):
    return scene_from_mapping({"stiffness": {"source": "appendix-a"}, "loads": {"F1_N": [10, 40]},
                               "sweep": {"key": "cup.preset", "values": ["A", "B"]},
                               "outputs": [{"kind": "lifetimes", "name": "life"},
                                           {"kind": "figure", "figure": "lifetime_vs_force"}]})


def test_lifetime_figure_draws_every_swept_cup():
    """A scene sweeping cup.preset draws one lifetime line per cup (each its own lifetimes), titled
    with both cups, the stiffness, the route and the surface."""
    from validation.scenes.figures import FIGURES, caption
    from validation.style import cupcheck_style

    products = Products(_cup_sweep().study())
    with cupcheck_style():
        fig = FIGURES["lifetime_vs_force"](products)
    lines = {line.get_label(): line.get_ydata() for line in fig.axes[0].get_lines()}
    assert set(lines) == {"cup A", "cup B"}
    for cup, (_, variant) in zip("AB", products.variants()):
        held = [r.lifetime_s for r in variant.lifetimes() if 0 < r.lifetime_s < float("inf")]
        assert list(lines[f"cup {cup}"]) == held and held
    assert list(lines["cup A"]) != list(lines["cup B"])         # two cups, two answers
    assert caption(products) == "cups A, B; Appendix A (d0 2 mm); paper route; pmma-1.89"
    import matplotlib.pyplot as plt
    plt.close(fig)


def test_scene_tables_and_figures_name_what_they_were_computed_for(tmp_path):
    import pandas as pd

    from validation.scenes.outputs import run_scene

    result = run_scene(_cup_sweep(), tmp_path / "out")
    table = pd.read_csv(tmp_path / "out" / "life.csv", keep_default_na=False)
    assert list(table.columns[:7]) == ["preset", "design", "contact", "mesh", "route", "surface", "force_N"]
    assert list(table.design) == ["cup A", "cup A", "cup B", "cup B"] and set(table.route) == {"paper"}
    assert {f["path"].rsplit(".", 1)[1] for f in result.files if f["kind"] == "figure"} == {"png", "svg", "csv"}
    svg = (tmp_path / "out" / "lifetime_vs_force.svg").read_text()
    assert "cups A, B; Appendix A (d0 2 mm); paper route; pmma-1.89" in svg
    data = pd.read_csv(tmp_path / "out" / "lifetime_vs_force_data.csv")     # what the figure draws
    assert set(data.figure) == {"cups A, B; Appendix A (d0 2 mm); paper route; pmma-1.89"}
    assert set(data.series) == {"cup A", "cup B"}


def test_scene_figures_keep_their_captions_on_the_canvas(tmp_path, monkeypatch):
    from validation import style
    from validation.scenes.outputs import run_scene

    seen, save = [], style.save_figure

    def measuring(fig, path, **kw):
        seen.append((fig._suptitle.get_text(), style.clipped_texts(fig)))
        return save(fig, path, **kw)

    monkeypatch.setattr(style, "save_figure", measuring)
    run_scene(_cup_sweep(), tmp_path / "out")
    assert seen == [("cups A, B; Appendix A (d0 2 mm); paper route; pmma-1.89", [])]
