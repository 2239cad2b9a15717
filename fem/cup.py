"""The cup job: press the cup's top plate down onto the rigid plane z = 0 and record its response.

    from fem.material import NeoHookean
    from fem.cup import compress_cup
    resp = compress_cup(mesh, NeoHookean(E_Pa=4e6, nu=0.49), contact="frictionless", u_max_m=5e-3)
    resp.F0_N, resp.r_c_m, resp.l_m, resp.V_m3        # per converged step, at resp.u_m
    resp.write_fields("cup.vtu")                        # displacement, Cauchy stress, pressure

The mesh is a scikit-fem ``MeshQuad2`` of the cross-section in metres (x = r, y = z) with the
boundary tags 'top_plate' (the edge at r0, clamped to the rigid plate), 'cavity' (the lower,
cavity-facing surface, from the plate down to the rim), 'outer' and 'rim'. The rim's inner corner
rests on the plane, z = 0, in the undeformed state. h1 is the height of the lowest top-plate node.

Loading (Sec. 5.3): the plate moves down by u (displacement control), h = h1 - u; the top-plate
nodes follow it rigidly (u_r = 0, u_z = -u). Every boundary node except those on the plate may
touch the plane (`fem.contact`); the contact zones are whatever the solution makes them.

Per converged step, `CupResponse` holds (all SI):

* ``F0_N``: the reaction on the top plate, the cup spring force F0 (eq. 7); ``F0_contact_N``: the
  integrated contact force 2 pi int p r dr, which equals F0 by equilibrium (a check, both stored);
* ``r_c_m``: the inner contact radius (eq. 3's r): the deformed radius of the innermost node in
  contact along the cavity surface (resolution: the local node spacing);
* ``V_m3``: the cavity volume under the plate and inside the cup down to z = 0 (the region of
  eq. 4), V = pi int r^2 dz along the deformed cavity surface from the inner contact point up to
  the plate;
* ``l_m``: the pressure-weighted strip width l = (int p dA)^2 / (2 pi r_c int p^2 dA), dA = 2 pi r dr,
  which is exactly l for a uniform strip of width l (the paper's eq. 6 picture), and an integral of
  the projected pressure, hence mesh-convergent; ``l_half_max_m``: the width of the contiguous
  region around the pressure maximum where p >= max p / 2;
* ``penetration_m`` (largest violation of z >= 0 along the contact edges), ``energy_J`` (stored
  elastic energy), ``newton_iterations``, and the pressure profiles ``pressure[i]``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from skfem import Mesh

from .contact import PressureProfile, RigidPlane
from .forms import Mechanics
from .kinematics import Kinematics
from .material import NeoHookean, cauchy_stress
from .solver import SolverOptions, SolverStats, StepResult, follow_path

__all__ = ["compress_cup", "CupResponse", "cup_height", "contact_width", "half_max_width",
           "REQUIRED_BOUNDARIES"]

REQUIRED_BOUNDARIES = ("top_plate", "cavity", "outer", "rim")


@dataclass(frozen=True, eq=False)
class CupResponse:
    """The cup's response per converged step (module docstring). Arrays are over steps."""

    h1_m: float
    contact: str
    material: NeoHookean
    u_m: np.ndarray
    F0_N: np.ndarray
    F0_contact_N: np.ndarray
    r_c_m: np.ndarray
    V_m3: np.ndarray
    l_m: np.ndarray
    l_half_max_m: np.ndarray
    penetration_m: np.ndarray
    energy_J: np.ndarray
    newton_iterations: np.ndarray
    pressure: tuple[PressureProfile, ...]
    stats: SolverStats
    mesh: Mesh = field(repr=False)
    displacements: tuple[np.ndarray, ...] = field(repr=False)
    nodal_pressure_Pa: tuple[np.ndarray, ...] = field(repr=False)

    @property
    def h_m(self) -> np.ndarray:
        """Cup height h = h1 - u [m]."""
        return self.h1_m - self.u_m

    def write_fields(self, path: str | Path, step: int = -1) -> Path:
        """Write displacement, Cauchy stress (element means) and contact pressure of one step as
        VTU (or any format meshio infers from the suffix, e.g. .xdmf) on the reference mesh."""
        from .fields import write_fields
        return write_fields(self, path, step)


def cup_height(mesh: Mesh) -> float:
    """h1: the height of the lowest top-plate node above the plane z = 0 [m]."""
    _check_mesh(mesh)
    kin_nodes = _boundary_nodes(mesh, "top_plate")
    return float(mesh.doflocs[1, kin_nodes].min())


