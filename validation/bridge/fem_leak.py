"""The leak through one FEM state of the route "fem": its contact traction as the leak's nominal pressure.

u_c(p) of rough-contact theory is read at the nominal pressure, the force on a patch of width L
(the u_c table's `patch_length_m`) over its area (`reduced.profile_leak.patch_average`). The FEM
gives the contact traction as the plane's nodal reactions lambda_a [N] (its multipliers) and, for
plots and widths, the lumped pressures p_a = lambda_a / int N_a dA. Where the contact is resolved
(neighbouring nodes on the plane) the profile of lumped pressures, linear in r between them, is
the traction's density, as on the profile route. Where one node touches alone (its neighbours
lifted: the rim corner of a seal that has narrowed to its last ring) the traction is a line load
of unresolved width: the lumped pressure divides lambda_a by the node's share of the facets on
either side, which leave the plane (one of them the rim's face), so that profile's force over
its neighbours' radii is not lambda_a and follows the elements (benchmarks/fem_route_mesh_study.md).
Such a node enters as a ring load of its own reaction lambda_a at its radius (`SealLoad`):
patch-averaged, a box F / (2 pi r L), the element size gone. The reaction is the FEM's converged
quantity: alone on the plane, the corner's is the plate's force (global equilibrium).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from fem.contact import RigidPlane
    from fem.gas_path import GasState
    from reduced.lifetime import LeakageModel

__all__ = ["SealLoad", "seal_load", "contact_reactions", "state_leak_rate"]


@dataclass(frozen=True)
class SealLoad:
    """The contact traction of one FEM state as the leak reads it (module docstring): the lumped
    pressures p_Pa [Pa] at the contact nodes' radii r_m [m] (0 at a lone node), and the lone nodes'
    reactions rings_F_N [N] at rings_r_m [m]."""

    r_m: np.ndarray
    p_Pa: np.ndarray
    rings_r_m: np.ndarray
    rings_F_N: np.ndarray


def contact_reactions(plane: RigidPlane, step) -> tuple[np.ndarray, np.ndarray]:
    """The plane's reactions lambda_a [N] at the nodes it holds and their deformed radii [m], both
    sorted by radius, of a converged state `step` (a `fem.solver.StepResult`)."""
    held = step.contact.active
    nodes = plane.nodes[held]
    r = plane.kin.node_coordinates()[0, nodes] + step.u[2 * nodes]
    lam = plane.reactions(step.r_int)[held]
    order = np.argsort(r, kind="stable")
    return r[order], lam[order]


def seal_load(state: GasState, plane: RigidPlane) -> SealLoad:
    """The state's `SealLoad`: its profile (radii merged where nodes coincide, the largest
    pressure kept), each loaded sample whose neighbours in r are both unloaded taken out of it
    and given as a ring load of the reactions of the nodes at its radius."""
    radii, p = _merged_profile(state)
    loaded = p > 0
    neighbour = np.zeros_like(loaded)
    neighbour[1:] |= loaded[:-1]
    neighbour[:-1] |= loaded[1:]
    lone = loaded & ~neighbour
    rings = radii[lone]
    if rings.size:
        r, lam = contact_reactions(plane, state.state)
        tol = 1e-12 * rings
        lo, hi = np.searchsorted(r, rings - tol, "left"), np.searchsorted(r, rings + tol, "right")
        if np.any(hi <= lo):
            raise RuntimeError("seal_load: a loaded node of the profile is not among the plane's held "
                               "nodes (the profile and the state disagree)")
        sums = np.concatenate([[0.0], np.cumsum(lam)])
        forces = np.maximum(sums[hi] - sums[lo], 0.0)
    else:
        forces = np.zeros(0)
    return SealLoad(radii, np.where(lone, 0.0, p), rings, forces)


def state_leak_rate(state: GasState, model: LeakageModel, E_Pa: float, radial: str = "annulus", *,
                    plane: RigidPlane, lone_by_reaction: bool = True) -> float:
    """Molecules per second leaking into the cavity at one sealed FEM state, or for water the
    volume inflow [m^3/s] of eq (24): the gas in the contact zone [r_k, r_cut] rises from p_b to
    p_a (the model's `interface`, as `reduced.table_surface.solid_profile`), which the FEM's
    traction (the suction p_a - p_b out to r_cut) does not carry, so the solid pressure is the
    profile's less that rise; patch-averaged with the lone nodes' ring loads (`seal_load`, module
    docstring) where u_c has a patch length (the rise acts on the resolved contact: a lone
    node's zone has no width), its rings' gaps u_c(p / E_Pa) in series at the state's p_b; inf
    where no solid contact is left (the fluid holds the seal open).
    lone_by_reaction=False reads the lumped profile as it is, lone nodes included (the reading
    before, for the mesh study's diagnosis)."""
    from reduced.profile_leak import ContactProfile, patch_average, profile_leak_rate, profile_liquid_rate, ring_gaps

    patch = getattr(model.u_c, "patch_length_m", None)
    if patch and lone_by_reaction:
        load = seal_load(state, plane)
    else:                   # no nominal pressure: the lumped profile as it is, lone nodes included
        load = SealLoad(*_merged_profile(state), np.zeros(0), np.zeros(0))
    if load.r_m.size < 2 or not (np.any(load.p_Pa > 0) or np.any(load.rings_F_N > 0)):
        return math.inf
    r, p = load.r_m, load.p_Pa
    dp = max(state.dp_Pa, 0.0)
    rk, rcut = state.seal_r_m, state.cut_r_m
    tol = 1e-9 * rcut
    zone = (r >= rk - tol) & (r <= rcut + tol)
    rise = {"p_b": 0.0, "p_a": 1.0}.get(model.interface)
    if rise is None:
        rise = np.clip((r - rk) / (rcut - rk), 0.0, 1.0) if rcut > rk else 1.0
    solid = ContactProfile(r, np.where(zone, np.maximum(p - dp * rise, 0.0), p))
    if patch:
        solid = patch_average(solid, patch, load.rings_r_m, load.rings_F_N)
    gaps = ring_gaps(solid, model.u_c, E_Pa)
    if np.all(np.isinf(gaps)):
        return math.inf
    if model.fluid == "water":          # a liquid under tension keeps p_b < 0
        return profile_liquid_rate(model.liquid_viscosity_Pa_s, model.p_a_Pa, min(state.p_b_Pa, model.p_a_Pa),
                                   solid.r_m, gaps, radial)
    p_b = min(max(state.p_b_Pa, 0.0), model.p_a_Pa)
    return profile_leak_rate(model.gas, model.p_a_Pa, p_b, solid.r_m, gaps, radial)


def _merged_profile(state: GasState) -> tuple[np.ndarray, np.ndarray]:
    """The state's lumped profile (r [m], p [Pa]), nodes at one radius merged (the largest p)."""
    radii, inverse = np.unique(np.asarray(state.profile.r_m, dtype=float), return_inverse=True)
    p = np.zeros(radii.size)
    np.maximum.at(p, inverse, np.asarray(state.profile.p_Pa, dtype=float))
    return radii, p
