"""The cup job: press the cup's top plate down onto the rigid plane z = 0 and record its response.

    from fem import ContactLaw, NeoHookean, compress_cup
    resp = compress_cup(mesh, NeoHookean(E_Pa=4e6, nu=0.49), contact=ContactLaw("frictionless"),
                        u_max_m=5e-3)
    resp.F0_N, resp.r_c_m, resp.l_m, resp.V_m3        # per converged step, at resp.u_m
    resp.write_fields("cup.vtu")                        # displacement, Cauchy stress, pressure

The mesh is a scikit-fem ``MeshQuad2`` (or ``MeshTri2``) of the cross-section in metres (x = r,
y = z) with the boundary tags 'top_plate' (the edge at r0, clamped to the rigid plate) and 'cavity'
(the lower, cavity-facing surface, from the plate down to the rim; `fem.mesh`). The rim's inner
corner rests on the plane in the undeformed state; h1 is the height of the lowest top-plate node.

Loading (Sec. 5.3): the plate moves down by u (displacement control), h = h1 - u; the top-plate
nodes follow it rigidly (u_r = 0, u_z = -u). Every other boundary node may touch the plane under
the chosen contact law (`fem.contact`, `fem.laws`); the contact zones are whatever the solution
makes them. A converged state that dips below the plane between its nodes or whose wall outline
crosses itself (no self-contact is modelled) ends the path with `fem.integrity.StateRejected`.

Per converged step `CupResponse` holds (SI; the measures are the pure functions of
`fem.postprocess`, docs/fem.md and docs/stiffness.md discuss them):

* ``F0_N``: the plate reaction, the cup spring force F0 (eq. 7); ``F0_contact_N``: the
  integrated contact force 2 pi int p r dr, equal to F0 by equilibrium (a check);
* ``r_c_m``: the inner contact radius (eq. 3's r), `postprocess.inner_contact_radius`;
* ``V_m3``: the cavity volume of eq. 4's region, `postprocess.enclosed_volume`;
* ``l_m``: the strip width handed to the reduced model (eq. 5's l): the force-quartile width
  2 (r_75 - r_25) of the innermost contact zone (`postprocess.quartile_width`: it rests on the
  cumulative load only, so it converges with the mesh while r_c jumps by node spacings), 0 where
  the mesh resolves no strip; for comparison ``l_median_m`` (median-force width),
  ``l_weighted_m`` (pressure-weighted width, (int p dA)^2 / (2 pi r_c int p^2 dA), sensitive to
  the singular rim-corner pressure) and ``l_half_max_m`` (width at half maximum);
* ``pressure[i]``: the contact-pressure profile (`fem.contact.PressureProfile`: lumped nodal
  values sorted by radius, and the consistent L2 projection at the Gauss points for integrals);
* ``penetration_m``, ``energy_J``, ``newton_iterations``, ``unstable`` (the step crossed an
  instability, `fem.solver`), ``cone_excess`` (Coulomb's cone check);
* ``min_stretch``: the smallest principal stretch in the wall; below Biot's 0.544 a compressed
  free surface can fold and the curve beyond (`CupResponse.folding_u_m`) depends on the mesh.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import numpy as np
from skfem import Mesh

from .contact import PressureProfile, RigidPlane
from .fields import write_fields
from .interface import ContactLaw
from .mesh import REQUIRED_BOUNDARIES, boundary_path, check_cup_mesh
from .postprocess import (BIOT_STRETCH, enclosed_volume, half_maximum_width, inner_contact_radius,
                          median_force_width, quartile_width, smallest_stretch, weighted_width)
from .forms import Mechanics
from .integrity import check_state
from .kinematics import Kinematics
from .laws import plane_law
from .material import NeoHookean
from .solver import ConvergenceError, SolverOptions, SolverStats, StepResult, follow_path

__all__ = ["compress_cup", "CupResponse", "CupSetup", "cup_height", "REQUIRED_BOUNDARIES"]



@dataclass(frozen=True, eq=False)
class CupResponse:
    """The cup's response per converged step (module docstring). Arrays are over steps."""

    h1_m: float
    contact: str                # the law's name (`contact_law`: the law with its mu)
    material: NeoHookean
    u_m: np.ndarray
    F0_N: np.ndarray
    F0_contact_N: np.ndarray
    r_c_m: np.ndarray
    V_m3: np.ndarray
    l_m: np.ndarray
    l_median_m: np.ndarray
    l_weighted_m: np.ndarray
    l_half_max_m: np.ndarray
    penetration_m: np.ndarray
    energy_J: np.ndarray
    newton_iterations: np.ndarray
    unstable: np.ndarray
    min_stretch: np.ndarray
    pressure: tuple[PressureProfile, ...]
    stats: SolverStats
    mesh: Mesh = field(repr=False)
    displacements: tuple[np.ndarray, ...] = field(repr=False)
    nodal_pressure_Pa: tuple[np.ndarray, ...] = field(repr=False)
    friction: float = 0.0       # Coulomb's mu (contact "coulomb")
    cone_excess: np.ndarray | None = None   # Coulomb: largest excess over the cone / max lambda
    partial: bool = False       # the converged part of a path that failed later (`compress_cup`)

    @property
    def contact_law(self) -> ContactLaw:
        """The contact law of the run, with Coulomb's mu."""
        return ContactLaw(self.contact, self.friction)

    @property
    def h_m(self) -> np.ndarray:
        """Cup height h = h1 - u [m]."""
        return self.h1_m - self.u_m

    @property
    def folding_u_m(self) -> float | None:
        """The first u [m] at which the wall is compressed beyond Biot's stretch (a free surface
        may fold there: the curve beyond depends on the mesh), or None."""
        beyond = np.flatnonzero(self.min_stretch < BIOT_STRETCH)
        return float(self.u_m[beyond[0]]) if beyond.size else None

    def write_fields(self, path: str | Path, step: int | None = -1) -> Path:
        """Write displacement, Cauchy stress (element means) and contact pressure on the reference
        mesh: one step as VTU (or another format meshio infers from the suffix), or, to an .xdmf,
        one step or every step (step=None) as a time series over u (`fem.fields`)."""
        return write_fields(self, path, step)


