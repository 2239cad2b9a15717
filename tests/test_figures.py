"""The toolkit's figures, measured rather than looked at (validation.style, render.compose, the
sweep figures, the 3D views).

Every figure written through `validation.style.save_figure` during a test is measured at the
moment it is saved (the `measured` fixture): no drawn text may leave the canvas, and its colour
bars and their labels are recorded. The PNGs are measured too: the scale bar is found as a dark
horizontal run of pixels whose length is the bar's length over the pixel size.
"""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.image import imread

from validation import style
from validation.bridge.cache import file_digest

RANGES = [(20, 60), (600, 2000), (5, 200), (1, 1e4), (550, 650), (0.2, 0.9), (3e-3, 40)]


@pytest.fixture
def measured(monkeypatch):
    """Every figure saved during the test: its clipped texts, colour-bar labels and log axes."""
    seen = []
    save = style.save_figure

    def checking(fig, path, **kw):
        style.readable_log_axes(fig)
        bars = [ax for ax in fig.axes if hasattr(ax, "_colorbar")]
        seen.append({"path": path, "clipped": style.clipped_texts(fig),
                     "colorbars": [(ax.get_ylabel() or ax.get_xlabel()) for ax in bars],
                     "log_ticks": _log_tick_labels(fig),
                     "x_overlap": _x_labels_overlap(fig),
                     "axes": [(ax.get_xlabel(), ax.get_ylabel(), [t.get_text() for t in ax.get_xticklabels()])
                              for ax in fig.axes if not hasattr(ax, "_colorbar")]})
        return save(fig, path, **kw)

    monkeypatch.setattr(style, "save_figure", checking)
    return seen


def _log_tick_labels(fig) -> list[list[str]]:
    """Per log axis of a drawn figure: the labels of its major ticks inside the view."""
    fig.canvas.draw()
    out = []
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() == "log":
                lo, hi = sorted(axis.get_view_interval())
                out.append([t.label1.get_text() for t in axis.get_major_ticks()
                            if lo * (1 - 1e-9) <= t.get_loc() <= hi * (1 + 1e-9) and t.label1.get_text()])
    return out


def _x_labels_overlap(fig) -> bool:
    """Whether any axes of a drawn figure has two shown x tick labels (inside the view) that overlap
    (the hidden labels of an axes sharing x with the one below have no extent to compare)."""
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        lo, hi = sorted(ax.xaxis.get_view_interval())
        boxes = [t.label1.get_window_extent(renderer) for t in ax.xaxis.get_major_ticks()
                 if lo - 1e-9 * abs(hi) <= t.get_loc() <= hi + 1e-9 * abs(hi) and t.label1.get_text()
                 and t.label1.get_visible()]
        if _boxes_overlap(boxes):
            return True
    return False


def _boxes_overlap(boxes) -> bool:
    boxes = sorted(boxes, key=lambda b: b.x0)
    return any(a.x1 > b.x0 + 0.5 for a, b in zip(boxes, boxes[1:]))


def test_the_style_sheet_ships_with_the_package_and_sets_a_column_width():
    import matplotlib.pyplot as plt
    assert style.STYLE_SHEET.is_file()
    with style.cupcheck_style():
        fig = plt.figure()
        assert fig.get_figwidth() == pytest.approx(style.COLUMN_WIDTH_IN)
        assert fig.get_layout_engine() is not None            # constrained layout: nothing clipped
        plt.close(fig)


@pytest.mark.parametrize("lo, hi", RANGES)
def test_log_axes_have_three_plain_labels_that_do_not_overlap(lo, hi):
    """On a column-wide figure, a log axis over [lo, hi] shows >= 3 labelled ticks, each label the
    number at its tick (no 2x10^1), none overlapping its neighbour, none clipped."""
    import matplotlib.pyplot as plt

    with style.cupcheck_style():
        fig, ax = plt.subplots()
        ax.plot([lo, hi], [lo, hi])
        style.log_axis(ax, "both")
        ax.set(xlim=(lo, hi), ylim=(lo, hi), xlabel="x (mm$^3$)", ylabel="y (s)")
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        ticks = [t for t in ax.xaxis.get_major_ticks() if lo * (1 - 1e-9) <= t.get_loc() <= hi * (1 + 1e-9)]
        labels = [t.label1.get_text() for t in ticks]
        print(f"[{lo:g}, {hi:g}]: {labels}")
        assert len(ticks) >= 3
        for t in ticks:
            text = t.label1.get_text()
            if "10^" not in text:
                assert float(text) == pytest.approx(t.get_loc(), rel=1e-6)
        assert not _boxes_overlap([t.label1.get_window_extent(renderer) for t in ticks])
        assert style.clipped_texts(fig) == []
        plt.close(fig)


