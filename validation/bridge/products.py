"""The products of a `validation.bridge.study.Study`, each computed on first use and cached by content.

`Products` computes a product the first time something asks for it and keeps it: a study whose
outputs need only the u_c table never builds a curve, and a lifetime fed by Appendix A never
imports `fem`. The expensive products (u_c table, FEM path, curve, frames, lifetimes) go through
`validation.bridge.cache`: the key is the function's code, its arguments with every input file (design
file, u_c table) by the sha256 of its bytes instead of its path, and a hash of the sources that
compute the product. The fem route's lifetimes need no curve: they come from the FEM cup of the
study's design, material, contact law and mesh level (`fem_route_options`). `COMPUTED` counts the products actually computed in this process (a second
run of the same study computes none).
"""

from __future__ import annotations

import math
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

from validation.bridge.cache import Cache, file_digest, source_hash
from validation.bridge.study import Contact, Study

__all__ = ["Products", "COMPUTED", "Refused", "fem_route_options"]

#: products computed (not taken from the cache) in this process, by name
COMPUTED: Counter = Counter()


def _design_key(study: Study) -> dict:
    d = study.design
    return {"preset": d.preset, "file": file_digest(d.file),
            "geometry": None if d.geometry is None else d.geometry.describe()}


def _study_key(study: Study) -> dict:
    """Everything a study's lifetimes depend on, input files by content."""
    data = asdict(replace(study, outputs=(), sweep=None, design=replace(study.design, geometry=None)))
    data["design"] = {**data["design"], **_design_key(study)}
    data["surface"] = {**data["surface"], "uc_table": file_digest(study.surface.uc_table)}
    data["suction_table"] = file_digest(study.suction_table)
    data["stiffness_file"] = file_digest(study.stiffness_file)
    return data


# ------------------------------------------------------------------ the cached computations
def _uc_table(surface_key: dict, code: str, surface=None):
    """u_c(p/E) of the study's surface (`surface`, not part of the key: `surface_key` has the
    table file's content hash)."""
    COMPUTED["uc_table"] += 1
    from reduced.critical_gap import UcTable
    if surface.uc_table is not None:
        return UcTable.from_csv(surface.uc_table)
    from validation.bridge.pipeline import surface_uc_table
    return surface_uc_table(surface.preset)


def _fem_path(design_key: dict, material: dict, contact: dict, fidelity: str, u_max_m: float, code: str,
              design=None, progress=None):
    """The FEM path: the design pressed onto the plane to u_max_m, as (a `fem.cup.CupResponse`, every
    converged step; None), or, for a path that failed after some converged steps, (its converged
    part, its `validation.bridge.pipeline.PathStop`). Keyed only by what it depends on, so a curve,
    a render, a footprint and a squeeze ending at the same u share one run."""
    COMPUTED["fem_path"] += 1
    from fem.solver import ConvergenceError
    from validation.bridge.pipeline import converged_part, fem_path, neo_hookean
    try:
        return fem_path(design.cup_geometry(), neo_hookean(material["E_MPa"] * 1e6, material["nu"]),
                        Contact(**contact).contact_law(), fidelity, u_max_m, progress), None
    except ConvergenceError as exc:
        kept = converged_part(exc)
        if kept is None:                   # nothing beyond u = 0 converged
            raise
        return kept


def _fem_curve(design_key: dict, material: dict, contact: dict, fidelity: str, u_max_m: float, code: str,
               contact_source: str, design=None, path=None):
    """The stiffness curve (hand-off) of the FEM path to u_max_m (`path()`: the response and its
    stop, not part of the key); its provenance says who chose the contact law and, for the
    converged part of a failed path, where and why it stopped (flagged partial)."""
    COMPUTED["fem_curve"] += 1
    from validation.bridge.pipeline import fem_curve
    response, stop = path()
    return fem_curve(response, design.cup_geometry().describe(), fidelity, contact_source, stop=stop)


