"""The leakage model: everything a suction cup's lifetime depends on except the pull force F1.

One noun for every route (`reduced.lifetime.solve_lifetime`): the cup, its stiffness (a
`StiffnessCurve`, for the paper and profile routes), the suction table (a `SuctionTable`, for the
coupled route), the critical gap u_c(p/E), the gas or liquid, the ambient pressure, the stiffness
factor kappa and the relaxation. Each route reads what it needs and refuses a model that lacks it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from reduced.cup import CupParameters
from reduced.gas import AIR, WATER_VISCOSITY_PA_S, Gas

if TYPE_CHECKING:                 # the model only holds these: building one imports no interpolant
    from reduced.stiffness_curve import StiffnessCurve
    from reduced.suction_table import SuctionTable
    from reduced.viscoelastic import RelaxationModulus

__all__ = ["LeakageModel", "reference_model", "FLUIDS"]

FLUIDS = ("air", "water")


@dataclass(frozen=True, eq=False)
class LeakageModel:
    """Everything a lifetime depends on except the pull force F1.

    cup: geometry and Table 1 parameters. stiffness: F0 over u = h1 - h (any `StiffnessCurve`; the
    paper and profile routes). suction: F1, V and contact profiles over (u, dp) (the coupled route).
    u_c: critical gap [m] as a function of p/E (e.g. a `UcTable`). gas, p_a_Pa: the gas and the
    ambient pressure. E_Pa: the modulus in p/E without relaxation (the coupled route takes the
    table's). kappa: the cup is kappa times stiffer than its curve or table (the paper's stiffness
    factor, Fig. 1stiffnessFactor), on every route. relaxation: E_eff(t), or None (then kappa is
    constant); phi0_s: contact time of the stiffness measurement (None: eq 10's steady state at the
    paper's 0.12 mm/s, `measurement_contact_time`). fluid: 'air' (eqs 8, 19) or 'water' (an
    incompressible liquid that flows in by eq 24; p_b may become negative, Sec. 6);
    cavitation_pressure_Pa: water only, None: metastable liquid, else a vapour bubble opens below it.
    interface: the gas law in the coupled route's contact zone (`reduced.table_surface.INTERFACES`).
    The route (and with it the cup laws and the seal) is not part of the model: `solve_lifetime`
    takes it by name.
    """

    cup: CupParameters
    stiffness: StiffnessCurve | None = None
    u_c: Callable[[float], float] | None = None
    gas: Gas = AIR
    p_a_Pa: float = 1e5
    E_Pa: float = 4e6
    relaxation: RelaxationModulus | None = None
    phi0_s: float | None = None
    fluid: str = "air"
    liquid_viscosity_Pa_s: float = WATER_VISCOSITY_PA_S
    cavitation_pressure_Pa: float | None = None
    label: str = field(default="", compare=False)
    suction: SuctionTable | None = None
    kappa: float = 1.0
    interface: str = "linear"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.p_a_Pa) and self.p_a_Pa > 0):
            raise ValueError(f"p_a_Pa: ambient pressure must be > 0 Pa, got {self.p_a_Pa}")
        if not (math.isfinite(self.E_Pa) and self.E_Pa > 0):
            raise ValueError(f"E_Pa: modulus must be > 0 Pa, got {self.E_Pa}")
        if not (math.isfinite(self.kappa) and self.kappa > 0):
            raise ValueError(f"kappa: stiffness factor must be > 0, got {self.kappa}")
        if self.phi0_s is not None and not self.phi0_s > 0:
            raise ValueError(f"phi0_s: measurement contact time must be > 0 s, got {self.phi0_s}")
        from reduced.table_surface import INTERFACES
        if self.interface not in INTERFACES:
            raise ValueError(f"interface: expected one of {', '.join(INTERFACES)}, got {self.interface!r}")
        if self.fluid not in FLUIDS:
            raise ValueError(f"fluid: unknown fluid '{self.fluid}', allowed: {', '.join(FLUIDS)}")
        if self.fluid == "water" and self.relaxation is not None:
            raise ValueError("fluid: the water-filled cavity is implemented without relaxation only")
        if not (math.isfinite(self.liquid_viscosity_Pa_s) and self.liquid_viscosity_Pa_s > 0):
            raise ValueError(f"liquid_viscosity_Pa_s: must be > 0, got {self.liquid_viscosity_Pa_s}")
        p_cav = self.cavitation_pressure_Pa
        if p_cav is not None:
            if self.fluid != "water":
                raise ValueError("cavitation_pressure_Pa: only for fluid 'water'")
            if not (math.isfinite(p_cav) and 0.0 <= p_cav < self.p_a_Pa):
                raise ValueError(f"cavitation_pressure_Pa: must be in [0, p_a) = [0, {self.p_a_Pa:g}) Pa, "
                                 f"got {p_cav}")

    @property
    def reference(self) -> bool:
        """No relaxation: kappa is constant and the state is one-dimensional."""
        return self.relaxation is None


def reference_model(cup: CupParameters, u_c: Callable[[float], float]) -> LeakageModel:
    """The paper's reference conventions (`reduced.lifetime.paper`) for `cup` and `u_c`: Appendix A
    stiffness (d0 = 2 mm, E = 4 MPa), no relaxation, air at 293.15 K, p_a = 1e5 Pa (the paper's rigid
    cone is the paper route's default cup_laws)."""
    from reduced.appendix_a import appendix_a_curve
    return LeakageModel(cup=cup, stiffness=appendix_a_curve(cup, E_Pa=4e6, d0_m=2e-3), u_c=u_c,
                        gas=Gas(T_K=293.15, molecular_mass_u=28.97, viscosity_Pa_s=1.81e-5),
                        p_a_Pa=1e5, E_Pa=4e6, relaxation=None, label="reference")