def compress_cup(mesh: Mesh, material: NeoHookean = NeoHookean(),
                 contact: Literal["frictionless", "sticking"] = "frictionless",
                 u_max_m: float | None = None,
                 progress: Callable[[float, str], None] | None = None,
                 **solver_opts: Any) -> CupResponse:
    """Press the cup from u = 0 to u_max_m (default 0.9 h1) and return its `CupResponse`.

    solver_opts: fields of `fem.solver.SolverOptions` (rtol, etol, max_iterations, initial_step,
    max_step, min_step, growth). Raises ValueError for bad input, `fem.solver.ConvergenceError`
    (a RuntimeError) if a step cannot be converged.
    """
    h1 = cup_height(mesh)
    if contact not in ("frictionless", "sticking"):
        raise ValueError(f"contact: must be 'frictionless' or 'sticking', got {contact!r}")
    if not isinstance(material, NeoHookean):
        raise ValueError(f"material: a fem.material.NeoHookean is required, got {type(material).__name__}")
    u_max = 0.9 * h1 if u_max_m is None else float(u_max_m)
    if not (0.0 < u_max <= 1.25 * h1):
        raise ValueError(f"u_max_m: plate displacement must be in (0, 1.25 h1] = (0, "
                         f"{1.25 * h1 * 1e3:.4g} mm], got {u_max * 1e3:.4g} mm")
    options = SolverOptions(**solver_opts)

    kin = Kinematics.of(mesh)
    mech = Mechanics(kin, material)
    top = _boundary_nodes(mesh, "top_plate")
    plane = RigidPlane.on(kin, ["cavity", "rim", "outer"], exclude=["top_plate"], law=contact)
    top_dofs = np.concatenate([2 * top, 2 * top + 1])
    cavity = _CavityCurve.of(mesh, kin)

    def dirichlet(u):
        return top_dofs, np.concatenate([np.zeros(len(top)), np.full(len(top), -u)])

    rec: dict[str, list] = {k: [] for k in (
        "u", "F0", "Fc", "rc", "V", "l", "lhm", "pen", "W", "its", "p", "disp", "pn")}

    def on_step(s: StepResult) -> None:
        prof, p_nodes = plane.pressure(s.u, s.contact, s.r_int)
        Fc = float(np.sum(prof.p_gauss_Pa * prof.w_m2))
        r_c, V = cavity.inner_contact_and_volume(s.u, plane.nodes[s.contact.active])
        rec["u"].append(s.t)
        rec["F0"].append(-float(np.sum(s.r_int[2 * top + 1])))
        rec["Fc"].append(Fc)
        rec["rc"].append(r_c)
        rec["V"].append(V)
        rec["l"].append(contact_width(prof, r_c))
        rec["lhm"].append(half_max_width(prof))
        rec["pen"].append(plane.largest_penetration(s.u))
        rec["W"].append(mech.energy(s.u))
        rec["its"].append(s.iterations)
        rec["p"].append(prof)
        rec["disp"].append(s.u)
        rec["pn"].append(p_nodes)

    stats = follow_path(mech, dirichlet, u_max, plane=plane, options=options, on_step=on_step,
                        progress=progress)
    a = {k: np.asarray(v) for k, v in rec.items() if k not in ("p", "disp", "pn")}
    return CupResponse(
        h1_m=h1, contact=contact, material=material, u_m=a["u"], F0_N=a["F0"],
        F0_contact_N=a["Fc"], r_c_m=a["rc"], V_m3=a["V"], l_m=a["l"], l_half_max_m=a["lhm"],
        penetration_m=a["pen"], energy_J=a["W"], newton_iterations=a["its"].astype(int),
        pressure=tuple(rec["p"]), stats=stats, mesh=mesh, displacements=tuple(rec["disp"]),
        nodal_pressure_Pa=tuple(rec["pn"]))


# ------------------------------------------------------------------------------------------
# Strip widths from a pressure profile (pure functions of the profile)
# ------------------------------------------------------------------------------------------
def contact_width(profile: PressureProfile, r_c_m: float) -> float:
    """Pressure-weighted strip width l = (int p dA)^2 / (2 pi r_c int p^2 dA) [m] (0 without contact).

    For a uniform pressure on a strip [r_c, r_c + l] it returns l (to O(l / r_c)); it is an integral
    of the projected pressure, so it converges with the mesh like the pressure does in L2.
    """
    if profile.w_m2.size == 0 or not np.isfinite(r_c_m) or r_c_m <= 0:
        return 0.0
    P1 = np.sum(profile.p_gauss_Pa * profile.w_m2)
    P2 = np.sum(profile.p_gauss_Pa**2 * profile.w_m2)
    return float(P1**2 / (2.0 * np.pi * r_c_m * P2)) if P2 > 0 else 0.0


