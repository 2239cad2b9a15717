"""The paper's calculated figures, drawn by cupcheck: `run_paper(out)` (`cupcheck paper --out DIR`).

Each figure of Tiwari & Persson's Sec. 5 that is a calculation is drawn twice over: fed by the
FEM (cup A or B, frictionless, at the chosen mesh level, through the profile route: the FEM's F0,
contact radius, volume and contact-pressure profile) and fed by the paper's own inputs (Appendix
A's F0 with d0 = 2 mm on Table 1's rigid cone, eq (6)'s strip, the paper route). Both use what the
paper used for its lifetimes: air at 293.15 K and 1e5 Pa, the relaxation modulus E_eff(t) (in water
E = 4 MPa, the paper's dashed lines; the water-filled cavity is implemented without relaxation)
and the calibrated surfaces (Persson theory, EMT). The numbers the paper states are marked on
each (`validation.scenes.paper_marks`), everything drawn is in a CSV beside the PNG and SVG, and
each figure carries one sentence on what agrees with the paper and what does not, computed from
what it drew.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from validation.bridge.products import Products
from validation.bridge.study import Contact, CupDesign, Loads, Study, Surface
from validation.scenes import paper_plots

if TYPE_CHECKING:
    from validation.bridge.lifetimes import Lifetimes

__all__ = ["PAPER_FIGURES", "PaperFigure", "PaperResult", "run_paper", "paper_study", "paper_inputs"]


@dataclass(frozen=True)
class PaperFigure:
    """One figure of the set: its file stem, the paper's figure it redraws, what it shows."""

    name: str
    paper: str
    shows: str
    draw: Callable


#: the set, in the paper's order (name -> figure)
PAPER_FIGURES = {f.name: f for f in (
    PaperFigure("F0_vs_u_cups", "Fig. 1h.2F0.old.new.cup (Sec. 5.5)", "F0(u) of cups A and B", paper_plots.F0_cups),
    PaperFigure("lifetime_vs_force_cups", "Figs. 1force.2time and 1LoadingForce.2lifetime (Sec. 5.4, 5.5)",
                "lifetime against F1 for cups A and B", paper_plots.lifetime_vs_force),
    PaperFigure("r_pb_vs_time", "Fig. 1time.2r.3pa (Sec. 5.4)", "r(t) and p_b(t) at F1 = 5 ... 80 N",
                paper_plots.r_pb_vs_time),
    PaperFigure("p_Ndot_vs_time", "Fig. 1time.2p.dotN (Sec. 5.4)", "p(t) and Ndot(t) at F1 = 5 ... 80 N",
                paper_plots.p_Ndot_vs_time),
    PaperFigure("lifetime_vs_kappa", "Fig. 1stiffnessFactor.2lifetime (Sec. 5.4)",
                "lifetime against the stiffness factor kappa at F1 = 0.1, 10, 60 N", paper_plots.lifetime_vs_kappa),
    PaperFigure("lifetime_vs_rms", "Fig. 1rms.2logFailureTime (Sec. 5.4)",
                "lifetime at 10 N against the surface's rms roughness", paper_plots.lifetime_vs_rms),
    PaperFigure("lifetime_vs_r_start", "Fig. 1rStart.2logFailureTime.Table (Sec. 5.4)",
                "lifetime at 10 N on the table against r_start, dry and in water", paper_plots.lifetime_vs_r_start),
    PaperFigure("uc_vs_pressure", "Fig. 1pressureMPa.2loguc (Sec. 5.1)", "u_c against p/E of the paper's surfaces",
                paper_plots.uc_vs_pressure),
)}


@dataclass(frozen=True)
class PaperResult:
    """A drawn figure: its files (PNG, SVG, CSV) and the sentence on what agrees with the paper."""

    figure: PaperFigure
    files: tuple[Path, ...]
    sentence: str


def paper_study(fidelity: str, cup: str = "A", surface: str = "pmma-1.89", forces_N=(10.0,), kappa: float = 1.0,
                r_start_mm: float | None = None, fluid: str = "air") -> Study:
    """The FEM-fed study of one case: cup `cup`, frictionless FEM at `fidelity`, profile route,
    relaxation E_eff(t) in air (none in water)."""
    return Study(design=CupDesign(preset=cup), contact=Contact(), fidelity=fidelity, stiffness="fem",
                 surface=Surface(preset=surface), route="profile",
                 loads=Loads(forces_N=tuple(float(f) for f in forces_N), kappa=kappa, r_start_mm=r_start_mm,
                             relaxation="none" if fluid == "water" else "default", fluid=fluid))


def paper_inputs(study: Study) -> Study:
    """The same case fed by the paper's inputs: Appendix A's F0 (d0 = 2 mm), Table 1's cone, the paper route."""
    return replace(study, stiffness="appendix-a", route="paper", contact=Contact(), cup_laws="cone")


