"""The products a scene can ask for, computed lazily and cached on disk.

    surface -------------------------------------> u_c table -------+
    cup, material, contact, fidelity, u_max ---> FEM path --> curve --+--> lifetimes (and trajectories)
                                                          +-> frames (render, footprint, squeeze)
    cup (Appendix A) ----------------------------> curve -------------+

`Products` computes each product the first time an output asks for it and keeps it: a scene whose
outputs need only the u_c table never builds a curve, and a lifetime fed by Appendix A never
imports `fem`. The expensive products (u_c table, FEM path, frames, lifetimes) go through
`validation.cache` (joblib.Memory): the key is the function's code, its arguments with every
input file (design file, u_c table) by the sha256 of its bytes instead of its path, and a hash
of the sources that compute the product. `COMPUTED` counts the products actually computed in this
process (a second run of the same scene computes none).
"""

from __future__ import annotations

import time
from collections import Counter
from pathlib import Path
from typing import Any

from validation.cache import Cache, file_digest, source_hash
from validation.scenes.schema import Scene

__all__ = ["Products", "COMPUTED"]

#: products computed (not taken from the cache) in this process, by name
COMPUTED: Counter = Counter()


def _keyed(table: dict, key: str) -> dict:
    """A scene table with its input file `key` (a path) replaced by the sha256 of the file's bytes."""
    return {**table, key: file_digest(table[key])}


def _tables_key(tables: dict) -> dict:
    """The scene's tables as a cache key: every input file by its content, not its path."""
    return {**tables, "cup": _keyed(tables["cup"], "geometry"), "surface": _keyed(tables["surface"], "uc_table")}


# ------------------------------------------------------------------ the cached computations
def _uc_table(surface_key: dict, code: str, surface: dict | None = None):
    """u_c(p/E) of the scene's surface (`surface`, not part of the key: `surface_key` has the
    table file's content hash)."""
    COMPUTED["uc_table"] += 1
    from reduced.critical_gap import UcTable
    if surface["uc_table"] is not None:
        return UcTable.from_csv(surface["uc_table"])
    from validation.pipeline import surface_uc_table
    return surface_uc_table(surface["preset"])


def _fem_path(cup_key: dict, material: dict, contact: dict, fidelity: str, u_max_m: float, code: str,
              cup: dict | None = None, progress=None):
    """The FEM path: the scene's cup pressed onto the plane to u_max_m (a `fem.cup.CupResponse`,
    every converged step). Keyed only by what it depends on (the cup with its design file by
    content, material, contact, fidelity, u_max), so a curve, a render, a footprint and a
    squeeze ending at the same u share one run."""
    COMPUTED["fem_path"] += 1
    from validation.pipeline import fem_path, neo_hookean
    return fem_path(_geometry(cup), neo_hookean(material["E_MPa"] * 1e6, material["nu"]), _contact_law(contact),
                    fidelity, u_max_m, progress)


def _contact_law(contact: dict):
    """The scene's [contact] table (checked by the schema) as a `fem.interface.ContactLaw`."""
    from fem.interface import ContactLaw
    return ContactLaw(contact["law"], float(contact["friction"] or 0.0) if contact["law"] == "coulomb" else 0.0)


def _fem_curve(cup_key: dict, material: dict, contact: dict, fidelity: str, u_max_m: float, code: str,
               cup: dict | None = None, path=None, contact_source: str | None = None):
    """The stiffness curve (hand-off) of the FEM path to u_max_m (`path()`, not part of the key);
    its provenance says who chose the contact law (`Scene.contact_source`)."""
    COMPUTED["fem_curve"] += 1
    from validation.pipeline import fem_curve
    return fem_curve(path(), _geometry(cup).describe(), fidelity, contact_source)


