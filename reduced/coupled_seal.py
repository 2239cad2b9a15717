"""The seal of a state under suction as the leak reads it: one definition for the fem route
(`validation.bridge.fem_leak`) and the table route (`reduced.coupled` on a `SuctionTable`).

The FEM gives the contact traction as the plane's nodal reactions lambda_a [N] and, for plots and
widths, the lumped pressures p_a = lambda_a / int N_a dA. Where the contact is resolved
(neighbouring nodes on the plane) the lumped profile, linear in r between them, is the traction's
density. Where one node touches alone (its neighbours lifted: the rim corner of a seal narrowed
to its last ring) the lumped pressure divides lambda_a by the node's share of facets that leave
the plane, so it follows the elements; such a node enters as a ring load of its own reaction at
its radius (`SealLoad`), which patch-averaging spreads as the box F / (2 pi r L)
(`reduced.profile_leak.patch_average`). The solid pressure the gaps are read at is that load less
the interface gas's rise over p_b across the contact zone next to the seal [r_k, r_cut]
(`solid_seal_profile`): "linear" from the seal to the zone's outer edge, "p_b" none, "p_a" the
whole dp (the two bounds). A lone node's zone has no width: its ring keeps its force.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reduced.profile_leak import ContactProfile, patch_average

__all__ = ["SealLoad", "lone_samples", "seal_load", "solid_seal_profile"]


@dataclass(frozen=True)
class SealLoad:
    """The contact traction of one state as the leak reads it (module docstring): the lumped
    pressures p_Pa [Pa] at the radii r_m [m] (0 at a lone node), and the lone nodes' reactions
    rings_F_N [N] at rings_r_m [m]."""

    r_m: np.ndarray
    p_Pa: np.ndarray
    rings_r_m: np.ndarray
    rings_F_N: np.ndarray


def lone_samples(p_Pa: np.ndarray) -> np.ndarray:
    """Loaded samples (p > 0) of a profile whose neighbours in r are both unloaded."""
    loaded = np.asarray(p_Pa) > 0
    neighbour = np.zeros_like(loaded)
    neighbour[1:] |= loaded[:-1]
    neighbour[:-1] |= loaded[1:]
    return loaded & ~neighbour


def seal_load(r_m: np.ndarray, p_Pa: np.ndarray, reaction_r_m: np.ndarray, reaction_F_N: np.ndarray) -> SealLoad:
    """The `SealLoad` of a lumped profile (r_m distinct and increasing, p_Pa) and the plane's
    reactions reaction_F_N [N] at the held nodes' radii reaction_r_m [m] (sorted): each lone
    sample taken out of the profile and given as a ring load of the reactions of the nodes at its
    radius. RuntimeError where a lone sample has no held node (profile and reactions disagree)."""
    r, p = np.asarray(r_m, float), np.asarray(p_Pa, float)
    lone = lone_samples(p)
    rings = r[lone]
    if rings.size:
        rr, lam = np.asarray(reaction_r_m, float), np.asarray(reaction_F_N, float)
        tol = 1e-12 * rings
        lo, hi = np.searchsorted(rr, rings - tol, "left"), np.searchsorted(rr, rings + tol, "right")
        if np.any(hi <= lo):
            raise RuntimeError("seal_load: a loaded node of the profile is not among the plane's held "
                               "nodes (the profile and the state disagree)")
        sums = np.concatenate([[0.0], np.cumsum(lam)])
        forces = np.maximum(sums[hi] - sums[lo], 0.0)
    else:
        forces = np.zeros(0)
    return SealLoad(r, np.where(lone, 0.0, p), rings, forces)


def solid_seal_profile(profile: ContactProfile, rings_r_m: np.ndarray | None, rings_F_N: np.ndarray | None,
                       dp_Pa: float, seal_r_m: float, cut_r_m: float, interface: str,
                       patch_length_m: float | None = None, scale: float = 1.0) -> ContactProfile:
    """The solid contact pressure the leak's gaps are read at (module docstring), of a lumped
    `profile` (radii distinct) whose lone samples carry the ring loads rings_F_N [N] at rings_r_m
    [m] (`seal_load`'s; None or empty: none), scaled by `scale`, less the interface gas's rise
    across [seal_r_m, cut_r_m] at dp_Pa. With a patch length the lone samples leave the profile and
    their rings are spread over the patch with it; without one (no nominal pressure to spread a
    ring over) the lumped profile is read as it is, lone samples included."""
    r, p = np.asarray(profile.r_m, float), scale * np.asarray(profile.p_Pa, float)
    rings_r = np.zeros(0) if rings_r_m is None or not patch_length_m else np.asarray(rings_r_m, float).reshape(-1)
    rings_F = np.zeros(0) if rings_F_N is None or not patch_length_m else scale * np.asarray(rings_F_N, float).reshape(-1)
    if rings_r.size != rings_F.size:
        raise ValueError(f"rings_F_N: one force per ring radius, got {rings_F.size} for {rings_r.size}")
    at = np.isin(r, rings_r)
    if int(at.sum()) != rings_r.size:
        raise ValueError("rings_r_m: every ring must lie at one radius of the profile")
    p = np.where(at, 0.0, p)
    tol = 1e-9 * cut_r_m                     # the zone's end nodes are profile nodes too
    zone = (r >= seal_r_m - tol) & (r <= cut_r_m + tol)
    rise = {"p_b": 0.0, "p_a": 1.0}.get(interface)
    if rise is None:
        rise = np.clip((r - seal_r_m) / (cut_r_m - seal_r_m), 0.0, 1.0) if cut_r_m > seal_r_m else 1.0
    solid = ContactProfile(r, np.where(zone, np.maximum(p - dp_Pa * rise, 0.0), p))
    return patch_average(solid, patch_length_m, rings_r, rings_F) if patch_length_m else solid