def test_display_unit_puts_the_largest_value_between_1_and_1000():
    for largest, unit in ((740.0, "Pa"), (1480.0, "kPa"), (1.48e6, "MPa"), (2.1e9, "GPa")):
        shown = style.display_unit("Pa", largest)
        assert shown.unit == unit and 1 <= shown.factor * largest < 1000
    assert style.display_unit("", 0.7) == style.DisplayUnit(1.0, "")


def test_a_stress_colour_bar_reads_in_MPa_without_exponents(measured, tmp_path):
    """von Mises 0 .. 1.48 MPa: the bar is titled in MPa and its tick labels are plain numbers
    that match their positions (the issue's '741 / 1.48e+03' in kPa does not recur)."""
    import matplotlib.pyplot as plt
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    clim = (0.0, 1.48e6)
    unit = style.display_unit("Pa", clim[1])
    with style.cupcheck_style():
        fig, ax = plt.subplots()
        bar = style.colorbar(fig, ScalarMappable(Normalize(*(unit.factor * c for c in clim)), "viridis"),
                             "von_mises", unit, ax=ax)
        fig.canvas.draw()
        ticks = [(t.get_loc(), t.label1.get_text()) for t in bar.ax.yaxis.get_major_ticks()
                 if 0 <= t.get_loc() <= 1.48 and t.label1.get_text()]
        labels = [s for _, s in ticks]
        style.save_figure(fig, tmp_path / "bar.png")
    assert measured[0]["colorbars"] == ["von Mises stress (MPa)"] and not measured[0]["clipped"]
    assert len(labels) >= 3 and not any("e" in s or "10^" in s for s in labels)
    assert all(float(s.replace("\u2212", "-")) == pytest.approx(loc) for loc, s in ticks)


def test_every_quantity_has_a_perceptually_uniform_colormap():
    uniform = {"viridis", "plasma", "inferno", "magma", "cividis"}
    assert all(q.cmap in uniform for q in style.QUANTITIES.values())
    for field in ("contact_pressure", "von_mises", "min_stretch"):
        assert field in style.QUANTITIES


def _dark_runs(img: np.ndarray, box) -> list[int]:
    """Lengths of horizontal runs of near-black pixels inside the box (col0, row0, col1, row1)."""
    c0, r0, c1, r1 = box
    dark = img[r0:r1, c0:c1, :3].max(-1) < 0.25
    runs = []
    for row in dark:
        edges = np.flatnonzero(np.diff(np.concatenate([[0], row.astype(int), [0]])))
        runs += list(edges[1::2] - edges[0::2])
    return runs


def _scale_bar_found(png, box, bar_m: float, m_per_px: float) -> bool:
    expected = bar_m / m_per_px
    runs = _dark_runs(imread(png), box)
    return sum(abs(r - expected) <= 2 for r in runs) >= 2          # the bar is 2 px thick at least


