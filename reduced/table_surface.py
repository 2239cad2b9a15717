"""A quantity z(u, dp) on a suction table's grid, interpolated: monotone cubic (PCHIP) or linear
along u, linear along dp (`reduced.coupled`'s F1, V, ln(Ndot / dp), and the strip's r and l).

PCHIP (Fritsch-Carlson slopes) keeps each column's monotonicity (the branch stays unique) and is
third order where the data are smooth; linear along dp keeps monotone rows monotone. The grid
refinement in benchmarks/bench_coupled.py measures both. `value_and_slopes` also returns the two
partial derivatives of the same interpolant (dz/du continuous, dz/ddp constant on each cell).
`solid_profile`: the contact pressure a node's leak goes through.
"""

from __future__ import annotations

import bisect
from functools import cached_property

import numpy as np

from reduced.coupled_seal import solid_seal_profile
from reduced.profile_leak import ContactProfile
from reduced.suction_table import SuctionTable

__all__ = ["INTERFACES", "TableSurface", "cell", "solid_profile"]


def cell(x: np.ndarray, y: np.ndarray, a: float, b: float) -> tuple[int, int, float, float]:
    """Cell (i, j) and local coordinates of (a, b) on the grid x by y (clamped to it)."""
    i = min(max(bisect.bisect_right(x, a) - 1, 0), x.size - 2)
    j = min(max(bisect.bisect_right(y, b) - 1, 0), y.size - 2)
    return i, j, (a - x[i]) / (x[i + 1] - x[i]), (b - y[j]) / (y[j + 1] - y[j])


class TableSurface:
    """z(u, dp) on the grid u by dp [len(u), len(dp)] (module docstring); along_u 'pchip' or 'linear'."""

    def __init__(self, u: np.ndarray, dp: np.ndarray, z: np.ndarray, along_u: str):
        self.u, self.dp, self.z = u, dp, np.asarray(z, dtype=float)
        from scipy.interpolate import PchipInterpolator     # here: scipy.interpolate costs ~0.4 s to import
        self.slope = (PchipInterpolator(u, self.z, axis=0).derivative()(u) if along_u == "pchip"
                      else None)

    def __call__(self, a: float, b: float) -> float:
        return self.value_and_slopes(a, b)[0]

    def value_and_slopes(self, a: float, b: float) -> tuple[float, float, float]:
        """(z, dz/du, dz/ddp) at (a, b) (on Python floats: it is called in the inner loops)."""
        i, j, s, t = cell(self.u, self.dp, a, b)
        z, h = self._lists[0], self._lists[2][i]
        z00, z01, z10, z11 = z[i][j], z[i][j + 1], z[i + 1][j], z[i + 1][j + 1]
        if self.slope is None:
            c0, c1 = z00 + s * (z10 - z00), z01 + s * (z11 - z01)
            d0, d1 = (z10 - z00) / h, (z11 - z01) / h
        else:
            m = self._lists[1]
            m00, m01, m10, m11 = h * m[i][j], h * m[i][j + 1], h * m[i + 1][j], h * m[i + 1][j + 1]
            h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
            g0, g10, g11 = (6 * s**2 - 6 * s) / h, (3 * s**2 - 4 * s + 1) / h, (3 * s**2 - 2 * s) / h
            c0, c1 = h00 * z00 + h10 * m00 + h01 * z10 + h11 * m10, h00 * z01 + h10 * m01 + h01 * z11 + h11 * m11
            d0, d1 = g0 * (z00 - z10) + g10 * m00 + g11 * m10, g0 * (z01 - z11) + g10 * m01 + g11 * m11
        return (1 - t) * c0 + t * c1, (1 - t) * d0 + t * d1, (c1 - c0) / (self.dp[j + 1] - self.dp[j])

    @cached_property
    def _lists(self) -> tuple[list, list | None, list]:
        return (self.z.tolist(), None if self.slope is None else self.slope.tolist(),
                np.diff(self.u).tolist())


#: the interface gas law in the contact zone next to the seal (`solid_profile`): the gas pressure
#: rises linearly from p_b to p_a across the zone, or stays p_b, or is p_a throughout (the bounds)
INTERFACES = ("linear", "p_b", "p_a")


def solid_profile(table: SuctionTable, i: int, j: int, scale: float, dp: float,
                  interface: str, patch_length_m: float | None = None) -> ContactProfile:
    """The solid contact pressure at node (i, j): scale p_tab less the interface gas's rise over
    p_b across the zone [r_k, r_cut] at the pressure difference dp (`reduced.coupled`), averaged
    over patches of `patch_length_m` when given (the nominal pressure of rough-contact theory,
    `reduced.profile_leak.patch_average`; the suction's share is in the FEM's pressures already),
    a lone node by its ring load where the table records it (`reduced.coupled_seal`, the fem
    route's reading). ValueError where the table has no profile (the cavity is open there)."""
    prof = table.profiles[i][j]
    if prof is None:
        raise ValueError(f"suction table: no contact profile at u = {1e3 * table.u_m[i]:.4g} mm, "
                         f"dp = {table.dp_Pa[j] / 1e3:.4g} kPa (the cavity is open)")
    rings = None if table.seal_rings is None else table.seal_rings[i][j]
    return solid_seal_profile(prof, *(rings or (None, None)), dp, table.seal_r_m[i, j], table.cut_r_m[i, j],
                              interface, patch_length_m, scale)
