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
from typing import TYPE_CHECKING

import numpy as np

from reduced.coupled_seal import SealLoad, lone_samples, solid_seal_profile
from reduced.coupled_seal import seal_load as _seal_load

if TYPE_CHECKING:
    from fem.contact import RigidPlane
    from fem.gas_path import GasState
    from reduced.lifetime import LeakageModel

__all__ = ["SealLoad", "seal_load", "state_leak_rate"]


def seal_load(state: GasState, plane: RigidPlane) -> SealLoad:
    """The state's `SealLoad` (`reduced.coupled_seal.seal_load`): its profile (radii merged where
    nodes coincide, the largest pressure kept), each loaded sample whose neighbours in r are both
    unloaded taken out of it and given as a ring load of the reactions of the nodes at its radius."""
    radii, p = _merged_profile(state)
    if not lone_samples(p).any():              # no reactions needed
        return SealLoad(radii, p, np.zeros(0), np.zeros(0))
    return _seal_load(radii, p, *plane.held_reactions(state.state))


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
    from reduced.profile_leak import ContactProfile, profile_leak_rate, profile_liquid_rate, ring_gaps

    patch = getattr(model.u_c, "patch_length_m", None)
    if patch and lone_by_reaction:
        load = seal_load(state, plane)
    else:                   # no nominal pressure: the lumped profile as it is, lone nodes included
        load = SealLoad(*_merged_profile(state), np.zeros(0), np.zeros(0))
    if load.r_m.size < 2 or not (np.any(load.p_Pa > 0) or np.any(load.rings_F_N > 0)):
        return math.inf
    solid = solid_seal_profile(ContactProfile(load.r_m, load.p_Pa), load.rings_r_m, load.rings_F_N,
                               max(state.dp_Pa, 0.0), state.seal_r_m, state.cut_r_m, model.interface, patch)
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