def test_a_composed_image_is_placed_pixel_for_pixel_with_a_scale_bar(measured, tmp_path):
    """A synthetic render (a white image with a grey disc 10 mm across, 50 um per pixel): the PNG
    holds it unresampled in the box `compose` reports, the scale bar is a dark run of its length
    in pixels, the colour bar is labelled in kPa, and no text is clipped."""
    from validation.render.compose import ColourKey, compose

    m_per_px = 50e-6
    rows, cols = 300, 400
    yy, xx = np.mgrid[:rows, :cols]
    img = np.full((rows, cols, 3), 255, np.uint8)
    img[np.hypot(xx - 200, yy - 150) < 100] = 128                        # 10 mm across
    placed = compose(img, tmp_path / "c.png", m_per_px=m_per_px, title="a long title, u = 3 mm, sticking",
                     colour=ColourKey("contact_pressure", (0.0, 8.0e4)))
    assert placed.m_per_px == pytest.approx(m_per_px, rel=1e-9)
    png = imread(placed.path)
    c0, r0, c1, r1 = placed.view_box_px
    grey = np.abs(png[r0:r1, c0:c1, 0] - 128 / 255) < 0.02
    assert grey.sum(1).max() == pytest.approx(200, abs=2)                 # the disc's diameter in px
    assert _scale_bar_found(placed.path, placed.view_box_px, placed.scale_bar_m, placed.m_per_px)
    assert not _scale_bar_found(placed.path, placed.view_box_px, 1.5 * placed.scale_bar_m, placed.m_per_px)
    assert measured[0]["colorbars"] == ["contact pressure (kPa)"] and measured[0]["clipped"] == []


# ------------------------------------------------------------------------------ sweep figures
def _sweep_table(tmp_path, axis_values, volumes):
    """A results.parquet as the sweep writes it (pandas' string dtype for a categorical column)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows = []
    for k, ((alpha, contact), vol) in enumerate(zip(axis_values, volumes)):
        rows.append({"design_hash": f"h{k}", "alpha_deg": alpha, "contact": contact, "F1_N": 10.0,
                     "lifetime_s": 30.0 * vol / 600 * (1.3 if contact == "sticking" else 1.0),
                     "small_u_stiffness_N_per_mm": 2.0 + alpha / 40, "volume_mm3": vol, "failure": None})
    frame = pd.DataFrame(rows).astype({"contact": "string", "failure": "string"})
    path = tmp_path / "results.parquet"
    pq.write_table(pa.Table.from_pandas(frame), path)
    return path


def test_sweep_figures_draw_a_categorical_contact_axis_with_named_axes(measured, tmp_path):
    """A grid over alpha_deg x contact = [frictionless, sticking] (contact read back as pandas'
    string dtype): the maps and the Pareto figure are written, the axes carry names and units,
    the categories are the tick labels, the Pareto's log axes have >= 3 non-overlapping labels."""
    from validation.sweeps.figures import sweep_figures

    values = [(a, c) for a in (25.0, 33.0, 40.0) for c in ("frictionless", "sticking")]
    table = _sweep_table(tmp_path, values, [620, 700, 900, 1100, 1500, 1900])
    paths = sweep_figures(table, ["alpha_deg", "contact"], tmp_path)
    assert {p.name for p in paths} == {"map_lifetime_s.png", "map_small_u_stiffness_N_per_mm.png",
                                       "pareto_lifetime_volume.png"}
    assert all(m["clipped"] == [] for m in measured)
    maps = [m for m in measured if m["path"].name.startswith("map_")]
    assert [m["colorbars"] for m in maps] == [["lifetime (s)"], ["small-u stiffness (N/mm)"]]
    pareto = next(m for m in measured if m["path"].name.startswith("pareto"))
    assert len(pareto["log_ticks"]) == 2 and all(len(t) >= 3 for t in pareto["log_ticks"])
    assert not pareto["x_overlap"]


def test_sweep_map_labels_are_names_with_units(measured, tmp_path):
    from validation.sweeps import figures

    table = _sweep_table(tmp_path, [(25.0, "frictionless"), (33.0, "sticking")], [600, 900])
    figures.sweep_figures(table, ["contact", "alpha_deg"], tmp_path)
    xlabel, ylabel, ticks = measured[0]["axes"][0]
    assert (xlabel, ylabel) == ("contact law", "cone angle \u03b1 (deg)")
    assert ticks == ["frictionless", "sticking"]
    assert figures.axis_label("d0_mm") == "wall thickness d0 at r0 (mm)"
    assert figures.axis_label("something_N_per_mm") == "something (N/mm)"


