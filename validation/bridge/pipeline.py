"""The FEM pipeline, written once: design -> mesh -> material -> contact law -> compress_cup ->
the hand-off curve with its provenance.

Every command, scene, sweep and report section that needs an FEM path or a stiffness curve calls
`fem_path` (the `fem.cup.CupResponse`) and `fem_curve` (the `StiffnessCurve` of a response), or
`fem_stiffness` (both). The rules that used to be spelled at each call site live here, once:

* the formulation by nu (`neo_hookean`): not given, nu above `LOCKING_NU` takes the mixed u-p
  formulation (the displacement elements lock there); the displacement formulation given with
  nu above it is refused;
* the default surface and its u_c table (`DEFAULT_SURFACE`, `surface_uc_table`: Persson theory,
  EMT, nu = 0.5);
* the contact law: a `fem.interface.ContactLaw` (or a `ContactChoice`, which also says who chose
  it) travels unchanged from the caller to `compress_cup`;
* a path that fails after some converged steps: `converged_part` keeps them as a response and a
  `PathStop` (where and why it stopped, and the u_max that runs), and `fem_curve` flags the curve
  partial in its provenance (``partial``, ``failed_at_u_mm``, ``failure_reason``,
  ``u_max_mm_that_runs``); `fem_stiffness(keep_partial=True)` does both.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:                          # importing this module imports no fem
    from fem.cup import CupResponse
    from fem.geometry import CupGeometry
    from fem.interface import ContactChoice, ContactLaw
    from fem.material import NeoHookean
    from fem.solver import ConvergenceError
    from reduced.critical_gap import UcTable
    from reduced.stiffness_curve import StiffnessCurve

__all__ = ["LOCKING_NU", "DEFAULT_SURFACE", "neo_hookean", "surface_uc_table",
           "mesh_record", "fem_path", "fem_curve", "fem_stiffness", "PathStop", "converged_part", "partial_note",
           "runnable_u_max_mm"]

#: above this Poisson's ratio the displacement (Q2) formulation locks (F0 stiffens)
LOCKING_NU = 0.495
#: the calibrated surface used where none is named: sandblasted PMMA, 1.89 um rms (the paper's Figs.)
DEFAULT_SURFACE = "pmma-1.89"
Progress = Callable[[float, str], None]


def neo_hookean(E_Pa: float, nu: float, formulation: str | None = None) -> NeoHookean:
    """The wall's compressible neo-Hookean material; `formulation` None: mixed above LOCKING_NU,
    else displacement. ValueError (field ``nu``) for the displacement formulation above LOCKING_NU."""
    from fem.material import NeoHookean

    if formulation is None:
        formulation = "mixed" if nu > LOCKING_NU else "displacement"
    elif formulation == "displacement" and nu > LOCKING_NU:
        raise ValueError(f"nu: with the displacement formulation Poisson's ratio must be <= "
                         f"{LOCKING_NU} (above, its elements lock and stiffen F0); use "
                         f"--formulation mixed for nu up to 0.4999, got {nu:g}")
    return NeoHookean(E_Pa=E_Pa, nu=nu, formulation=formulation)


@lru_cache(maxsize=8)
def surface_uc_table(name: str | None = None) -> UcTable:
    """u_c(p/E) of a calibrated surface preset (default `DEFAULT_SURFACE`): Persson theory, EMT,
    nu = 0.5 (the paper's route); once per process and name."""
    from reduced.roughness import uc_table
    from reduced.roughness.surfaces import preset

    return uc_table(preset(name or DEFAULT_SURFACE).spectrum(), 0.5)


def mesh_record(mesh: Any, fidelity: str | None, file: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The provenance of a mesh: a generated level's parameters (or the file it was read from) and
    its size."""
    from fem.mesh import FIDELITIES

    record: dict[str, Any] = dict(file) if file is not None else {"generated": asdict(FIDELITIES[fidelity])}
    record.update(element=type(mesh).__name__, elements=int(mesh.t.shape[1]), nodes=int(mesh.doflocs.shape[1]))
    return record


def fem_path(geometry: CupGeometry | str | None, material: NeoHookean, contact: ContactLaw | ContactChoice,
             fidelity: str | None, u_max_m: float | None = None, progress: Progress | None = None, *,
             mesh: Any = None, element: str = "quad", **solver_opts: Any) -> CupResponse:
    """The cup (a `CupGeometry`, a preset name, or None with a given `mesh`) meshed at `fidelity`
    and pressed onto the plane to u_max_m (default 0.9 h1) under `contact`."""
    from fem.cup import compress_cup
    from fem.geometry import cup_geometry
    from fem.mesh import cup_mesh

    law = getattr(contact, "contact", contact)
    if mesh is None:
        if isinstance(geometry, str):
            geometry = cup_geometry(geometry)
        mesh = cup_mesh(geometry, fidelity, element=element)
    if u_max_m is None and geometry is not None and not isinstance(geometry, str):
        u_max_m = 0.9 * geometry.h1_m
    return compress_cup(mesh, material, contact=law, u_max_m=u_max_m, progress=progress, **solver_opts)


@dataclass(frozen=True)
class PathStop:
    """Where and why an FEM path stopped before its u_max: the step from `u_max_m_that_runs` (the
    last converged u [m]) to `failed_at_u_m` [m] did not converge or gave a state that was refused
    (`reason`); `error` is the `fem.solver.ConvergenceError` itself (its residual history)."""

    failed_at_u_m: float
    u_max_m_that_runs: float
    reason: str
    error: ConvergenceError = field(repr=False, compare=False)

    def provenance(self) -> dict[str, Any]:
        """The keys that flag a curve partial (lengths in mm, like the sidecar)."""
        return {"partial": True, "failed_at_u_mm": 1e3 * self.failed_at_u_m,
                "u_max_mm_that_runs": 1e3 * self.u_max_m_that_runs, "failure_reason": self.reason}


def converged_part(exc: ConvergenceError) -> tuple[CupResponse, PathStop] | None:
    """The converged part of a failed `fem_path` (the response `fem.cup.compress_cup` kept, flagged
    partial) and its `PathStop`; None when no step beyond u = 0 converged (nothing to keep)."""
    part = getattr(exc, "partial", None)
    if part is None or len(part.u_m) < 2 or not part.u_m[-1] > 0.0:
        return None
    reason = exc.cause or str(exc)
    return part, PathStop(float(exc.t_to), float(part.u_m[-1]), reason, exc)


def partial_note(provenance: Mapping[str, Any]) -> str | None:
    """What a partial curve's provenance says of it, in a few words ("a partial curve: converged to
    u = 8.467 mm, its FEM path stopped at 8.921 mm"), or None for a complete curve."""
    if provenance.get("partial") is not True:
        return None
    runs, failed = provenance.get("u_max_mm_that_runs"), provenance.get("failed_at_u_mm")
    if not isinstance(runs, (int, float)) or not isinstance(failed, (int, float)):
        return "a partial curve (its FEM path stopped before its u_max)"
    return f"a partial curve: converged to u = {runs:.4g} mm, its FEM path stopped at {failed:.4g} mm"


def runnable_u_max_mm(u_mm: float, digits: int = 4) -> float:
    """A partial path's last converged u [mm] rounded down to `digits` significant digits: the
    u_max, as a user types it, that stays within the converged part (and so runs)."""
    import math

    scale = 10.0 ** (math.floor(math.log10(u_mm)) - digits + 1)
    return math.floor(u_mm / scale) * scale


def fem_curve(response: CupResponse, geometry: Mapping[str, Any], fidelity: str | None,
              contact_source: str | None = None, mesh: Mapping[str, Any] | None = None,
              stop: PathStop | None = None) -> StiffnessCurve:
    """The hand-off `StiffnessCurve` of an FEM path, with its provenance (`validation.bridge.handoff`):
    the design's description, the mesh (`mesh_record` of the path's mesh unless given), who
    chose the contact law, and, for the converged part of a failed path, its `PathStop`."""
    from validation.bridge import handoff

    record = dict(mesh) if mesh is not None else mesh_record(response.mesh, fidelity)
    prov = handoff.provenance(response, geometry=geometry, mesh=record, fidelity=fidelity,
                              contact_source=contact_source)
    if stop is not None:
        prov.update(stop.provenance())
    return handoff.stiffness_curve(response, prov)


def fem_stiffness(geometry: CupGeometry | str, material: NeoHookean, contact: ContactLaw | ContactChoice,
                  fidelity: str, u_max_m: float | None = None, progress: Progress | None = None, *,
                  keep_partial: bool = False) -> tuple[CupResponse, StiffnessCurve]:
    """(CupResponse, StiffnessCurve) of a generated cup: `fem_path`, then `fem_curve`; the contact
    source is recorded when `contact` is a `ContactChoice`. A path that fails raises
    `fem.solver.ConvergenceError`; with `keep_partial`, one that converged beyond u = 0 returns its
    converged part instead (``response.partial``; the curve's provenance says where and why)."""
    from fem.geometry import cup_geometry
    from fem.solver import ConvergenceError

    if isinstance(geometry, str):
        geometry = cup_geometry(geometry)
    stop = None
    try:
        response = fem_path(geometry, material, contact, fidelity, u_max_m, progress)
    except ConvergenceError as exc:
        kept = converged_part(exc) if keep_partial else None
        if kept is None:
            raise
        response, stop = kept
    return response, fem_curve(response, geometry.describe(), fidelity, getattr(contact, "source", None),
                               stop=stop)
