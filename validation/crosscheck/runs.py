"""FEM runs as plain requests, and a memo that runs each distinct request once.

A section of the validation report declares the cup compressions it needs as `FemRun` values
(frozen, hashable: the memo's key). `RunMemo.get` runs a request the first time it is asked for
and returns the stored `FemResult` (or re-raises the stored failure) afterwards, so sections share
runs and a subset of sections runs only what it needs. With `cache_dir`, results also persist on
disk (`validation.bridge.cache`), keyed by the request and a hash of the `fem` sources and the pipeline
(a code change invalidates them).

Geometry of a request: the preset cup (`fem.geometry.cup_geometry`) with, optionally, another cone
angle and a root thickness d_root at r0; the thickness line then keeps the preset's shape, scaled
by d_root / d_preset(r0) (cup A: 2.5 -> 0.3 mm at r = 5 -> 20 mm, so the rim stays 0.179 d_root).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["FemRun", "FemResult", "RunMemo"]

_MM = 1e-3


@dataclass(frozen=True)
class FemRun:
    """One FEM compression of a cup, from u = 0 to u_max = u_max_over_h1 * h1 (plain data).

    cup: preset 'A' or 'B'; alpha_deg, d_root_mm: overrides of the preset's cone angle and of its
    thickness at r0 (None: the preset's); contact: 'frictionless', 'sticking' or 'coulomb' (with
    Coulomb's coefficient `friction`; None for the other laws); fidelity: mesh
    level; element: 'quad' (Q2) or 'tri' (P2); E_Pa, nu, formulation: the neo-Hookean material;
    max_step: the largest load step as a fraction of u_max (the curve's sampling).
    """

    cup: str = "A"
    contact: str = "frictionless"
    fidelity: str = "coarse"
    element: str = "quad"
    alpha_deg: float | None = None
    d_root_mm: float | None = None
    E_Pa: float = 4e6
    nu: float = 0.49
    formulation: str = "displacement"
    u_max_over_h1: float = 0.9
    max_step: float = 0.05
    friction: float | None = None

    def __post_init__(self) -> None:
        if (self.contact == "coulomb") != (self.friction is not None):
            raise ValueError(f"FemRun: friction is Coulomb's mu, given with contact='coulomb' only "
                             f"(contact={self.contact!r}, friction={self.friction!r})")

    def label(self) -> str:
        law = self.contact if self.friction is None else f"coulomb mu {self.friction:.6g}"
        parts = [f"cup {self.cup}", law, self.fidelity]
        if self.element != "quad":
            parts.append(self.element)
        if self.alpha_deg is not None:
            parts.append(f"alpha {self.alpha_deg:g} deg")
        if self.d_root_mm is not None:
            parts.append(f"d0 {self.d_root_mm:g} mm")
        if self.E_Pa != 4e6:
            parts.append(f"E {self.E_Pa / 1e6:g} MPa")
        if self.nu != 0.49:
            parts.append(f"nu {self.nu:g}")
        if self.formulation != "displacement":
            parts.append(self.formulation)
        if self.u_max_over_h1 != 0.9:
            parts.append(f"u_max {self.u_max_over_h1:g} h1")
        if self.max_step != 0.05:
            parts.append(f"step <= {self.max_step:g} u_max")
        return ", ".join(parts)

    def geometry(self):
        """The `fem.geometry.CupGeometry` (ValueError if the wall is invalid, e.g. self-intersecting)."""
        from fem.geometry import PRESETS, LinearThickness, cup_geometry

        overrides = {}
        if self.alpha_deg is not None:
            overrides["alpha_deg"] = self.alpha_deg
        if self.d_root_mm is not None:
            p = PRESETS[self.cup.upper()]
            k = self.d_root_mm / p["d_inner_mm"]
            overrides["thickness"] = LinearThickness(5 * _MM, k * p["d_inner_mm"] * _MM,
                                                     20 * _MM, k * p["d_outer_mm"] * _MM)
        return cup_geometry(self.cup, **overrides)

    def thickness_at_ends_m(self) -> tuple[float, float]:
        """(d at r0, d at r1) of the request's thickness line [m] (no mesh, no validity check)."""
        from fem.geometry import PRESETS

        p = PRESETS[self.cup.upper()]
        k = 1.0 if self.d_root_mm is None else self.d_root_mm / p["d_inner_mm"]
        d0, d20 = k * p["d_inner_mm"] * _MM, k * p["d_outer_mm"] * _MM
        return d0, d0 + (d20 - d0) * (19 - 5) / (20 - 5)

    def geometry_alpha(self) -> float:
        """The cone angle [deg] (the override, else the preset's)."""
        from fem.geometry import PRESETS
        return self.alpha_deg if self.alpha_deg is not None else PRESETS[self.cup.upper()]["alpha_deg"]

    def material(self):
        from validation.bridge.pipeline import neo_hookean
        return neo_hookean(self.E_Pa, self.nu, self.formulation)


@dataclass(frozen=True, eq=False)
class FemResult:
    """What the report needs of a `fem.cup.CupResponse` (arrays over converged steps, SI)."""

    request: FemRun
    h1_m: float
    u_m: np.ndarray
    F0_N: np.ndarray
    F0_contact_N: np.ndarray
    r_c_m: np.ndarray
    l_m: np.ndarray
    V_m3: np.ndarray
    energy_J: np.ndarray
    penetration_m: np.ndarray
    wall_s: float
    steps: int
    newton_iterations: int
    dofs: int
    outline_r_m: np.ndarray = field(repr=False)   # deformed closed outline at the last step
    outline_z_m: np.ndarray = field(repr=False)
    outline_p_Pa: np.ndarray = field(repr=False)  # contact pressure on it (0 off contact)
    unstable: np.ndarray | None = field(default=None, repr=False)   # per step: tangent indefinite
    pressure: tuple = field(default=(), repr=False)   # per step: fem.contact.PressureProfile
    cone_excess: np.ndarray | None = field(default=None, repr=False)   # Coulomb (fem.cup)

    def F0_at(self, u_m) -> np.ndarray:
        """F0 at plate displacements u [N], monotone cubic (PCHIP) between the steps."""
        return self._pchip(self.F0_N)(u_m)

    def r_c_at(self, u_m) -> np.ndarray:
        return self._pchip(self.r_c_m)(u_m)

    def l_at(self, u_m) -> np.ndarray:
        return self._pchip(self.l_m)(u_m)

    def V_at(self, u_m) -> np.ndarray:
        return self._pchip(self.V_m3)(u_m)

    def _pchip(self, y):
        from scipy.interpolate import PchipInterpolator
        return PchipInterpolator(self.u_m, y, extrapolate=False)

    def stiffness_curve(self):
        """The hand-off `StiffnessCurve` (u, F0, r_c, l, V), built by `validation.bridge.handoff`."""
        from validation.bridge.handoff import stiffness_curve
        return stiffness_curve(self, {"source": "fem", **asdict(self.request)})


def compute(request: FemRun, progress: Callable[[float, str], None] | None = None) -> FemResult:
    """Run the request: mesh, compress, and keep the plain arrays (raises ValueError/RuntimeError)."""
    from fem.interface import ContactLaw
    from fem.mesh import cup_mesh
    from validation.bridge.pipeline import fem_path

    geometry = request.geometry()
    mesh = cup_mesh(geometry, request.fidelity, element=request.element)
    t0 = time.perf_counter()
    resp = fem_path(geometry, request.material(), ContactLaw(request.contact, request.friction or 0.0),
                    request.fidelity, request.u_max_over_h1 * geometry.h1_m, progress, mesh=mesh,
                    max_step=request.max_step)
    wall = time.perf_counter() - t0
    r, z, p = deformed_outline(resp)
    return FemResult(request=request, h1_m=resp.h1_m, u_m=resp.u_m, F0_N=resp.F0_N,
                     F0_contact_N=resp.F0_contact_N, r_c_m=resp.r_c_m, l_m=resp.l_m, V_m3=resp.V_m3,
                     energy_J=resp.energy_J, penetration_m=resp.penetration_m, wall_s=wall,
                     steps=int(resp.stats.steps), newton_iterations=int(resp.stats.newton_iterations),
                     dofs=int(resp.stats.dofs), outline_r_m=r, outline_z_m=z, outline_p_Pa=p,
                     unstable=resp.unstable, pressure=tuple(resp.pressure),
                     cone_excess=resp.cone_excess)


def deformed_outline(resp) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The closed outline cavity -> rim -> outer -> plate of the last step, deformed."""
    from fem.mesh import boundary_path

    mesh, u = resp.mesh, resp.displacements[-1]
    x = mesh.doflocs + np.stack([u[0::2], u[1::2]])
    pn = np.asarray(resp.nodal_pressure_Pa[-1]) if hasattr(resp, "nodal_pressure_Pa") else None
    loop = []
    for name in ("cavity", "rim", "outer", "top_plate"):
        try:
            path = boundary_path(mesh, name)
        except Exception:          # a tag the mesh does not have: skip that side
            continue
        if loop and path[-1] == loop[-1]:      # each side continues from the corner the last ended at
            path = path[::-1]
        loop.extend(path if not loop or path[0] != loop[-1] else path[1:])
    nodes = np.asarray(loop)
    p = pn[nodes] if pn is not None and pn.size == x.shape[1] else np.zeros(nodes.size)
    return x[0, nodes], x[1, nodes], p


def _outcome(request: FemRun, code: str, runner: Callable[[FemRun], FemResult] | None = None) -> FemResult | Exception:
    """The run's result, or the failure it raised (stored like a result: a failed request is not
    rerun); `code` (the sources' hash) and `request` are the cache key, `runner` is not."""
    try:
        return runner(request)
    except (ValueError, RuntimeError) as exc:
        return exc


class RunMemo:
    """Runs each distinct `FemRun` once per memo; optionally persists results in `cache_dir`
    (`validation.bridge.cache`, keyed by the request and the sources of fem and of this pipeline).

    `get(request)` returns the `FemResult` or raises the run's failure (ValueError for an invalid
    geometry or input, RuntimeError for a solver failure), the same one on every call.
    `computed` counts the runs actually computed (not memo or cache hits).
    """

    def __init__(self, cache_dir: str | Path | None = None,
                 runner: Callable[[FemRun], FemResult] = compute):
        from validation.bridge.cache import Cache, source_hash

        self._runner = runner
        self._store: dict[FemRun, FemResult | Exception] = {}
        self.cache_dir = None if cache_dir is None else Path(cache_dir)
        self.computed = 0
        self.cache_hits = 0
        self._cached = Cache(cache_dir).cached(_outcome, ignore=["runner"])
        self._version = source_hash("fem", "validation/bridge/pipeline.py") if cache_dir is not None else ""

    def get(self, request: FemRun) -> FemResult:
        if request not in self._store:
            self._store[request] = self._load_or_run(request)
        outcome = self._store[request]
        if isinstance(outcome, Exception):
            raise outcome
        return outcome

    @property
    def requests(self) -> tuple[FemRun, ...]:
        """Every distinct request asked for so far."""
        return tuple(self._store)

    def outcome(self, request: FemRun) -> FemResult | Exception:
        """The result, or the exception the run raised (for outcome tables)."""
        try:
            return self.get(request)
        except (ValueError, RuntimeError) as exc:
            return exc

    def _load_or_run(self, request: FemRun) -> FemResult | Exception:
        ran: list[FemRun] = []

        def runner(req: FemRun) -> FemResult:
            ran.append(req)
            return self._runner(req)

        outcome = self._cached(request, self._version, runner=runner)
        if ran:
            self.computed += 1
        else:
            self.cache_hits += 1
        return outcome