def cup_height(mesh: Mesh) -> float:
    """h1: the height of the lowest top-plate node above the plane z = 0 [m]."""
    _check_mesh(mesh)
    kin_nodes = _boundary_nodes(mesh, "top_plate")
    return float(mesh.doflocs[1, kin_nodes].min())


def compress_cup(mesh: Mesh, material: NeoHookean = NeoHookean(),
                 contact: ContactLaw | str = ContactLaw(),
                 u_max_m: float | None = None, friction: float = 0.0,
                 progress: Callable[[float, str], None] | None = None,
                 admissible_only: bool = True, **solver_opts: Any) -> CupResponse:
    """Press the cup from u = 0 to u_max_m (default 0.9 h1, at most h1: there the plate's edge
    reaches the plane; the steep rise of F0 where the wall is squeezed flat lies just below it)
    and return its `CupResponse`.

    contact: the law at the plane, a `fem.interface.ContactLaw` (frictionless, sticking, or
    coulomb with Coulomb's mu in [0, 100]; a design file's law is
    `fem.design_file.load_design(path).contact`); or, the older spelling, the law's name with mu as
    `friction` (`fem.laws.plane_law` converts either).
    admissible_only: end the path with `fem.integrity.StateRejected` at the first converged state
    that violates contact between the nodes or crosses itself (module docstring); False follows
    the solver's path regardless (for studies of the solver itself).
    solver_opts: fields of `fem.solver.SolverOptions` (rtol, etol, max_iterations, initial_step,
    max_step, min_step, growth); the step fractions are of the default travel 0.9 h1, or of u_max
    when that is shorter (`_step_schedule`: a longer path takes the default path's steps). Raises ValueError for bad input, `fem.solver.ConvergenceError`
    (a RuntimeError) if a step cannot be converged; it carries the converged part as
    ``exc.partial`` (a `CupResponse` flagged partial, up to u = exc.t_from).
    """
    h1 = cup_height(mesh)
    cup = CupSetup.of(mesh, material, contact, friction)
    u_max = 0.9 * h1 if u_max_m is None else float(u_max_m)
    if h1 < u_max <= h1 * (1 + 1e-9):        # h1 itself, up to the round-off of a unit conversion
        u_max = h1
    if not (0.0 < u_max <= h1):
        raise ValueError(f"u_max_m: plate displacement must be in (0, h1] = (0, "
                         f"{h1 * 1e3:.4g} mm] (at u = h1 the plate reaches the plane), "
                         f"got {u_max * 1e3:.4g} mm")
    options = _step_schedule(SolverOptions(**solver_opts), u_max, h1)
    mech, plane, top, path = cup.mech, cup.plane, cup.top, cup.path
    steps: list[_StepOutputs] = []

    def on_step(s: StepResult) -> None:
        # a converged state that violates contact (between the nodes, or self-contact) ends the path
        if admissible_only:
            check_state(mesh, s.u, s.t, len(steps), steps[-1].u_m if steps else 0.0)
        steps.append(_measure(s, mech, plane, top, path))
        if progress and s.t > 0.0:
            progress(s.t / u_max, f"step {len(steps) - 1}: u = {s.t * 1e3:.4g} mm of {u_max * 1e3:.4g} mm, "
                                  f"{s.iterations} Newton iterations")

    try:
        stats = follow_path(mech, cup.plate_at(0.0), u_max, plane=plane, options=options,
                            on_step=on_step, name="u [m]")
    except ConvergenceError as exc:
        if exc.stats is not None:       # the solver gave up: keep what converged
            exc.partial = _response(steps, h1, plane, material, exc.stats, mesh, partial=True)
        raise
    return _response(steps, h1, plane, material, stats, mesh)