def _fem_frames(cup_key: dict, material: dict, contact: dict, fidelity: str, u_max_m: float, n_frames: int,
                code: str, path=None) -> list:
    """The deformed states (`validation.render.frames.CupFrame`, every field) at n_frames plate
    displacements evenly spaced up to u_max_m (1 frame: u_max_m itself; more: from 0, each the
    converged step nearest its target), drawn from the FEM path to u_max_m (`path()`, not part of
    the key: the path is its own product)."""
    COMPUTED["fem_frames"] += 1
    import numpy as np

    from validation.render.frames import frame_from_response

    response = path()
    targets = [u_max_m] if n_frames == 1 else np.linspace(0.0, u_max_m, n_frames)
    steps = [int(np.argmin(np.abs(response.u_m - t))) for t in targets]
    return [frame_from_response(response, k) for k in steps]


def _lifetimes(tables_key: dict, curve, uc, code: str, tables: dict | None = None, progress=None):
    COMPUTED["lifetimes"] += 1
    from validation.lifetimes import lifetimes, route_options
    model = _model(tables, curve, uc)
    forces = tables["loads"]["F1_N"]
    route = tables["stiffness"]["route"]

    def each(fraction: float, message: str) -> None:
        if progress is not None:
            progress(f"lifetime {round(fraction * len(forces))} of {len(forces)} done ({message})")
    return lifetimes(model, forces, route, refine=2, progress=each, **route_options(route))


def _geometry(cup: dict):
    from fem.geometry import cup_geometry, load_geometry
    return load_geometry(cup["geometry"], cup=cup["preset"]) if cup["geometry"] else cup_geometry(cup["preset"])


def _model(tables: dict, curve, uc):
    """The `LeakageModel` of the scene (the cup from the curve's design, or Table 1's preset)."""
    from dataclasses import replace

    from reduced.cup import CUPS
    from reduced.gas import Gas
    from reduced.lifetime import LeakageModel
    from reduced.viscoelastic import default_relaxation
    from validation.lifetimes import route_laws

    loads = tables["loads"]
    if curve.design is None:               # Appendix A of a Table 1 preset: no fem imported
        cup = CUPS[tables["cup"]["preset"]]
        if loads["r_start_mm"] is not None:
            cup = replace(cup, r_start_m=1e-3 * loads["r_start_mm"])
    else:
        from validation.design import resolve_cup
        cup = resolve_cup(curve, r_start_mm=loads["r_start_mm"], laws=route_laws(tables["stiffness"]["route"])).cup
    return LeakageModel(cup=cup, stiffness=curve, u_c=uc, gas=Gas(T_K=293.15), p_a_Pa=1e5,
                        E_Pa=tables["material"]["E_MPa"] * 1e6, kappa=loads["kappa"],
                        relaxation=default_relaxation() if tables["material"]["relaxation"] == "default" else None,
                        fluid=tables["fluid"]["kind"])


