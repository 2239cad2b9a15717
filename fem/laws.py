"""The contact laws at the plane as objects: what the path follower asks of a law.

A law (`Frictionless`, `Sticking`, `Coulomb`) supplies the Newton step that decides which nodes
press (and stick or slide), the plane's friction on the sliding nodes, the check of the friction
cone, the commit of its state at the end of a load step, whether held nodes are anchored
radially, and whether the path is conservative (the energy is its potential: jump control and
extrapolation apply): `fem.contact.PlaneLaw`. The plane's geometry and the contact state are
`fem.contact`'s.

`plane_law` is the one conversion from the plain data of `fem.interface.ContactLaw` (or the
string and mu of the older keyword pair ``contact=, friction=``) to a law object.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .contact import ContactState, PlaneLaw
from .contact_step import ContactStep
from .factorization import factor_shifted
from .friction import FrictionStep
from .interface import ContactLaw

__all__ = ["Frictionless", "Sticking", "Coulomb", "plane_law"]


@dataclass(frozen=True)
class Frictionless:
    """Normal contact only: held nodes slide freely; conservative."""

    name: ClassVar[str] = "frictionless"
    conservative: ClassVar[bool] = True     # the total energy is the path's potential
    anchored: ClassVar[bool] = False        # held nodes keep their radial anchor
    relaxes: ClassVar[bool] = False         # instabilities crossed by damped motion (`fem.newton.relax_step`)
    incremental: ClassVar[bool] = False     # its anchors move to the converged state at every commit
    mu: ClassVar[float] = 0.0

    @property
    def contact(self) -> ContactLaw:
        """The plain data of this law."""
        return ContactLaw(self.name, self.mu)

    def step(self, plane, state: ContactState, u, res, free, du_fixed, tol, friction) -> ContactStep:
        """The Newton step of an iterate: the QP/LCP of `fem.contact_step`."""
        return ContactStep(plane, state, u, res, free, du_fixed, tol)

    def friction_force(self, plane, state: ContactState, res: np.ndarray) -> np.ndarray | None:
        """The plane's friction on the sliding nodes [N], or None: this law has none."""
        return None

    def cone_excess(self, plane, state: ContactState, r_int: np.ndarray) -> float:
        """The largest excess over the friction cone of a stuck node / max lambda: none here."""
        return 0.0

    def commit(self, plane, state: ContactState, u: np.ndarray) -> ContactState:
        """The state carried into the next load step."""
        return state


@dataclass(frozen=True)
class Sticking(Frictionless):
    """A node that lands sticks where it touched down until its reaction turns tensile: the
    slips dissipate, so the path is not conservative."""

    name: ClassVar[str] = "sticking"
    conservative: ClassVar[bool] = False
    anchored: ClassVar[bool] = True


@dataclass(frozen=True)
class Coulomb:
    """Coulomb friction with coefficient mu (`fem.contact`'s module docstring, `fem.friction`):
    incremental, the anchors move to the converged positions at every commit."""

    mu: float
    name: ClassVar[str] = "coulomb"
    conservative: ClassVar[bool] = False
    anchored: ClassVar[bool] = True
    relaxes: ClassVar[bool] = True          # its slip across an instability is integrated in increments
    incremental: ClassVar[bool] = True      # its anchors move to the converged state at every commit

    def __post_init__(self) -> None:
        ContactLaw(self.name, self.mu)          # the one check of mu
        object.__setattr__(self, "mu", float(self.mu))

    @property
    def contact(self) -> ContactLaw:
        """The plain data of this law."""
        return ContactLaw(self.name, self.mu)

    def step(self, plane, state: ContactState, u, res, free, du_fixed, tol, friction) -> FrictionStep:
        """The Newton step of an iterate: the condensed frictional problem of `fem.friction`;
        `friction`: the friction forces of the iterate, part of its load."""
        return FrictionStep(plane, state, u, res, free, du_fixed, tol, factor_shifted, friction)

    def friction_bound(self, plane, res: np.ndarray) -> np.ndarray:
        """g = mu max(lambda, 0) [N] per candidate, lambda the normal reaction in `res`."""
        return self.mu * np.maximum(plane.reactions(res), 0.0)

    def friction_force(self, plane, state: ContactState, res: np.ndarray) -> np.ndarray:
        """The plane's friction on the sliding nodes, -mu lambda s at their radial dofs [N]
        (lambda from `res`, the residual without friction)."""
        f = np.zeros_like(res)
        s = state.active & (state.slip != 0)
        f[2 * plane.nodes[s]] = -self.friction_bound(plane, res)[s] * state.slip[s]
        return f

    def cone_excess(self, plane, state: ContactState, r_int: np.ndarray) -> float:
        """The largest excess of a sticking node's tangential reaction over the cone,
        max(|t| - mu lambda, 0), relative to the largest nodal normal reaction. Round-off at a
        converged state (`fem.friction` solves the cone exactly)."""
        a = state.active & (state.slip == 0)
        if not a.any():
            return 0.0
        lam = plane.reactions(r_int)
        excess = np.abs(r_int[2 * plane.nodes[a]]) - self.mu * np.maximum(lam[a], 0.0)
        return float(max(np.max(excess), 0.0) / max(np.max(lam[state.active]), 1e-300))

    def commit(self, plane, state: ContactState, u: np.ndarray) -> ContactState:
        """The anchors move to the converged positions (the law is incremental)."""
        anchor = np.where(state.active, u[2 * plane.nodes], state.u_r_stick_m)
        return ContactState(state.active, anchor, state.slip)


def plane_law(contact: ContactLaw | str = ContactLaw(), friction: float = 0.0) -> PlaneLaw:
    """The law object of `contact`: a `fem.interface.ContactLaw`, or (the older keyword pair)
    a law's name with Coulomb's mu as `friction`, checked by `ContactLaw` (ValueError)."""
    if isinstance(contact, ContactLaw):
        if friction != 0.0:
            raise ValueError(f"friction: give Coulomb's mu in the ContactLaw ({contact.label()}), "
                             f"not as friction={friction!r}")
    else:
        contact = ContactLaw(contact, friction)
    return _BUILD[contact.law](contact.friction)


_BUILD = {"frictionless": lambda mu: Frictionless(), "sticking": lambda mu: Sticking(), "coulomb": Coulomb}
