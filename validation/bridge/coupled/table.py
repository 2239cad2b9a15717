"""From the FEM's `SuctionGrid` to the reduced model's `SuctionTable`, and beta as the FEM sees it."""

from __future__ import annotations

from typing import Any

import numpy as np

from fem.interface import ContactLaw
from fem.suction import SuctionGrid, SuctionStates
from reduced.coupled_seal import seal_load
from reduced.stiffness_curve import profiles_from_lists
from reduced.suction_table import SuctionTable

__all__ = ["suction_table", "holed_suction_table", "fem_beta"]


def suction_table(grid: SuctionGrid, provenance: dict[str, Any] | None = None) -> SuctionTable:
    """The hand-off table of an FEM grid: F1, V, r_k, r_cut, the lumped nodal contact pressures
    and the lone nodes' ring loads (`_rings`) (provenance: the grid's law and mu, material, h1, solver, then `provenance`),
    converted as the stiffness sidecar's are (`profiles_from_lists`: a node shared by
    two facets merged, fewer than two points or no pressure is None). A state without a seal
    (`fem.suction`: no node of the cavity chain on the plane) is null in every grid and profile
    and False in `sealed`: its numbers are not those of a cup under suction; so is a state whose
    plane carries no pressure (the rim touching at zero force)."""
    prov = _provenance(grid.contact_law, grid.material, grid.h1_m, grid.stats, provenance)
    converted = [[None if p is None else profiles_from_lists([1e3 * p.r_m], [1e-3 * p.p_Pa])[0] for p in row]
                 for row in grid.profiles]
    # a state whose plane carries no pressure (the rim touching at zero force, u = 0 and dp = 0)
    # holds no seal either
    sealed = np.asarray(grid.sealed, dtype=bool) & np.array(
        [[p is not None for p in row] for row in converted]).reshape(np.shape(grid.sealed))
    cut = {name: np.where(sealed, getattr(grid, name), np.nan) for name in ("F1_N", "V_m3", "seal_r_m", "cut_r_m")}
    profiles = tuple(tuple(p if ok else None for p, ok in zip(row, sealed[i])) for i, row in enumerate(converted))
    rings = tuple(tuple(None if p is None else _rings(p, reactions) for p, reactions in zip(row, grid.reactions[i]))
                  for i, row in enumerate(profiles))
    return SuctionTable(u_m=grid.u_m, dp_Pa=grid.dp_Pa, **cut, profiles=profiles,
                        E_Pa=grid.material.E_Pa, provenance=prov, sealed=None if sealed.all() else sealed,
                        seal_rings=rings)


def fem_beta(table: SuctionTable) -> np.ndarray:
    """Eq (6)'s beta as the FEM sees it, [len(u), len(dp) - 1]: the extra contact force the
    suction puts on the contact at fixed u, per unit dp and per area of the sealing strip
    2 pi r_k l, with l the strip's force-quartile width without suction (`fem.postprocess`);
    N = dp pi r_k^2 - F1 is the contact force with the interface outside the seal at ambient
    pressure (`fem.suction`). nan where the unsucked cup resolves no strip."""
    from fem.postprocess import quartile_width

    N = table.dp_Pa * np.pi * table.seal_r_m**2 - table.F1_N
    l = np.array([quartile_width(p.r_m, p.p_Pa) if p is not None else np.nan
                  for p in (row[0] for row in table.profiles)])
    area = 2 * np.pi * table.seal_r_m[:, 0] * np.where(l > 0, l, np.nan)
    return (N[:, 1:] - N[:, :1]) / (table.dp_Pa[1:] * area[:, None])