# ------------------------------------------------------------------ the lazy products
class Products:
    """The products of one scene, each computed on first use (through the disk cache, if any)."""

    def __init__(self, scene: Scene, cache_dir: str | Path | None = None, progress=None):
        self.scene, self.timings, self._done = scene, {}, {}
        self._progress = progress or (lambda message: None)
        self._cache = Cache(cache_dir)

    def _cached(self, func, ignore: list[str] | None = None):
        return self._cache.cached(func, ignore=ignore)

    def _cup_key(self) -> dict:
        return _keyed(self.scene["cup"], "geometry")

    def _fem_progress(self, fraction: float, message: str) -> None:
        self._progress(f"FEM {message.split(': ', 1)[-1].split(',')[0]}")     # FEM u = .. mm of .. mm

    def _get(self, name: str, compute):
        if name not in self._done:
            self._progress(f"{name} ...")
            t0 = time.perf_counter()
            self._done[name] = compute()
            self.timings[name] = time.perf_counter() - t0
        return self._done[name]

    def uc_table(self):
        surface = self.scene["surface"]
        return self._get("uc_table", lambda: self._cached(_uc_table, ignore=["surface"])(
            _keyed(surface, "uc_table"), source_hash("reduced"), surface=surface))

    def curve(self):
        if self.scene["stiffness"]["source"] == "appendix-a":
            return self._get("curve", self._appendix_a)
        s, u_max_m = self.scene, self._u_max_m(None)
        return self._get("curve", lambda: self._cached(_fem_curve, ignore=["cup", "path"])(
            self._cup_key(), s["material"], s["contact"], s["stiffness"]["fidelity"], u_max_m,
            source_hash("fem", "validation"), cup=s["cup"], path=lambda: self.fem_path(None),
            contact_source=s.contact_source))

    def _appendix_a(self):
        from reduced.appendix_a import appendix_a_curve
        from reduced.cup import CUPS
        return appendix_a_curve(CUPS[self.scene["cup"]["preset"]], E_Pa=self.scene["material"]["E_MPa"] * 1e6,
                                d0_m=2e-3)

    def _u_max_m(self, u_mm: float | None) -> float:
        """The path's end [m]: u_mm, or 0.9 h1 for the stiffness curve; checked against h1."""
        h1_m = _geometry(self.scene["cup"]).h1_m
        if u_mm is None:
            return 0.9 * h1_m
        if not 0 < u_mm * 1e-3 <= h1_m:
            raise ValueError(f"outputs: u_mm must be in (0, h1] = (0, {1e3 * h1_m:.4g}] mm, got {u_mm:g}")
        return u_mm * 1e-3

    def fem_path(self, u_mm: float | None):
        """The FEM path to u_mm (None: 0.9 h1), computed once per end point and scene (`_fem_path`)."""
        s, u_max_m = self.scene, self._u_max_m(u_mm)
        return self._get(f"fem_path_{1e3 * u_max_m:.6g}mm", lambda: self._cached(_fem_path, ignore=["cup", "progress"])(
            self._cup_key(), s["material"], s["contact"], s["stiffness"]["fidelity"], u_max_m,
            source_hash("fem", "validation/pipeline.py"), cup=s["cup"], progress=self._fem_progress))

    def fem_frames(self, u_mm: float, n_frames: int = 1) -> list:
        """The deformed states at n_frames plate displacements up to u_mm (`_fem_frames`), drawn from
        the FEM path to u_mm: a render, a footprint and a squeeze ending at one u share one FEM run."""
        s, u_max_m = self.scene, self._u_max_m(u_mm)
        name = f"fem_state_{u_mm:g}mm" + (f"_{n_frames}frames" if n_frames > 1 else "")
        return self._get(name, lambda: self._cached(_fem_frames, ignore=["path"])(
            self._cup_key(), s["material"], s["contact"], s["stiffness"]["fidelity"], u_max_m, n_frames,
            source_hash("fem", "validation"), path=lambda: self.fem_path(u_mm)))

    def lifetimes(self):
        return self._get("lifetimes", lambda: self._cached(_lifetimes, ignore=["tables", "progress"])(
            _tables_key(self.scene.tables), self.curve(), self.uc_table(), source_hash("reduced", "validation"),
            tables=self.scene.tables, progress=self._progress))

    def appendix_a(self) -> "Products | None":
        """For a FEM scene of a Table 1 preset: the same scene fed by Appendix A's F0 through the
        paper's route (the comparison `cupcheck example` draws), sharing the cache; else None."""
        s = self.scene
        if s["stiffness"]["source"] != "fem" or s["cup"]["geometry"] or s.sweep is not None:
            return None

        def compute():
            tables = {k: dict(v) for k, v in s.tables.items()}
            tables["stiffness"].update(source="appendix-a", route="paper")
            tables["contact"].update(law="frictionless", friction=None)
            return Products(Scene(tables=tables, outputs=s.outputs, source=s.source), progress=self._progress)._share(self)
        return self._get("appendix_a", compute)

    def variants(self) -> list[tuple[Any, "Products"]]:
        """For a swept scene: (value, the products of the scene with that value), sharing the cache."""
        def compute():
            return [(v, Products(self.scene.variant(v), cache_dir=None, progress=self._progress)._share(self))
                    for v in self.scene.sweep["values"]]
        return self._get("variants", compute)

    def _share(self, parent: "Products") -> "Products":
        self._cache = parent._cache
        return self

    def computed(self) -> dict[str, Any]:
        return dict(self._done)