def test_nice_length_is_1_2_5_not_above_the_limit():
    for limit, nice in ((0.0123, 0.01), (0.0049, 0.002), (2.6e-4, 2e-4), (0.05, 0.05)):
        assert style.nice_length(limit) == pytest.approx(nice)
    assert style.length_label(0.005) == "5 mm" and style.length_label(2e-4) == "200 \u00b5m"


def test_a_3d_views_caption_names_design_contact_law_and_mesh():
    from validation.bridge.products import Products
    from validation.bridge.study import Contact, CupDesign, Study
    from validation.scenes.views3d import view_caption

    study = Study(design=CupDesign(preset="B"), contact=Contact("coulomb", 0.5), fidelity="medium")
    assert view_caption(Products(study)) == "cup B, coulomb mu = 0.5, medium mesh"
    assert view_caption(Products(Study())) == "cup A, frictionless, coarse mesh"


# ------------------------------------------------------------------------------ 3D views (real renders)
@pytest.fixture(scope="module")
def frames():
    """Cup A (coarse, frictionless) at four states from u = 0 to 0.84 h1, all fields."""
    from validation.render import probe_offscreen_rendering

    probe = probe_offscreen_rendering()
    if not probe.ok:
        pytest.skip(probe.message)
    from fem.cup import compress_cup
    from fem.geometry import cup_geometry
    from fem.material import NeoHookean
    from fem.mesh import cup_mesh
    from validation.render.frames import frame_from_response

    g = cup_geometry("A")
    resp = compress_cup(cup_mesh(g, "coarse"), NeoHookean(E_Pa=4e6, nu=0.49), u_max_m=0.84 * g.h1_m)
    steps = [int(np.argmin(np.abs(resp.u_m - t))) for t in np.linspace(0, resp.u_m[-1], 4)]
    return [frame_from_response(resp, k) for k in steps]


@pytest.mark.parametrize("field, unit", [("von_mises", "MPa"), ("contact_pressure", "kPa"), ("min_stretch", "")])
def test_a_cutaway_has_its_colour_bar_unclipped_and_a_scale_bar(frames, measured, tmp_path, field, unit):
    from validation.render.views import cutaway

    image = cutaway(frames[-1], field, tmp_path / "c.png", title="cup A, coarse, frictionless, u = 7.6 mm")
    (m,) = measured
    label = style.quantity(field).label + (f" ({unit})" if unit else "")
    assert m["clipped"] == [] and m["colorbars"] == [label]
    assert _scale_bar_found(image.path, image.view_box_px, image.scale_bar_m, image.m_per_px)


def test_the_footprints_scale_is_the_same_for_every_state_of_a_cup(frames, measured, tmp_path):
    """Two states of cup A drawn as footprints: one pixel size, one axis pixel, a scale bar of the
    length its label says, the contact pressure bar unclipped."""
    from validation.render.views import footprint

    a = footprint(frames[-2], tmp_path / "a.png", title="from below, u = 5.2 mm")
    b = footprint(frames[-1], tmp_path / "b.png", title="from below, u = 7.6 mm")
    assert a.m_per_px == b.m_per_px and a.centre_px == b.centre_px
    assert all(m["clipped"] == [] and m["colorbars"] == ["contact pressure (kPa)"] for m in measured)
    for image in (a, b):
        assert _scale_bar_found(image.path, image.view_box_px, image.scale_bar_m, image.m_per_px)


def test_the_squeeze_of_the_contact_pressure_shows_it_side_on(frames, measured, tmp_path):
    """The squeeze's default field: side-on, the pressure profile hangs below the plane line, so
    the last frame has saturated (coloured) pixels below the plane, the first (no contact) none;
    every frame has its colour bar in kPa and a scale bar."""
    from validation.render.views import squeeze

    seq = squeeze(frames, "contact_pressure", tmp_path / "sq")
    c0, r0, c1, r1 = seq.view_box_px
    first, last = (imread(p)[r0:r1, c0:c1, :3] for p in (seq.frames[0], seq.frames[-1]))
    plane_row = int(np.argmax((first.max(-1) < 0.2).sum(1)))

    def coloured_below(img):
        hi, lo = img.max(-1), img.min(-1)
        return int(((hi - lo) / np.maximum(hi, 1e-9) > 0.4)[plane_row + 2:].sum())

    print(f"coloured pixels below the plane: first {coloured_below(first)}, last {coloured_below(last)}")
    assert coloured_below(first) == 0 and coloured_below(last) > 500
    assert all(m["clipped"] == [] and m["colorbars"] == ["contact pressure (kPa)"] for m in measured)
    assert _scale_bar_found(seq.frames[-1], seq.view_box_px, seq.scale_bar_m, seq.m_per_px)