#: the travel whose fractions the load steps are (the default u_max): `_step_schedule`
REFERENCE_TRAVEL = 0.9


def _step_schedule(options: SolverOptions, u_max: float, h1: float) -> SolverOptions:
    """`options` with its step fractions (initial, largest, smallest, of a judged jump) taken of
    REFERENCE_TRAVEL h1 instead of u_max when u_max is longer: every path to u_max >= 0.9 h1 then
    converges the same states as the default one up to its end (the steps fall at the same u), so
    a stiffness curve's samples, and what is interpolated between them, do not move with u_max. A
    shorter path keeps its fractions of u_max (at least 1 / max_step steps)."""
    scale = min(1.0, REFERENCE_TRAVEL * h1 / u_max)
    if scale == 1.0:
        return options
    return replace(options, **{name: getattr(options, name) * scale
                               for name in ("initial_step", "max_step", "min_step", "jump_min_step")})


def _response(steps: list["_StepOutputs"], h1: float, plane: RigidPlane, material: NeoHookean,
              stats: SolverStats, mesh: Mesh, partial: bool = False) -> CupResponse:
    """The `CupResponse` of the converged steps."""
    per_step = {f.name: np.array([getattr(st, f.name) for st in steps])
                for f in fields(_StepOutputs) if f.name not in _PER_STEP_OBJECTS}
    return CupResponse(h1_m=h1, contact=plane.law.name, friction=plane.law.mu, material=material,
                       stats=stats, mesh=mesh, partial=partial, **per_step,
                       **{name: tuple(getattr(st, name) for st in steps) for name in _PER_STEP_OBJECTS})


@dataclass(frozen=True, eq=False)
class CupSetup:
    """What every cup job sets up: the body, the plane (every boundary node but the plate's may
    touch it), the top plate's nodes and the cavity path (plate edge -> rim)."""

    mech: Mechanics
    plane: RigidPlane
    top: np.ndarray
    path: np.ndarray

    @classmethod
    def of(cls, mesh: Mesh, material: NeoHookean, contact: ContactLaw | str = ContactLaw(),
           friction: float = 0.0) -> "CupSetup":
        """Check the contact law (`fem.laws.plane_law`: a `ContactLaw`, or a name and Coulomb's mu)
        and the material (ValueError) and build the setup."""
        law = plane_law(contact, friction)
        if not isinstance(material, NeoHookean):
            raise ValueError(f"material: a fem.material.NeoHookean is required, got {type(material).__name__}")
        kin = Kinematics.of(mesh)
        top = _boundary_nodes(mesh, "top_plate")
        plane = RigidPlane(kin, mesh.boundary_facets(), law=law, exclude=top)
        return cls(Mechanics(kin, material), plane, top, boundary_path(mesh, "cavity"))

    def plate_at(self, u0_m: float, moving: bool = True) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
        """The prescribed plate, u_r = 0 and u_z = -(u0 + t) (moving) or -u0 (held), as
        `fem.solver.follow_path`'s dirichlet(t)."""
        dofs = np.concatenate([2 * self.top, 2 * self.top + 1])
        zeros = np.zeros(len(self.top))
        return lambda t: (dofs, np.concatenate([zeros, np.full(len(self.top), -(u0_m + moving * t))]))


def _joined(a: SolverStats, b: SolverStats) -> SolverStats:
    """The cost of two consecutive paths as one."""
    return SolverStats(**{f.name: getattr(a, f.name) + getattr(b, f.name) if f.name != "dofs"
                          else b.dofs for f in fields(SolverStats)})


