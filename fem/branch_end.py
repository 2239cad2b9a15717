"""Where the held cup's walk gives up without a detachment: the plate's floor.

    u_min = plate_floor_m(cup)          # [m], < 0: the plate above its touching height

Along its equilibrium branch (`fem.gas_branch`) the sealed cup lets go at a fold or where its
seal opens; with the plate raised above its touching height (u < 0) the suction keeps the wall's
lower part on the plane and the wall between the plate and the seal is stretched. The walk needs
a lowest plate position where it stops without a detachment (reason "u_min"), and that position
must lie beyond every detachment the model can give, not at a height tied to the cone's own
(h1): a thin, shallow cup is pulled far above h1 before it lets go.

The floor is where the apex (the plate's edge) stands twice the wall's length above the plane:
h = h1 - u = 2 L, L the unstretched length of the wall's cavity side from the plate's edge to the
rim (the cavity chain in the reference mesh). The wall that joins the plate to the plane is then
stretched on average at least twofold along its length (a straight line is the shortest way,
and only part of the wall spans it), well past the range in which the neo-Hookean wall stands for
the cup's rubber; a branch still closed there has no detachment the model can vouch for.

A fold is the largest N held at F1. Where the walk crossed a jump of the pull (a slip) and landed
on a state holding less gas than one it had passed, and that branch then folds below the gas
already held, the leak (which only adds gas) never takes the cup there: it lets go at the slip,
with the most gas it held (`up_to_most_gas`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .cup import cup_height

__all__ = ["FLOOR_STRETCH", "plate_floor_m", "up_to_most_gas", "wall_length_m"]

#: the mean stretch of the wall at the floor: the apex at FLOOR_STRETCH * L above the plane
FLOOR_STRETCH = 2.0


def wall_length_m(cup) -> float:
    """L [m]: the length of the cavity side of the wall, plate edge to rim, in the reference mesh
    (the polyline through the cavity chain's nodes)."""
    x = cup.mesh.doflocs[:, cup.cavity.nodes]
    return float(np.sum(np.hypot(*np.diff(x, axis=1))))


def plate_floor_m(cup) -> float:
    """The lowest plate position u_min [m] of the held cup's walk (module docstring): the apex at
    FLOOR_STRETCH times the wall's length above the plane, u_min = h1 - FLOOR_STRETCH L. `cup` is a
    `fem.gas_path.CupWithGas` or its water counterpart."""
    return cup_height(cup.mesh) - FLOOR_STRETCH * wall_length_m(cup)


def up_to_most_gas(states: Sequence) -> list:
    """A folded branch's states up to the first one holding the most gas (its N, or V_w for
    water), the detachment (module docstring): the same states where N never fell along them."""
    k = int(np.argmax([s.N for s in states]))
    return list(states[:k + 1])
