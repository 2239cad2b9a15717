"""Gas (and liquid) flow through the critical constrictions, Sec. 4: eqs (11)-(24).

All leak rates are for the whole annulus: they take the aspect ratio L_y/L_x = 2 pi r / l of
eq (9) as an argument. They are plain arithmetic, so they accept floats or numpy arrays.

Air at 20 deg C: eta = 1.81e-5 Pa s (tabulated), m = 28.97 u. The paper's remark after eq (24)
that air has "~5e-5 Pa s" is not air's viscosity (that is 1.8e-5 Pa s at room temperature); we
use the tabulated value, and the mean free path follows from it through eq (12): about 99 nm at
1 bar and 20 deg C, consistent with the paper's "of order 100 nm".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

__all__ = ["K_B", "ATOMIC_MASS", "XI", "Gas", "AIR", "WATER_VISCOSITY_PA_S",
           "diffusive_leak_rate", "ballistic_leak_rate", "average_mean_free_path",
           "interpolated_leak_rate", "leak_rate_function", "ballistic_share",
           "liquid_volume_rate"]

K_B = 1.380649e-23          # J/K (exact, SI 2019)
ATOMIC_MASS = 1.66053906660e-27  # kg
XI = 32.0 / math.pi         # eq (19)
#: dynamic viscosity of water at 20 deg C [Pa s]
WATER_VISCOSITY_PA_S = 1.002e-3


@dataclass(frozen=True)
class Gas:
    """An ideal gas: temperature, molecular mass and (tabulated) viscosity."""

    T_K: float = 293.15
    molecular_mass_u: float = 28.97
    viscosity_Pa_s: float = 1.81e-5

    def __post_init__(self) -> None:
        for name in ("T_K", "molecular_mass_u", "viscosity_Pa_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name}: must be > 0, got {value}")

    @cached_property
    def kT_J(self) -> float:
        return K_B * self.T_K

    @cached_property
    def mass_kg(self) -> float:
        return self.molecular_mass_u * ATOMIC_MASS

    @cached_property
    def mean_speed_m_s(self) -> float:
        """v = (8 kT / (pi m))^(1/2), eq (11)."""
        return math.sqrt(8.0 * self.kT_J / (math.pi * self.mass_kg))

    @cached_property
    def n_lambda_per_m2(self) -> float:
        """n lambda = 3 eta / (m v), independent of the density (eq 12)."""
        return 3.0 * self.viscosity_Pa_s / (self.mass_kg * self.mean_speed_m_s)

    def number_density(self, p_Pa):
        """n = p / kT [1/m^3] (ideal gas)."""
        return p_Pa / self.kT_J

    def mean_free_path_m(self, p_Pa):
        """lambda = 3 eta / (m n v) from eta = m n v lambda / 3, eq (12)."""
        return self.n_lambda_per_m2 / self.number_density(p_Pa)


#: air at 20 deg C
AIR = Gas()


def diffusive_leak_rate(gas: Gas, p_a, p_b, u_c, Ly_over_Lx):
    """Molecules per second, compressible Newtonian flow (lambda << u_c), eq (13)."""
    return Ly_over_Lx * (p_a * p_a - p_b * p_b) * u_c ** 3 / (24.0 * gas.kT_J * gas.viscosity_Pa_s)


def ballistic_leak_rate(gas: Gas, p_a, p_b, u_c, Ly_over_Lx):
    """Molecules per second, Knudsen flow (lambda >> u_c), eq (17)."""
    return 0.5 * Ly_over_Lx * (p_a - p_b) / gas.kT_J * gas.mean_speed_m_s * u_c * u_c


def average_mean_free_path(gas: Gas, p_a, p_b):
    """<lambda> = (n_a lambda_a + n_b lambda_b) / (2 (n_a + n_b)), eq (20).

    n lambda is independent of density (eq 12), so <lambda> = n lambda / (n_a + n_b)
    = lambda_a p_a / (p_a + p_b).
    """
    return gas.n_lambda_per_m2 * gas.kT_J / (p_a + p_b)


def interpolated_leak_rate(gas: Gas, p_a, p_b, u_c, Ly_over_Lx):
    """Molecules per second, eq (19): eq (13) times (1 + xi <lambda>/u_c), xi = 32/pi.

    Tends to eq (17) for <lambda> >> u_c and to eq (13) for <lambda> << u_c. u_c = 0 gives 0.
    """
    return Ly_over_Lx * leak_rate_function(gas, p_a, p_b, u_c)


def leak_rate_function(gas: Gas, p_a, p_b, u_c):
    """Square-unit leak rate f(p, p_a, p_b) of eq (23), molecules per second."""
    lam = average_mean_free_path(gas, p_a, p_b)
    diffusive = (p_a * p_a - p_b * p_b) / (24.0 * gas.kT_J * gas.viscosity_Pa_s)
    return diffusive * (u_c ** 3 + XI * lam * u_c * u_c)


def ballistic_share(gas: Gas, p_a, p_b, u_c):
    """Fraction of eq (19)'s flow carried by its ballistic term: x/(1+x), x = xi <lambda>/u_c."""
    x = XI * average_mean_free_path(gas, p_a, p_b)
    return x / (x + u_c)


def liquid_volume_rate(viscosity_Pa_s, p_a, p_b, u_c, Ly_over_Lx):
    """Volume per second of an incompressible liquid filling the cavity, eq (24).

    It is eq (13) divided by the mean number density (p_a + p_b) / (2 kT): the incompressible
    limit of the same lubrication flow.
    """
    return Ly_over_Lx * u_c ** 3 * (p_a - p_b) / (12.0 * viscosity_Pa_s)
