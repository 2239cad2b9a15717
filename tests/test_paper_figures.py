"""The paper's figure set (`cupcheck paper`, validation/scenes/paper.py): the set and the paper's
numbers parse, bad input is one line and exit 2 before any work, the committed gallery is small
and complete, and (slow) the whole set at the coarse level, its images measured and its tables
checked against the physics they must obey.
"""

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.image import imread

from tests.cli import run_cli
from tests.test_figures import _log_tick_labels, _x_labels_overlap
from validation import style
from validation.scenes.paper import PAPER_FIGURES, run_paper
from validation.scenes.paper_marks import PAPER_ROUTE_LABEL, all_paper_numbers, paper_numbers

ROOT = Path(__file__).resolve().parents[1]
#: the paper's calculated figures the set must draw (issue: "The paper's figures in one command")
WANTED = {"F0_vs_u_cups", "lifetime_vs_force_cups", "r_pb_vs_time", "p_Ndot_vs_time", "lifetime_vs_kappa",
          "lifetime_vs_rms", "lifetime_vs_r_start", "uc_vs_pressure"}
RECORD = ["design", "contact", "mesh", "route", "surface"]


def test_the_set_draws_every_calculated_figure_of_the_paper():
    from validation.commands.paper import FIGURE_NAMES
    assert set(PAPER_FIGURES) == WANTED
    assert FIGURE_NAMES == tuple(PAPER_FIGURES)          # --help's list is the set's
    assert all(re.search(r"Fig", f.paper) for f in PAPER_FIGURES.values())


def test_every_paper_number_names_its_source_and_figure():
    numbers = all_paper_numbers()
    assert len(numbers) >= 20
    for n in numbers:
        assert n.figure in PAPER_FIGURES, n
        assert re.search(r"Sec\. \d|Table 1|App\. A|Fig\. |eq \(", n.source), n
        assert n.stated.strip() and n.unit
    drawn = {n.figure for n in numbers if n.kind not in ("claim", "input")}
    assert drawn >= WANTED - {"p_Ndot_vs_time"}           # the paper states no number for Ndot(t)


def test_the_stated_u_c_values_are_the_papers_words():
    """The u_c stars: each value (nm) is the number quoted (um) in its `stated` text."""
    for n in paper_numbers("uc_vs_pressure", "point"):
        assert f"{n.value / 1000:.2f}".rstrip("0") in n.stated or f"{n.value / 1000:g}" in n.stated, n


@pytest.mark.parametrize("argv, field", [(["--fidelity", "rough"], "--fidelity"), (["--only", "Fig9"], "--only")])
def test_bad_input_is_one_line_and_exit_2_before_any_work(capsys, tmp_path, argv, field):
    out = tmp_path / "paper"
    code, stdout, err = run_cli(capsys, "paper", "--out", out, *argv)
    assert code == 2 and len(err.strip().splitlines()) == 1 and field in err
    assert not out.exists()


def test_run_paper_refuses_an_unknown_figure_before_any_work(tmp_path):
    with pytest.raises(ValueError, match="--only: unknown figure 'nope'"):
        run_paper(tmp_path / "paper", only=("nope",))
    assert not (tmp_path / "paper").exists()


def test_the_committed_gallery_shows_every_figure_small_with_its_command():
    page = (ROOT / "docs" / "paper-figures.md").read_text()
    for name in PAPER_FIGURES:
        png = ROOT / "docs" / "paper-figures" / f"{name}.png"
        assert png.stat().st_size < 150_000, png
        assert imread(png).shape[1] == round(style.COLUMN_WIDTH_IN * 300)       # a journal column at 300 dpi
        assert f"](paper-figures/{name}.png)" in page and f"cupcheck paper --out out/paper --only {name}" in page