def half_max_width(profile: PressureProfile) -> float:
    """Width [m] of the contiguous radial interval around the pressure maximum where p >= max p / 2
    (crossings located by linear interpolation between sample points); 0 without contact."""
    r, p = profile.r_m, profile.p_Pa
    if r.size < 2 or np.max(p) <= 0:
        return 0.0
    k = int(np.argmax(p))
    half = 0.5 * p[k]
    lo = k
    while lo > 0 and p[lo - 1] >= half:
        lo -= 1
    hi = k
    while hi < r.size - 1 and p[hi + 1] >= half:
        hi += 1
    r_lo, r_hi = r[lo], r[hi]
    if lo > 0 and p[lo] != p[lo - 1]:
        r_lo = r[lo - 1] + (half - p[lo - 1]) / (p[lo] - p[lo - 1]) * (r[lo] - r[lo - 1])
    if hi < r.size - 1 and p[hi] != p[hi + 1]:
        r_hi = r[hi] + (half - p[hi]) / (p[hi + 1] - p[hi]) * (r[hi + 1] - r[hi])
    return float(r_hi - r_lo)


# ------------------------------------------------------------------------------------------
# Geometry of the deformed cavity surface
# ------------------------------------------------------------------------------------------
def _check_mesh(mesh: Mesh) -> None:
    missing = [b for b in REQUIRED_BOUNDARIES if mesh.boundaries is None or b not in mesh.boundaries]
    if missing:
        raise ValueError(f"mesh: boundary tags {missing} are missing; a cup mesh needs "
                         f"{list(REQUIRED_BOUNDARIES)}")
    zmin = float(mesh.doflocs[1].min())
    size = float(np.ptp(mesh.doflocs[1]))
    if abs(zmin) > 1e-9 * size:
        raise ValueError(f"mesh: the rim must rest on the plane z = 0 (lowest z = {zmin:.3g} m)")


def _boundary_nodes(mesh: Mesh, name: str) -> np.ndarray:
    nv = int(mesh.t.max()) + 1
    f = mesh.boundaries[name]
    return np.unique(np.concatenate([mesh.facets[:, f].ravel(), nv + f]))


@dataclass(frozen=True)
class _CavityCurve:
    """The cavity-facing boundary as an ordered chain of quadratic facets (plate -> rim)."""

    facet_nodes: np.ndarray     # [3, nf]: start vertex, end vertex, midpoint; ordered along the chain
    X: np.ndarray               # reference node coordinates

    @classmethod
    def of(cls, mesh: Mesh, kin: Kinematics) -> "_CavityCurve":
        nv = int(mesh.t.max()) + 1
        f = mesh.boundaries["cavity"]
        ends = mesh.facets[:, f]
        X = kin.node_coordinates()
        # walk the chain starting at the end that lies on the top plate
        top = set(_boundary_nodes(mesh, "top_plate").tolist())
        nbr: dict[int, list[int]] = {}
        for j, (a, b) in enumerate(ends.T):
            nbr.setdefault(a, []).append(j)
            nbr.setdefault(b, []).append(j)
        starts = [v for v in nbr if len(nbr[v]) == 1 and v in top]
        if len(starts) != 1:
            raise ValueError("mesh: the 'cavity' boundary must be one chain of facets starting at "
                             "the 'top_plate' edge")
        order, node, used = [], starts[0], set()
        while True:
            nxt = [j for j in nbr[node] if j not in used]
            if not nxt:
                break
            j = nxt[0]
            used.add(j)
            a, b = ends[:, j]
            a, b = (a, b) if a == node else (b, a)
            order.append((a, b, nv + f[j]))
            node = b
        return cls(np.array(order).T, X)

    def inner_contact_and_volume(self, u: np.ndarray, active_nodes: np.ndarray) -> tuple[float, float]:
        """(r_c, V): the first node in contact along the chain from the plate, and the volume
        pi int r^2 dz from the plate down to it (or to the rim if the cavity has no contact)."""
        fn = self.facet_nodes
        x = self.X[:, fn] + np.stack([u[2 * fn], u[2 * fn + 1]])      # [2, 3, nf]
        on = np.isin(fn[:2], active_nodes)                              # start/end node in contact
        hit = np.flatnonzero(on[0] | on[1])
        if hit.size:
            j = hit[0]
            last = j - 1 if on[0, j] else j          # facets 0..last lie above the contact point
            r_c = float(x[0, 0, j] if on[0, j] else x[0, 1, j])
        else:
            last = fn.shape[1] - 1
            r_c = float(x[0, 1, last])
        s, w = np.polynomial.legendre.leggauss(4)
        s, w = 0.5 * (s + 1), 0.5 * w
        N = np.stack([(1 - s) * (1 - 2 * s), s * (2 * s - 1), 4 * s * (1 - s)])
        dN = np.stack([4 * s - 3, 4 * s - 1, 4 - 8 * s])
        xs = x[:, :, : last + 1]
        r = np.einsum("ag,an->gn", N, xs[0])
        dz = np.einsum("ag,an->gn", dN, xs[1])
        # the chain runs from the plate down: dz < 0, so V = -pi int r^2 dz along it
        V = float(-np.pi * np.sum(r**2 * dz * w[:, None]))
        return r_c, V