class PaperContext:
    """The products of the set's studies, each study computed once; FEM studies of one design,
    material, law and mesh share one FEM curve, studies of one surface one u_c table."""

    def __init__(self, fidelity: str, cache_dir: str | Path | None = None,
                 progress: Callable[[str], None] | None = None):
        self.fidelity, self._cache_dir, self._progress = fidelity, cache_dir, progress
        self._roots: dict[tuple, Products] = {}
        self._products: dict[Study, Products] = {}

    def study(self, **kw) -> Study:
        """The FEM-fed study of `paper_study`'s keywords at the set's mesh level."""
        return paper_study(self.fidelity, **kw)

    def pair(self, **kw) -> tuple[Study, Study]:
        """(the FEM-fed study, the same case on the paper's inputs) of `paper_study`'s keywords."""
        study = self.study(**kw)
        return study, paper_inputs(study)

    def products(self, study: Study) -> Products:
        """The study's products (each study once; its FEM curve and u_c table shared, above)."""
        if study not in self._products:
            key = (study.design, study.material, study.contact, study.fidelity, study.stiffness, study.surface)
            if key not in self._roots:
                self._roots[key] = Products(replace(study, loads=Loads()), cache_dir=self._cache_dir,
                                            progress=self._progress)
            inherit = ("curve", "uc_table") if study.stiffness == "fem" else ("uc_table",)
            self._products[study] = self._roots[key].derived(study, inherit=inherit)
        return self._products[study]

    def lifetimes(self, study: Study) -> Lifetimes:
        """The study's lifetimes on its route, one per pull force, and the largest force held."""
        return self.products(study).lifetimes()

    def record(self, study: Study) -> dict[str, str]:
        """A row's leading columns: design, contact, mesh, route, surface, and the feed and fluid."""
        loads = study.loads
        return {**study.record(), "stiffness": study.stiffness, "fluid": loads.fluid,
                "relaxation": "E_eff(t)" if loads.relaxation == "default" else f"E = {study.material.E_MPa:g} MPa"}


def run_paper(out: str | Path | None = None, fidelity: str = "coarse", cache_dir: str | Path | None = None,
              only: tuple[str, ...] | None = None, progress: Callable[[str], None] | None = None,
              dpi: float | None = None) -> list[PaperResult]:
    """Draw the set (or the figures named in `only`); with `out`, write each figure's PNG, SVG and
    CSV and ``manifest.json`` into `out` atomically. ValueError for an unknown figure name."""
    names = tuple(PAPER_FIGURES) if not only else tuple(only)
    unknown = [n for n in names if n not in PAPER_FIGURES]
    if unknown:
        raise ValueError(f"--only: unknown figure {unknown[0]!r}; choose from {', '.join(PAPER_FIGURES)}")
    if fidelity not in ("coarse", "medium", "fine"):
        raise ValueError(f"--fidelity: expected one of coarse, medium, fine, got {fidelity!r}")
    ctx = PaperContext(fidelity, cache_dir, progress)
    if out is None:
        return [_one(PAPER_FIGURES[n], ctx, None, dpi) for n in names]
    from validation.output import atomic_directory, software_versions

    t0 = time.perf_counter()
    with atomic_directory(out) as tmp:
        results = []
        for k, n in enumerate(names):
            if progress is not None:
                progress(f"figure {k + 1} of {len(names)}: {n}")
            results.append(_one(PAPER_FIGURES[n], ctx, Path(tmp), dpi))
        manifest = {"files": [{"name": r.figure.name, "path": p.name, "kind": p.suffix[1:]}
                              for r in results for p in r.files],
                    "figures": [{"name": r.figure.name, "paper": r.figure.paper, "sentence": r.sentence}
                                for r in results],
                    "fidelity": fidelity, "paper_numbers": "validation/data/paper_numbers.toml",
                    "versions": software_versions(), "timings_s": {"total": time.perf_counter() - t0}}
        (Path(tmp) / "manifest.json").write_text(json.dumps(manifest, indent=1, default=str) + "\n")
    return [replace(r, files=tuple(Path(out) / p.name for p in r.files)) for r in results]


def _one(figure: PaperFigure, ctx: PaperContext, tmp: Path | None, dpi: float | None) -> PaperResult:
    from validation.output import write_table
    from validation.scenes.paper_marks import Drawn
    from validation.style import cupcheck_style, readable_log_axes, save_figure

    drawn = Drawn()
    with cupcheck_style():
        fig, sentence = figure.draw(ctx, drawn)
        if tmp is None:
            import matplotlib.pyplot as plt
            plt.close(fig)
            return PaperResult(figure, (), sentence)
        svg, png = tmp / f"{figure.name}.svg", tmp / f"{figure.name}.png"
        readable_log_axes(fig)
        fig.savefig(svg)
        save_figure(fig, png, **({} if dpi is None else {"dpi": dpi}))
    csv = write_table(tmp / f"{figure.name}.csv", drawn.columns(), stage=f"paper figure {figure.name}")
    return PaperResult(figure, (png, svg, csv), sentence)
