"""The coupled route's model from typed options: an FEM suction table (`cupcheck suction`), the
cup it was built for, and the reduced model's gas, interface and relaxation."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from reduced.design import CupShape, recorded_design

__all__ = ["CoupledOptions", "coupled_model"]


@dataclass(frozen=True)
class CoupledOptions:
    """What the coupled route needs besides u_c (units in the names).

    suction_table: the table's JSON file; cup, geometry_file, r_start_mm: the cup as
    `validation.bridge.design.resolve_cup` reads them (the table's recorded design wins); interface: the
    gas pressure next to the seal ("linear", "p_b", "p_a"); kappa: the stiffness factor;
    relaxation: a `reduced.viscoelastic.RelaxationModulus` or None; phi0_s: the measurement's
    contact time (None: the cup's default, with relaxation only).
    """

    suction_table: Path
    cup: str | None = None
    geometry_file: Path | None = None
    r_start_mm: float | None = None
    interface: str = "linear"
    kappa: float = 1.0
    T_K: float = 293.15
    p_a_Pa: float = 1e5
    relaxation: Any = None
    phi0_s: float | None = None


@dataclass(frozen=True)
class _TableDesign:
    """What `validation.bridge.design.resolve_cup` reads of a curve: the recorded design and h1."""

    design: CupShape | None
    h1_m: float

    def has(self, name: str) -> bool:
        """No column of a stiffness curve: the table's r, V, l replace eq (5)'s l0, l1."""
        return False


def coupled_model(options: CoupledOptions, uc: Callable[[float], float]):
    """(the `reduced.LeakageModel` of the coupled route, the `CupChoice`, the cup's description
    for the outputs); ValueError on a table or cup that does not fit."""
    from reduced.gas import Gas
    from reduced.lifetime import LeakageModel
    from reduced.suction_table import SuctionTable
    from reduced.viscoelastic import measurement_contact_time
    from validation.bridge.design import resolve_cup

    table = SuctionTable.from_json(options.suction_table)
    h1 = table.h1_m
    recorded = _TableDesign(recorded_design(table.provenance), h1)
    choice = resolve_cup(recorded if recorded.design is not None else None, cup=options.cup,
                         geometry_file=options.geometry_file, r_start_mm=options.r_start_mm,
                         curve_label=f"'{options.suction_table}'", laws="curve")
    cup = choice.cup
    u_start = (h1 if math.isfinite(h1) else cup.h1_m) - cup.h_start_m
    relaxation = options.relaxation
    phi0 = None if relaxation is None else (
        options.phi0_s if options.phi0_s is not None else measurement_contact_time(cup))
    model = LeakageModel(cup=cup, suction=table, u_c=uc, gas=Gas(T_K=options.T_K), p_a_Pa=options.p_a_Pa,
                         kappa=options.kappa, interface=options.interface, relaxation=relaxation,
                         phi0_s=phi0, label=choice.label)
    description = {**choice.describe(), "route": "coupled", "u_start_mm": 1e3 * u_start,
                   "interface": options.interface, "suction_table": str(options.suction_table),
                   **({} if relaxation is None else {"relaxation": relaxation.provenance, "phi0_s": phi0})}
    return model, choice, description