def holed_suction_table(states: SuctionStates, u_m: np.ndarray, dp_Pa: np.ndarray, built: np.ndarray,
                        contact: ContactLaw, provenance: dict[str, Any] | None = None,
                        converted: dict | None = None) -> SuctionTable:
    """The hand-off table (as `suction_table`) on the grid u_m x dp_Pa with only the states
    `built` [len(u), len(dp)] (solved by `states`, whose contact law is `contact`, pressed rows in
    increasing u and dp, raised rows (u <= 0) in decreasing u, where it lacks them), nan and None
    at the others: a table with holes (`reduced.suction_table`); a state without a seal as in
    `suction_table`, and so is a raised state no raise reaches (the wall folds onto itself, or
    Newton fails: no cup state is there, a path reaching it has let go; the provenance's
    `unreached` says how many and why). `converted`: a dict of the states' hand-off values by
    (u, dp), read and filled here, that the tables of a growing build share (each state is
    converted once)."""
    shape = (len(u_m), len(dp_Pa))
    grids = {name: np.full(shape, np.nan) for name in ("F1_N", "V_m3", "seal_r_m", "cut_r_m")}
    profiles = [[None] * shape[1] for _ in range(shape[0])]
    rings = [[None] * shape[1] for _ in range(shape[0])]
    sealed = np.ones(shape, dtype=bool)
    nodes = sorted(zip(*np.nonzero(built)), key=lambda n: (u_m[n[0]] <= 0, abs(u_m[n[0]]), n[1]))
    converted = {} if converted is None else converted
    for i, j in nodes:
        key = (float(u_m[i]), float(dp_Pa[j]))
        if key not in converted:
            converted[key] = _handed_off(states.state(*key))
        values = converted[key]
        if values is None:
            sealed[i, j] = False
            continue
        for name, x in zip(grids, values[:4]):
            grids[name][i, j] = x
        profiles[i][j], rings[i][j] = values[4:]
    prov = _provenance(contact, states.material, states.h1_m, states.stats, provenance)
    if states.unreached:
        prov["unreached"] = _unreached(states.unreached)
    return SuctionTable(u_m=np.asarray(u_m, float), dp_Pa=np.asarray(dp_Pa, float), **grids,
                        profiles=tuple(tuple(row) for row in profiles), E_Pa=states.material.E_Pa,
                        provenance=prov, sealed=None if sealed.all() else sealed,
                        seal_rings=tuple(tuple(row) for row in rings))


def _handed_off(state: tuple) -> tuple | None:
    """(F1, V, r_k, r_cut, profile, ring loads) of a state (`fem.suction.SuctionStates.state`) as
    the table holds them, None for one without a seal."""
    F1, _, V, r_k, r_cut, _, _, p, closed, reactions = state
    profile = profiles_from_lists([1e3 * p.r_m], [1e-3 * p.p_Pa])[0] if closed else None
    return None if profile is None else (F1, V, r_k, r_cut, profile, _rings(profile, reactions))


def _unreached(unreached: dict) -> dict:
    """The provenance of the raised states no raise reached (`fem.suction.SuctionStates._raised`):
    how many, the highest u among them and the first one's cause."""
    (u, dp), cause = max(unreached.items(), key=lambda item: item[0])
    return {"states": len(unreached), "highest_u_mm": 1e3 * u, "cause": f"at dp = {dp / 1e3:.4g} kPa: {cause}"}


def _rings(profile, reactions: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The ring loads (r [m], F [N]) of the profile's lone nodes from the plane's reactions, read as
    the fem route reads them (`reduced.coupled_seal.seal_load`)."""
    load = seal_load(profile.r_m, profile.p_Pa, *reactions)
    return load.rings_r_m, load.rings_F_N


def _provenance(law: ContactLaw, material, h1_m: float, stats, extra: dict[str, Any] | None) -> dict[str, Any]:
    from validation.bridge.handoff import contact_provenance

    return {"source": "fem.suction", **contact_provenance(law), "E_Pa": material.E_Pa, "nu": material.nu,
            "formulation": material.formulation, "h1_mm": 1e3 * h1_m,
            "solver": {"newton_iterations": stats.newton_iterations if stats else 0,
                       "wall_time_s": stats.wall_time_s if stats else 0.0, "dofs": stats.dofs if stats else 0},
            **(extra or {})}