# ------------------------------------------------------------------------------ crosscheck figures
def test_the_validate_pareto_figure_reads(measured, tmp_path):
    """The speed section's Pareto figure (wall time 3 ms .. 40 s, errors 1e-7 .. 0.1, the level
    names annotated at the points): nothing clipped, no overlapping x labels, >= 3 labelled ticks on
    every log axis."""
    from types import SimpleNamespace

    from validation.crosscheck import speed
    from validation.crosscheck.report import Report

    levels = [("Appendix A (d0 2 mm)", 3e-3, 0.1), ("FEM coarse Q2", 0.8, 2e-2), ("FEM medium Q2", 3.0, 5e-3),
              ("FEM fine Q2", 12.0, 1e-3), ("FEM finest Q2", 40.0, 1e-7)]
    rows = [{"level": name, "wall_s": t, "errors": {q: e * (1 + k) for k, q in enumerate(speed.QUANTITIES)}}
            for name, t, e in levels]
    rrows = [[rtol, 2e-3 / rtol ** 0.1, 10, 100.0, rtol] for rtol in (1e-3, 1e-5, 1e-7)]
    speed._pareto(SimpleNamespace(report=Report(tmp_path)), {"frictionless": rows, "sticking": rows}, rrows)
    (m,) = measured
    print(m["log_ticks"])
    assert m["clipped"] == [] and not m["x_overlap"]
    assert len(m["log_ticks"]) == 4 and all(len(t) >= 3 for t in m["log_ticks"])


def test_sweep_figures_name_the_base_design_law_mesh_route_and_surface(measured, tmp_path):
    """A sweep's maps and Pareto figure carry the caption of what its designs share (the shipped
    alpha x thickness sweep's base: cup A, sticking, coarse, paper route, pmma-1.89) and what they
    vary, unclipped."""
    from pathlib import Path

    from validation.sweeps.figures import sweep_caption, sweep_figures
    from validation.sweeps.spec import load_sweep

    spec = load_sweep(Path(__file__).parents[1] / "scenes" / "sweep_alpha_thickness.toml")
    caption = sweep_caption(spec.base, [a["name"] for a in spec.axes])
    assert caption == ("base cup A; FEM sticking (coarse mesh); paper route; pmma-1.89"
                       "\nvaried: cone angle \u03b1 (deg), wall thickness d0 at r0 (mm)")
    assert "contact law varied" in sweep_caption({**spec.base, "contact": "coulomb"}, ["friction"])
    table = _sweep_table(tmp_path, [(25.0, "frictionless"), (33.0, "sticking")], [600, 900])
    seen = []
    import matplotlib.figure
    monkey = matplotlib.figure.Figure.suptitle

    def recording(fig, text, **kw):
        seen.append(text)
        return monkey(fig, text, **kw)

    matplotlib.figure.Figure.suptitle = recording
    try:
        paths = sweep_figures(table, ["alpha_deg", "contact"], tmp_path, caption)
    finally:
        matplotlib.figure.Figure.suptitle = monkey
    assert len(paths) == 3 and seen == [caption] * 3
    assert all(m["clipped"] == [] for m in measured)


# ------------------------------------------------------------------ figures drawn in a second process
def _drawing_processes():
    import multiprocessing
    return [p for p in multiprocessing.active_children() if p.name == "cupcheck-figures"]


_FORKS = pytest.mark.skipif("not __import__('validation.scenes.drawing').scenes.drawing.can_fork()",
                            reason="figures are drawn in a second process only where it can fork")
#: a FEM study of cup A (the lifetime figure draws the Appendix A-fed lifetimes beside it) and its curve
_SCENE = {"loads": {"F1_N": [10, 40]}, "outputs": [
    {"kind": "lifetimes"}, {"kind": "figure", "figure": "lifetime_vs_force"}, {"kind": "curve"},
    {"kind": "figure", "figure": "F0_vs_u"}]}