@pytest.fixture
def seen(monkeypatch):
    """Every figure the set saves: clipped texts, colour-bar labels, legend texts, the caption."""
    found = {}
    save = style.save_figure

    def checking(fig, path, **kw):
        legends = [leg for leg in (*fig.legends, *(ax.get_legend() for ax in fig.axes)) if leg is not None]
        found[Path(path).stem] = {
            "clipped": style.clipped_texts(fig),
            "log_ticks": _log_tick_labels(fig), "x_overlap": _x_labels_overlap(fig),
            "colorbars": [ax.get_ylabel() for ax in fig.axes if hasattr(ax, "_colorbar")],
            "legend": " | ".join(t.get_text() for leg in legends for t in leg.get_texts()),
            "title": fig._suptitle.get_text() if fig._suptitle else ""}
        return save(fig, path, **kw)

    monkeypatch.setattr(style, "save_figure", checking)
    return found


@pytest.mark.slow
def test_the_whole_set_at_coarse_reads_and_obeys_its_physics(seen, tmp_path):
    out = tmp_path / "paper"
    results = run_paper(out, fidelity="coarse")
    manifest = json.loads((out / "manifest.json").read_text())
    files = sorted(p.name for p in out.iterdir())
    assert files == sorted(["manifest.json", *(f["path"] for f in manifest["files"])])
    assert len(results) == 8 and all(len(r.files) == 3 and r.sentence for r in results)
    page = (ROOT / "docs" / "paper-figures.md").read_text()      # the committed gallery says what a fresh run says
    stale = [r.figure.name for r in results if f"**Against the paper.** {r.sentence}" not in page]
    assert not stale, f"docs/paper-figures.md is stale for {stale}: python -m validation.scenes.gallery --paper"

    for name, m in seen.items():                           # the images, measured
        assert m["clipped"] == [], (name, m["clipped"])
        assert not m["x_overlap"] and all(len(t) >= 3 for t in m["log_ticks"]), (name, m["log_ticks"])
        assert imread(out / f"{name}.png").shape[1] == round(style.COLUMN_WIDTH_IN * 300)
        if name not in ("F0_vs_u_cups", "uc_vs_pressure"):
            assert "frictionless (coarse), profile route" in m["legend"] and "paper route" in m["legend"], name
    assert "frictionless (coarse)" in seen["F0_vs_u_cups"]["legend"] and "Appendix A" in seen["F0_vs_u_cups"]["legend"]
    for name in ("r_pb_vs_time", "p_Ndot_vs_time"):
        assert seen[name]["colorbars"] == ["pull force $F_1$ (N)"]

    tables = {name: pd.read_csv(out / f"{name}.csv", keep_default_na=False) for name in PAPER_FIGURES}
    for name, t in tables.items():                         # every table names what each row was computed for
        assert set(RECORD) <= set(t.columns), name
        marks = t[t.route == PAPER_ROUTE_LABEL]
        assert len(marks) == sum(2 if n.kind in ("band", "slope") else 1 for n in paper_numbers(name)
                                 if n.kind not in ("claim", "input")), name
        assert len(marks) == 0 or (marks.source != "").all()
        if name != "uc_vs_pressure":
            assert {"profile", "paper"} <= set(t.route), name

    # the lifetime against F1 is where each trajectory ends (two outputs of one computation agree)
    lives, traj, leak = tables["lifetime_vs_force_cups"], tables["r_pb_vs_time"], tables["p_Ndot_vs_time"]
    for route in ("profile", "paper"):
        a = lives[(lives.route == route) & (lives.design == "cup A")]
        assert len(a) == 16
        for F, life in zip(a.F1_N.astype(float), a.lifetime_s.astype(float)):
            t = traj[(traj.route == route) & (traj.series == f"F1 = {F:g} N")]
            assert t.t_s.astype(float).max() == pytest.approx(life, rel=1e-9)
        # gas only leaks in: the leak rate is positive at every drawn instant
        n_dot = leak[(leak.route == route) & (leak.N_dot_per_s != "")].N_dot_per_s.astype(float)
        assert len(n_dot) > 100 and (n_dot > 0).all()
    # water is ~20x more viscous than air: at every start radius the cup holds longer in water
    r = tables["lifetime_vs_r_start"]
    for route in ("profile", "paper"):
        dry = r[(r.route == route) & (r.fluid == "air")].lifetime_s.astype(float).to_numpy()
        wet = r[(r.route == route) & (r.fluid == "water")].lifetime_s.astype(float).to_numpy()
        assert len(dry) == len(wet) == 9 and np.all(wet > 10 * dry)