def _fem_frames(design_key: dict, material: dict, contact: dict, fidelity: str, u_max_m: float, n_frames: int,
                code: str, path=None) -> list:
    """The deformed states (`validation.render.frames.CupFrame`) at n_frames plate displacements
    evenly spaced up to u_max_m (1 frame: u_max_m itself; more: from 0, each the converged step
    nearest its target), drawn from the FEM path to u_max_m (`path()`, not part of the key)."""
    COMPUTED["fem_frames"] += 1
    import numpy as np

    from validation.render.frames import frame_from_response

    response = path()[0]
    targets = [u_max_m] if n_frames == 1 else np.linspace(0.0, u_max_m, n_frames)
    steps = [int(np.argmin(np.abs(response.u_m - t))) for t in targets]
    return [frame_from_response(response, k) for k in steps]


def _lifetimes(study_key: dict, stiffness, uc, cup, code: str, study=None, progress=None):
    """The study's lifetimes on its route, as (`validation.bridge.lifetimes.Lifetimes`, the
    `Refused` forces): on a partial curve (the converged part of a failed FEM path) a force whose
    lifetime needs a state beyond the curve is refused, the others computed."""
    COMPUTED["lifetimes"] += 1
    from validation.bridge.lifetimes import Lifetimes, lifetimes, route_options
    from validation.bridge.pipeline import partial_note
    forces = study.loads.forces_N

    def each(fraction: float, message: str) -> None:
        if progress is not None:
            progress(f"lifetime {round(fraction * len(forces))} of {len(forces)} done ({message})")
    options = fem_route_options(study) if study.route == "fem" else route_options(study.route, study.cup_laws)
    model = _model(study, stiffness, uc, cup)
    run = lambda fs, report=None: lifetimes(model, fs, study.route, progress=report,         # noqa: E731
                                           refine=1 if study.route in ("coupled", "fem") else study.refine, **options)
    try:
        return run(forces, each), ()
    except ValueError:
        if partial_note(getattr(stiffness, "provenance", {})) is None:
            raise
    done, refused = [], []                 # the reduced model never extrapolates the curve: force by force
    for i, force in enumerate(forces):
        try:
            done.append(run([force]))
        except ValueError as exc:
            refused.append(Refused(float(force), " ".join(str(exc).split())))
        each((i + 1) / len(forces), f"F1 = {force:g} N")
    largest = done[0].largest_force_N if done else math.nan
    return Lifetimes(study.route, tuple(r for d in done for r in d), largest), tuple(refused)


@dataclass(frozen=True)
class Refused:
    """A pull force [N] whose lifetime was not computed: on a partial stiffness curve it needs a
    state beyond the curve's range (`message`: the reduced model's words)."""

    force_N: float
    message: str


def fem_route_options(study: Study) -> dict[str, Any]:
    """The fem route's options for the study (`validation.bridge.fem_route.FemRoute`): the FEM cup
    of its design, material, contact law and mesh level, the loads' press (None: to the cup's
    r_start) and plate step."""
    from validation.bridge.fem_route import FemCup, Press

    s = study
    design = s.design
    geometry = design.cup_geometry() if (design.file or design.geometry is not None) else design.preset
    press = s.loads.press()
    return {"cup": FemCup(geometry, s.fidelity, E_Pa=s.material.E_MPa * 1e6, nu=s.material.nu,
                          contact=s.contact.contact_law()),
            "press": None if press is None else Press(*press), "du_m": 1e-3 * s.loads.du_mm}


def _model(study: Study, stiffness, uc, cup):
    """The `reduced.LeakageModel` of the study: its cup, its stiffness curve (or, on the coupled
    route, its suction table), u_c, air at 293.15 K and 1e5 Pa, kappa, relaxation and fluid."""
    from reduced.gas import Gas
    from reduced.lifetime import LeakageModel
    from reduced.viscoelastic import default_relaxation

    loads = study.loads
    feed = {"suction": stiffness} if study.route == "coupled" else {"stiffness": stiffness}
    if study.route == "fem":               # the FEM states are the cup's mechanics: no curve
        feed = {}
    return LeakageModel(cup=cup, u_c=uc, gas=Gas(T_K=293.15), p_a_Pa=1e5, E_Pa=study.material.E_MPa * 1e6,
                        kappa=loads.kappa, relaxation=default_relaxation() if loads.relaxation == "default" else None,
                        fluid=loads.fluid, **feed)


