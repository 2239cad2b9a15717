"""The cavity load's jump where the contact's outer end moves (`ChainCut`), which Coulomb's condensed
contact problem (`fem.friction`) carries in the iteration that moves it."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .cavity import CavitySurface

__all__ = ["ChainCut"]


@dataclass(frozen=True)
class ChainCut:
    """The cavity load dp dV/du at the deformed coordinates x as it depends on where the chain is
    cut, for a contact step that moves the contact's outer end. Releasing the outermost held
    node takes the faces beyond the next one out of the gas region, and their suction with
    them; pressing a node beyond the cut brings the suction onto the faces up to it. The load
    jumps there (V is continuous, its gradient is not), so a linearization at the iterate's cut
    alone sees it one Newton iteration late: the outer end of the contact then peels, or lands,
    one node per iteration."""

    surface: CavitySurface
    x: np.ndarray
    dp_Pa: float

    @property
    def index(self) -> int:
        """The iterate's cut (`CavitySurface.cut_index`)."""
        return self.surface.cut_index(self.x)

    def on_plane(self) -> np.ndarray:
        """Whether each chain node is on the plane at the iterate [n]."""
        return self.surface.on_plane(self.x)

    def positions(self, nodes: np.ndarray) -> np.ndarray:
        """The chain positions of mesh `nodes` (-1: not on the chain)."""
        where = np.full(int(max(self.surface.nodes.max(), nodes.max())) + 1, -1)
        where[self.surface.nodes] = np.arange(self.surface.nodes.size)
        return where[nodes]

    def cut_of(self, on: np.ndarray) -> int:
        """The cut of the chain nodes `on` the plane (`CavitySurface.cut_of`)."""
        return self.surface.cut_of(on)

    @cached_property
    def _gradient(self) -> np.ndarray:
        return self.surface.gradient_cut_at(self.x, self.index)

    def load_change(self, k: int) -> np.ndarray:
        """dp (dV/du cut at k - dV/du at the iterate's cut) [N, 2 nnodes]: the load the residual
        gains when the cut moves to k."""
        return self.dp_Pa * (self.surface.gradient_cut_at(self.x, k) - self._gradient)