@_FORKS
def test_figures_drawn_aside_are_the_figures_drawn_in_process(tmp_path):
    """The same scene with its figures drawn in the drawing process and in this one: the same files
    in the same order, the same PNG pixels and the same data tables (what each figure draws, the
    Appendix A-fed lifetimes included), and no drawing process left."""
    from validation.scenes.outputs import run_scene

    here = run_scene(_SCENE, tmp_path / "here", cache_dir=tmp_path / "cache")
    aside = run_scene(_SCENE, tmp_path / "aside", cache_dir=tmp_path / "cache", figure_process=True)
    assert [(f["name"], f["kind"], Path(f["path"]).name) for f in aside.files] == \
        [(f["name"], f["kind"], Path(f["path"]).name) for f in here.files]
    for name in ("lifetime_vs_force", "F0_vs_u"):
        assert np.array_equal(imread(tmp_path / "aside" / f"{name}.png"), imread(tmp_path / "here" / f"{name}.png"))
        assert (tmp_path / "aside" / f"{name}_data.csv").read_bytes() == \
            (tmp_path / "here" / f"{name}_data.csv").read_bytes()
    assert set(pd.read_csv(tmp_path / "aside" / "lifetime_vs_force_data.csv").series) == \
        {"fem-fed, paper route", "appendix-a-fed, paper route"}
    manifest = json.loads((tmp_path / "aside" / "manifest.json").read_text())
    assert all(f["sha256"] == file_digest(tmp_path / "aside" / f["path"]) for f in manifest["files"])
    assert _drawing_processes() == []


@_FORKS
def test_a_figure_failing_aside_raises_here_and_a_dead_drawer_is_an_error(tmp_path):
    """A figure the drawing process cannot write raises its own error in this process; a drawing
    process that was killed is a RuntimeError naming the figure; either way none is left."""
    import os
    import signal

    from validation.bridge.products import Products
    from validation.scenes.drawing import FigureDrawer
    from validation.scenes.schema import scene_from_mapping

    products = Products(scene_from_mapping({"stiffness": {"source": "appendix-a"}, "outputs": [{"kind": "curve"}]}).study())
    with FigureDrawer(forked=True) as drawer:
        assert drawer.forked
        drawer.submit("F0_vs_u", products, [tmp_path / "no" / "F0.svg", tmp_path / "no" / "F0.png"], None)
        with pytest.raises(FileNotFoundError):
            drawer.wait()
    assert _drawing_processes() == []
    with FigureDrawer(forked=True) as drawer:
        os.kill(_drawing_processes()[0].pid, signal.SIGKILL)
        drawer.submit("F0_vs_u", products, [tmp_path / "F0.svg", tmp_path / "F0.png"], None)
        with pytest.raises(RuntimeError, match="figure F0_vs_u: the drawing process ended before drawing it"):
            drawer.wait()
    assert _drawing_processes() == []


@_FORKS
def test_ctrl_c_is_the_main_processes_and_an_interrupted_run_leaves_nothing(tmp_path):
    """The drawing process ignores Ctrl-C (the main process reports it); a run interrupted after a
    figure was sent to it writes nothing, leaves no temporary directory and no drawing process."""
    import os
    import signal
    import time

    from validation.scenes.drawing import FigureDrawer
    from validation.scenes.outputs import run_scene

    with FigureDrawer(forked=True) as drawer:
        child = _drawing_processes()[0]
        os.kill(child.pid, signal.SIGINT)
        time.sleep(0.3)
        assert child.is_alive() and drawer.forked
    assert not child.is_alive()

    def interrupt(message):
        if message.startswith("output 3 of 4"):          # the lifetime figure has been sent
            raise KeyboardInterrupt

    scene = {**_SCENE, "stiffness": {"source": "appendix-a"}}
    with pytest.raises(KeyboardInterrupt):
        run_scene(scene, tmp_path / "out", progress=interrupt, figure_process=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == [] and _drawing_processes() == []