# ------------------------------------------------------------------ the lazy products
class Products:
    """The products of one study, each computed on first use (through the disk cache, if any).

    progress(message): a line per product, FEM step and force; fem_progress(fraction, message):
    the FEM's and suction table's own progress instead (a terminal's status line); suction_cache_dir:
    where the coupled route's suction tables are kept (`validation.bridge.coupled.build`; None: not kept);
    keep_partial: a stiffness curve whose FEM path fails after some converged steps is their
    converged part, flagged partial (`path_stop` says where and why; else the failure is raised)."""

    def __init__(self, study: Study, cache_dir: str | Path | None = None,
                 progress: Callable[[str], None] | None = None, suction_cache_dir: str | Path | None = None,
                 fem_progress: Callable[[float, str], None] | None = None, keep_partial: bool = False):
        self.study, self.timings, self._done, self._memos = study, {}, {}, {}
        self.keep_partial = keep_partial
        self._progress = progress or (lambda message: None)
        self._fem_report = fem_progress
        self._cache = Cache(cache_dir)
        self._suction_cache_dir = suction_cache_dir
        self._parent: Products | None = None
        self._inherit: tuple[str, ...] = ()

    def _cached(self, func, ignore: list[str] | None = None):
        return self._cache.cached(func, ignore=ignore)

    def _fem_progress(self, fraction: float, message: str) -> None:
        if self._fem_report is not None:
            return self._fem_report(fraction, message)
        self._progress(f"FEM {message.split(': ', 1)[-1].split(',')[0]}")     # FEM u = .. mm of .. mm

    def _get(self, name: str, compute):
        if name in self._inherit:
            return getattr(self._parent, name)()
        if name not in self._done:
            self._progress(f"{name} ...")
            t0 = time.perf_counter()
            self._done[name] = compute()
            self.timings[name] = time.perf_counter() - t0
        return self._done[name]

    def _memo(self, name: str, compute):
        """A cheap derived value (the cup), kept but neither timed nor reported as a product."""
        if name in self._inherit:
            return getattr(self._parent, name)()
        if name not in self._memos:
            self._memos[name] = compute()
        return self._memos[name]

    def _fem_args(self, u_max_m: float) -> tuple:
        s = self.study
        contact = {"law": s.contact.law, "friction": s.contact.friction}      # who chose it changes no state
        return (_design_key(s), asdict(s.material), contact, s.fidelity, u_max_m)

    def uc_table(self):
        surface = self.study.surface
        return self._get("uc_table", lambda: self._cached(_uc_table, ignore=["surface"])(
            {**asdict(surface), "uc_table": file_digest(surface.uc_table)}, source_hash("reduced"), surface=surface))

    def curve(self):
        """The stiffness curve: the FEM's to the study's u_max (default 0.9 h1; the converged part
        of a failed path with `keep_partial`), or the study's curve file, or Appendix A's (d0 = 2 mm)
        of the study's cup."""
        if self.study.stiffness == "appendix-a":
            return self._get("curve", self._appendix_a_curve)
        if self.study.stiffness_file is not None:
            from reduced.stiffness_curve import StiffnessCurve
            return self._get("curve", lambda: StiffnessCurve.from_csv(self.study.stiffness_file))
        curve = self._get("curve", lambda: self._cached(_fem_curve, ignore=["design", "path"])(
            *self._fem_args(self._u_max_m(None)), source_hash("fem", "validation"), self.study.contact.source,
            design=self.study.design,
            path=lambda: self._path(None)))
        if curve.provenance.get("partial") is True and not self.keep_partial:
            self.fem_path(None)            # raises the path's failure
        return curve

    def _appendix_a_curve(self):
        from reduced.appendix_a import appendix_a_curve
        return appendix_a_curve(self.cup(), E_Pa=self.study.material.E_MPa * 1e6, d0_m=2e-3)

    def cup_choice(self):
        """The cup the FEM curve was computed for (`validation.bridge.design.CupChoice`: the curve's design
        with the study's r_start, l0, l1); None for Appendix A."""
        if self.study.stiffness == "appendix-a":
            return None

        def compute():
            from validation.bridge.design import resolve_cup
            from validation.bridge.lifetimes import route_laws
            s = self.study
            if s.route == "fem" and s.design.geometry is None:     # the FEM route needs no curve
                return resolve_cup(None, cup=s.design.preset, geometry_file=s.design.file,
                                   r_start_mm=s.loads.r_start_mm, laws="curve")
            return resolve_cup(self.curve(), r_start_mm=s.loads.r_start_mm, l0_mm=s.design.l0_mm,
                               l1_mm=s.design.l1_mm, curve_label="the FEM curve",
                               laws=route_laws(s.route, s.cup_laws))
        return self._memo("cup_choice", compute)

    def cup(self):
        """The reduced model's `CupParameters`: the FEM design's (`cup_choice`), or Table 1's preset."""
        def compute():
            choice = self.cup_choice()
            if choice is not None:
                return choice.cup
            from reduced.cup import CUPS
            cup, r_start = CUPS[self.study.design.preset], self.study.loads.r_start_mm
            return cup if r_start is None else replace(cup, r_start_m=1e-3 * r_start)
        return self._memo("cup", compute)

    def _u_max_m(self, u_mm: float | None) -> float:
        """The path's end [m]: u_mm, or for the stiffness curve the study's u_max (default 0.9 h1);
        checked against h1."""
        h1_m = self.study.design.cup_geometry().h1_m
        if u_mm is None:
            if self.study.u_max_mm is None:
                return 0.9 * h1_m
            from validation.guards import check_plate_travel      # each spelling checked it against h1
            return 1e-3 * check_plate_travel(self.study.u_max_mm, 1e3 * h1_m, "u_max_mm")
        if not 0 < u_mm * 1e-3 <= h1_m:
            raise ValueError(f"outputs: u_mm must be in (0, h1] = (0, {1e3 * h1_m:.4g}] mm, got {u_mm:g}")
        return u_mm * 1e-3

    def _path(self, u_mm: float | None) -> tuple:
        """(the FEM path to u_mm (None: the curve's end), its `PathStop` or None), computed once per
        end point and study (`_fem_path`)."""
        u_max_m = self._u_max_m(u_mm)
        return self._get(f"fem_path_{1e3 * u_max_m:.6g}mm", lambda: self._cached(_fem_path, ignore=["design", "progress"])(
            *self._fem_args(u_max_m), source_hash("fem", "validation/bridge/pipeline.py"), design=self.study.design,
            progress=self._fem_progress))

    def fem_path(self, u_mm: float | None):
        """The FEM path to u_mm (None: the curve's end, its converged part with `keep_partial`); a
        path that stopped short of it raises its `fem.solver.ConvergenceError`."""
        response, stop = self._path(u_mm)
        if stop is not None and not (u_mm is None and self.keep_partial):
            raise stop.error
        return response

    def path_stop(self):
        """Where and why the stiffness curve's FEM path stopped short of its u_max (a
        `validation.bridge.pipeline.PathStop`; None: it reached it)."""
        return self._path(None)[1]

    def fem_frames(self, u_mm: float, n_frames: int = 1) -> list:
        """The deformed states at n_frames plate displacements up to u_mm (`_fem_frames`), drawn from
        the FEM path to u_mm: a render, a footprint and a squeeze ending at one u share one FEM run."""
        u_max_m = self._u_max_m(u_mm)
        name = f"fem_state_{u_mm:g}mm" + (f"_{n_frames}frames" if n_frames > 1 else "")
        return self._get(name, lambda: self._cached(_fem_frames, ignore=["path"])(
            *self._fem_args(u_max_m), n_frames, source_hash("fem", "validation"),
            path=lambda: (self.fem_path(u_mm), None)))

    def suction_table(self):
        """The coupled route's FEM suction table: the study's file, or built for the design at its
        mesh level and contact law (kept in suction_cache_dir), only where the study's lifetimes
        read it when `validation.bridge.coupled.adaptive.goal_for` allows."""
        def compute():
            from reduced.suction_table import SuctionTable
            s = self.study
            if s.suction_table is not None:
                return SuctionTable.from_json(s.suction_table)
            from validation.bridge.coupled.adaptive import goal_for
            from validation.bridge.coupled.build import suction_table_for
            return suction_table_for(s.design.cup_geometry(), fidelity=s.fidelity, contact=s.contact.contact_law(),
                                     E_Pa=s.material.E_MPa * 1e6, nu=s.material.nu,
                                     cache_dir=self._suction_cache_dir,
                                     goal=goal_for(_model(s, None, self.uc_table(), self.cup()), s.loads.forces_N,
                                                   s.contact.contact_law()),
                                     progress=self._fem_report or (lambda f, m: self._progress(f"suction {m}")))
        return self._get("suction_table", compute)

    def lifetimes(self):
        """The lifetimes (`validation.bridge.lifetimes.Lifetimes`) of the study's forces on its route
        (on a partial curve: of the forces not `refused`)."""
        s = self.study
        def compute():
            feed = {"coupled": self.suction_table, "fem": lambda: None}.get(s.route, self.curve)()
            code = source_hash("fem", "reduced", "validation") if s.route == "fem" else source_hash("reduced", "validation")
            results, self._memos["refused"] = self._cached(_lifetimes, ignore=["study", "progress"])(
                _study_key(s), feed, self.uc_table(), self.cup(), code, study=s, progress=self._progress)
            return results
        return self._get("lifetimes", compute)

    def refused(self) -> tuple[Refused, ...]:
        """The forces whose lifetimes need a state beyond a partial stiffness curve (none on a complete one)."""
        self.lifetimes()
        return self._parent.refused() if "lifetimes" in self._inherit else self._memos["refused"]

    def partial(self) -> dict[str, Any] | None:
        """A partial stiffness curve's record (where and why its FEM path stopped, the u_max that
        runs, the forces refused), or None: no curve computed, or a complete one. Computes nothing."""
        owner = self
        while "curve" in owner._inherit:
            owner = owner._parent
        curve = owner._done.get("curve")
        prov = getattr(curve, "provenance", {})
        if prov.get("partial") is not True:
            return None
        record = {k: prov.get(k) for k in ("failed_at_u_mm", "u_max_mm_that_runs", "failure_reason")}
        refused = [{"force_N": r.force_N, "message": r.message} for r in self._memos.get("refused", ())]
        return {"partial": True, **record, "refused": refused}

    def derived(self, study: Study, inherit: tuple[str, ...] = ()) -> Products:
        """The products of another study sharing this one's cache, and taking the products named
        in `inherit` (e.g. "uc_table", "cup", "curve") from this one."""
        child = Products(study, progress=self._progress, suction_cache_dir=self._suction_cache_dir,
                         fem_progress=self._fem_report, keep_partial=self.keep_partial)
        child._cache, child._parent, child._inherit = self._cache, self, inherit
        return child

    def appendix_a(self, refine: int | None = None) -> Products | None:
        """For a FEM study: the same cup fed by Appendix A's F0 (d0 = 2 mm) through the paper's
        route and frictionless contact (the comparison `cupcheck example` draws); else None."""
        s = self.study
        if s.stiffness != "fem":
            return None
        study = replace(s, stiffness="appendix-a", route="paper", cup_laws="cone", contact=Contact(), sweep=None,
                        refine=s.refine if refine is None else refine)
        return self._get("appendix_a", lambda: self.derived(study, inherit=("uc_table", "cup")))

    def variants(self) -> list[tuple[Any, Products]]:
        """For a swept study: (value, the products of the study with that value), sharing the cache."""
        return self._get("variants", lambda: [(v, self.derived(study)) for v, study in self.study.variants()])

    def computed(self) -> dict[str, Any]:
        return dict(self._done)