@dataclass(frozen=True, eq=False)
class _StepOutputs:
    """The outputs of one converged state (module docstring); fields named as in `CupResponse`."""

    u_m: float
    F0_N: float
    F0_contact_N: float
    r_c_m: float
    V_m3: float
    l_m: float
    l_median_m: float
    l_weighted_m: float
    l_half_max_m: float
    penetration_m: float
    energy_J: float
    newton_iterations: int
    unstable: bool
    min_stretch: float
    cone_excess: float
    pressure: PressureProfile
    displacements: np.ndarray
    nodal_pressure_Pa: np.ndarray


_PER_STEP_OBJECTS = ("pressure", "displacements", "nodal_pressure_Pa")     # tuples, not arrays


def _measure(s: StepResult, mech: Mechanics, plane: RigidPlane, top: np.ndarray,
             path: np.ndarray) -> _StepOutputs:
    """The per-step outputs of a converged state (module docstring)."""
    prof, p_nodes = plane.pressure(s.u, s.contact, s.r_int)
    active = plane.nodes[s.contact.active]
    x = mech.kin.node_coordinates() + np.stack([s.u[0::2], s.u[1::2]])
    on_path = np.isin(path, active)
    on_path[-1] |= not on_path.any()          # u = 0: the rim corner rests on the plane
    r_c, l_q, l_hm, l_med = _edge_and_widths(prof, x[0, path[-1]])
    return _StepOutputs(
        u_m=s.t, F0_N=-float(np.sum(s.r_int[2 * top + 1])),
        F0_contact_N=float(np.sum(prof.p_gauss_Pa * prof.w_m2)), r_c_m=r_c,
        V_m3=enclosed_volume(x[0, path], x[1, path], on_path),
        l_m=l_q, l_median_m=l_med, l_weighted_m=_weighted_width(prof, r_c), l_half_max_m=l_hm,
        penetration_m=plane.largest_penetration(s.u), energy_J=s.energy_J,
        newton_iterations=s.iterations, unstable=s.unstable,
        min_stretch=float(np.min(smallest_stretch(mech.kin.deformation_gradient(s.u)))),
        cone_excess=plane.law.cone_excess(plane, s.contact, s.r_int),
        pressure=prof, displacements=s.u, nodal_pressure_Pa=p_nodes)


def _weighted_width(profile: PressureProfile, r_c_m: float) -> float:
    """Pressure-weighted strip width l = (int p dA)^2 / (2 pi r_c int p^2 dA) [m], dA = 2 pi r dr
    (the definition of `postprocess.pressure_weighted_width`), with the integrals taken over the
    consistent L2 projection at the boundary Gauss points (0 without contact)."""
    if profile.w_m2.size == 0:
        return 0.0
    return weighted_width(float(np.sum(profile.p_gauss_Pa * profile.w_m2)),
                          float(np.sum(profile.p_gauss_Pa**2 * profile.w_m2)), r_c_m)


def _edge_and_widths(profile: PressureProfile, r_rim: float) -> tuple[float, float, float, float]:
    """(r_c, l_quartile, l_half_max, l_median) from the lumped nodal profile; with fewer than two
    loaded nodes (the rim corner alone, or no contact at u = 0) r_c is that node's (or the rim's)
    radius and the widths are 0 (no strip the mesh resolves)."""
    r, p = profile.r_m, profile.p_Pa
    keep = np.concatenate([[True], np.diff(r) > 0]) if r.size else np.zeros(0, bool)
    r, p = r[keep], p[keep]
    if np.count_nonzero(p > 0) < 2:
        return (float(r[np.argmax(p)]) if r.size else float(r_rim)), 0.0, 0.0, 0.0
    r_c = inner_contact_radius(r, p)
    return r_c, quartile_width(r, p), half_maximum_width(r, p, r_c), median_force_width(r, p, r_c)


def _check_mesh(mesh: Mesh) -> None:
    """`fem.mesh.check_cup_mesh` (tags, orientation, r >= 0, z >= 0), and the rim on the plane."""
    check_cup_mesh(mesh)
    zmin = float(mesh.doflocs[1].min())
    if zmin > 1e-9 * float(np.ptp(mesh.doflocs[1])):
        raise ValueError(f"mesh: the rim must rest on the plane z = 0 (lowest z = {zmin:.3g} m)")


def _boundary_nodes(mesh: Mesh, name: str) -> np.ndarray:
    nv = int(mesh.t.max()) + 1
    f = mesh.boundaries[name]
    return np.unique(np.concatenate([mesh.facets[:, f].ravel(), nv + f]))
