"""The exact slopes of the held branch (`fem.gas_branch`): the linear response of a converged
state at the held plate, dF1/dN and dF1/du, and the displacement's response du/dN, du/du_plate
(the first-order predictor of a nearby state). The held-plate system is shared with the water
cavity's walk (`fem.water_branch`)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .free_block import solve_free_block
from .gas_path import CupWithGas
from .solver import StepResult
from .trapped_gas import K_B, GasMechanics

__all__ = ["held_plate_system", "sensitivities", "linear_response"]


def held_plate_system(cup, state: StepResult) -> tuple[np.ndarray, np.ndarray, sp.csr_matrix, np.ndarray]:
    """The linear response at the held plate, shared by the gas and the water cavity: the plate's
    z dofs, the free dofs (plate and held contact dofs fixed), the rows P that let Coulomb's sliding
    nodes slide (r + mu s lambda = 0) and the plate's unit move d/du (u_z = -u on the plate)."""
    u = state.u
    plane, top = cup.cup.plane, cup.cup.top
    plate_z = 2 * top + 1
    held, _ = plane.constraints(state.contact)
    free = np.ones(u.size, bool)
    free[np.concatenate([2 * top, plate_z, held])] = False
    slide = state.contact.active & (state.contact.slip != 0)
    P = sp.identity(u.size, format="csr")
    if slide.any():
        nodes = plane.nodes[slide]
        P = P + sp.csr_matrix((plane.law.mu * state.contact.slip[slide].astype(float),
                               (2 * nodes, 2 * nodes + 1)), shape=P.shape)
    down = np.zeros(u.size)
    down[plate_z] = -1.0
    return plate_z, free, P, down


def sensitivities(cup: CupWithGas, N: float, state: StepResult) -> tuple[float, float]:
    """(dF1/dN, dF1/du) of the converged state `state` holding N molecules
    (`fem.gas_branch.pull_sensitivities`)."""
    return linear_response(cup, N, state)[:2]


def linear_response(cup: CupWithGas, N: float,
                    state: StepResult) -> tuple[float, float, np.ndarray, np.ndarray]:
    """(dF1/dN, dF1/du, du/dN, du/du_plate) of the converged state `state` holding N molecules:
    the pull's sensitivities and the displacement's linear response to N at the held plate and
    to the plate at fixed N (held contact dofs fixed, `held_plate_system`), the first-order
    predictor of a nearby state (`Walk.solve`)."""
    mech = GasMechanics(cup.cup.mech, cup.cavity, cup._gas(N))
    u = state.u
    _, r, K = mech.evaluate(u)
    c, g = K.rank_one
    plate_z, free, P, down = held_plate_system(cup, state)
    Ks = K.plain()
    b = -(K_B * cup.T_K / mech.volume_m3(u)) * g          # dr/dN at fixed u
    h = (P @ g)[free]
    rhs = np.stack([-(P @ b)[free], -(P @ (Ks @ down))[free] - c * h * (g @ down), h], axis=1)
    y = solve_free_block(Ks, P, free, rhs, cup.cup.mech.kin)
    gf = g[free]
    y[:, :2] -= np.outer(y[:, 2], c * (gf @ y[:, :2]) / (1.0 + c * gf @ y[:, 2]))
    x_N, x_u = np.zeros(u.size), down.copy()
    x_N[free], x_u[free] = y[:, 0], y[:, 1]
    return float(np.sum((K @ x_N + b)[plate_z])), float(np.sum((K @ x_u)[plate_z])), x_N, x_u
