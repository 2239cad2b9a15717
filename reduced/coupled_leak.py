"""The coupled cavity's leak at the suction table's nodes: each node's conductance Ndot / dp.

At node (u_i, dp_j) the gas at p_b = p_a - dp_j flows in through that state's own solid contact
pressure (`reduced.table_surface.solid_profile`: the table's, less the interface gas's rise across
the zone next to the seal, patch-averaged), its rings' critical gaps u_c(p / E) in series
(`reduced.profile_leak`). Divided by dp the rate has no zero of its driving force at dp = 0 (there
its limit, from a 1 Pa difference), so `reduced.coupled.CoupledCavity` interpolates its logarithm.

The solid pressure in the contact zone next to the seal is the table's (the plane's reaction with
the interface gas at p_b) less the gas pressure rise across the zone, P - p_b = dp (r - r_k) /
(r_cut - r_k), linear from the seal to the zone's outer edge (``interface="linear"``; "p_b" keeps
the table's, "p_a" takes the whole dp off: the two bounds). When the u_c table carries a patch
length (`UcTable.patch_length_m`, from the roughness spectrum) that solid pressure is averaged over
patches of that width before u_c is read, as on the profile route
(`reduced.profile_leak.patch_average`): the nominal pressure of rough-contact theory. A node that
touches alone (a seal narrowed to its last ring) enters by the plane's reaction on it where the
table records it (`SuctionTable.seal_rings`), a ring load spread over the patch: the fem route's
reading of the same state (`reduced.coupled_seal`), which makes the leak independent of the mesh
there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from reduced.gas import Gas
from reduced.profile_leak import profile_leak_rate, ring_gaps
from reduced.suction_table import SuctionTable
from reduced.table_surface import solid_profile

__all__ = ["NodeLeak"]


@dataclass(frozen=True)
class NodeLeak:
    """The leak through the table's states of the kappa-times-stiffer cup (module docstring).
    u_c: critical gap [m] as a function of p / E (E the table's modulus); interface, radial: as
    `reduced.table_surface.solid_profile` and `reduced.profile_leak.profile_leak_rate` read them;
    patch_length_m: the u_c table's patch length (None: raw pressures)."""

    table: SuctionTable
    u_c: Callable[[float], float]
    gas: Gas
    p_a_Pa: float
    kappa: float
    interface: str
    radial: str
    patch_length_m: float | None

    def conductance(self, i: int, j: int, dp: float) -> float:
        """Ndot / dp [1/(s Pa)] at node (i, j) with dp [Pa] its (kappa-scaled) suction; inf where
        no solid contact is left (the gas holds the seal open: no resistance)."""
        prof = solid_profile(self.table, i, j, self.kappa, dp, self.interface, self.patch_length_m)
        drive = max(dp, 1.0)
        gaps = ring_gaps(prof, self.u_c, self.table.E_Pa)
        if np.all(np.isinf(gaps)):
            return np.inf
        return profile_leak_rate(self.gas, self.p_a_Pa, self.p_a_Pa - drive, prof.r_m, gaps, self.radial) / drive

    def conductances(self, dp_axis: np.ndarray, memo: dict | None = None) -> np.ndarray:
        """Ndot / dp at every node (u_i, dp_axis[j]) that is built and sealed, nan elsewhere and
        beyond p_a. memo: node conductances by the node's (u, dp) in table units, read and filled
        (cavities of the same model on tables of the same states share them)."""
        u = self.table.u_m
        out = np.full((u.size, dp_axis.size), np.nan)
        built = self.table.built & self.table.sealed
        for i in range(u.size):
            for j, dp in enumerate(dp_axis):
                if dp > self.p_a_Pa or not built[i, j]:
                    continue
                key = (float(u[i]), float(self.table.dp_Pa[j]))
                if memo is not None and key in memo:
                    out[i, j] = memo[key]
                    continue
                out[i, j] = self.conductance(i, j, float(dp))
                if memo is not None:
                    memo[key] = out[i, j]
        return out
