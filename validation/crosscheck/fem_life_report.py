"""Section 8's tables, figure and prose from its FEM lives (`validation.crosscheck.fem_life`): the
lifetimes by route and contact law, the largest holdable forces, the seal radii under suction, and
a paragraph on whether friction explains the paper's ~88 N hold and its 80 N lifetimes."""

from __future__ import annotations

import math

import numpy as np

from validation.crosscheck.context import SURFACE, Context
from validation.crosscheck.report import new_figure

__all__ = ["write_section", "suction_radius_m"]


def suction_radius_m(force_N: float, dp_Pa: float) -> float:
    """The smallest radius [m] over which a pressure difference dp [Pa] holds `force_N` [N]
    (F = dp pi r^2: the suction's reach a hold needs at best)."""
    return math.sqrt(force_N / (math.pi * dp_Pa))


def write_section(ctx: Context, outcomes: dict, others: dict) -> None:
    """outcomes: (cup, law, mu, F1 or None) -> `LifeOutcome`; others: cup -> route -> (cells, largest)."""
    from validation.crosscheck import fem_life as fl

    laws = fl.QUICK_LAWS if ctx.quick else fl.LAWS
    forces = fl.QUICK_FORCES_N if ctx.quick else fl.FORCES_N
    _lifetime_table(ctx, outcomes, others, laws, forces)
    largest = _largest_table(ctx, outcomes, others, laws, forces)
    seal = _seal_table(ctx, outcomes, laws, forces)
    _seal_figure(ctx, outcomes, laws)
    _conclusion(ctx, outcomes, others, largest, seal, laws, forces)
    failed = [o for o in outcomes.values() if o.failed]
    ctx.report.summary[fl.NAME] = {
        "fidelity": fl.FIDELITY, "quick": ctx.quick,
        "largest_force_N": largest,
        "lifetime_s": {f"{k[0]} {_law(k[1], k[2])} {k[3]:g}N": o.lifetime_s for k, o in outcomes.items()
                       if k[3] is not None},
        "failed_runs": [o.run.label() + ": " + o.cell() for o in failed],
        "wall_s": sum(o.wall_s for o in outcomes.values() if math.isfinite(o.wall_s))}


def _law(law: str, mu: float | None) -> str:
    return f"mu {mu:g}" if law == "coulomb" else law


def _col(law: str, mu: float | None) -> str:
    return "fem_" + _law(law, mu).replace(" ", "_") + "_s"


def _lifetime_table(ctx, outcomes, others, laws, forces) -> None:
    from validation.crosscheck import fem_life as fl

    routes = list(next(iter(others.values())))
    rows = []
    for cup, Fs in forces.items():
        for i, F in enumerate(Fs):
            rows.append([cup, F] + [others[cup][r][0][i] for r in routes]
                        + [outcomes[(cup, law, mu, F)].cell() for law, mu in laws])
    cols = ["cup", "force_N"] + [f"{r}_s" for r in routes] + [_col(law, mu) for law, mu in laws]
    ctx.report.table(fl.NAME, "fem_life_lifetimes", cols, rows,
                     f"Lifetime [s] (reason) on {SURFACE}: paper route (the paper's inputs), table-coupled "
                     f"route (frictionless FEM suction table) and the fem route by contact law ({fl.FIDELITY} "
                     f"mesh)")


def _largest_table(ctx, outcomes, others, laws, forces) -> dict:
    from validation.crosscheck import fem_life as fl

    rows, largest = [], {}
    for cup in forces:
        for r, (_, held) in others[cup].items():
            rows.append([cup, r, "(see route)", held])
            largest.setdefault(cup, {})[r] = held
        for law, mu in laws:
            o = outcomes[(cup, law, mu, None)]
            rows.append([cup, "fem", _law(law, mu), o.largest_force_N if not o.failed else o.cell()])
            largest[cup][f"fem {_law(law, mu)}"] = o.largest_force_N
    ctx.report.table(fl.NAME, "fem_life_largest_force", ["cup", "route", "contact", "largest_force_N"], rows,
                     f"Largest force the freshly pressed and sealed cup holds (the paper's cup A held about "
                     f"{fl.PAPER_HOLD_N:g} N)")
    return largest


def _states(o) -> list[tuple[str, dict]]:
    """(state, radii and state) of one life: sealed, branch start, detachment (the branch's end)."""
    s = o.sealed
    out = [("sealed", {"r_c_mm": s.get("r_c_mm", math.nan), "r_k_mm": s.get("r_k_mm", math.nan),
                       "r_out_mm": s.get("r_out_mm", math.nan), "u_mm": s.get("u_mm", math.nan),
                       "p_b_kPa": s.get("p_b_kPa", math.nan), "N_over_N0": 1.0})]
    tr = o.trajectory
    if tr and len(tr.get("N", ())) and s.get("N0"):
        for name, k in (("branch start", 0), ("detachment", -1)):
            out.append((name, {"r_c_mm": tr["r_c_mm"][k], "r_k_mm": tr["seal_r_mm"][k],
                               "r_out_mm": tr["r_out_mm"][k], "u_mm": tr["u_mm"][k],
                               "p_b_kPa": 1e-3 * tr["p_b_Pa"][k], "N_over_N0": tr["N"][k] / s["N0"]}))
    return out


def _seal_table(ctx, outcomes, laws, forces) -> dict:
    from validation.crosscheck import fem_life as fl

    rows, seal = [], {}
    keys = ("r_c_mm", "r_k_mm", "r_out_mm", "u_mm", "p_b_kPa", "N_over_N0")
    for cup, Fs in forces.items():
        for F in (F for F in fl.SEAL_FORCES_N if F in Fs):
            for law, mu in laws:
                o = outcomes[(cup, law, mu, F)]
                states = _states(o)
                for name, v in states:
                    note = "" if len(states) > 1 else o.cell()
                    rows.append([cup, F, _law(law, mu), name, *[v[k] for k in keys], note])
                    seal.setdefault(cup, {}).setdefault(f"{F:g}N", {}).setdefault(_law(law, mu), {})[name] = v
    ctx.report.table(fl.NAME, "fem_life_seal", ["cup", "force_N", "contact", "state", *keys, "note"], rows,
                     "What friction does to the seal under suction: inner contact radius r_c, seal node r_k "
                     "and the contact's outer end r_out at the sealed state, at the branch's start (pulled "
                     "to F1 at N0) and at the detachment")
    return seal


def _seal_figure(ctx, outcomes, laws) -> None:
    from validation.crosscheck import fem_life as fl

    fig, ax = new_figure(2, 1, 4.2, 3.3)
    drawn = 0
    for law, mu in fl.FIGURE_LAWS:
        o = outcomes.get(("A", law, mu, fl.FIGURE_FORCE_N))
        if o is None or not o.trajectory or not len(o.trajectory.get("N", ())):
            continue
        x = o.trajectory["N"] / o.sealed["N0"]
        ax[0][0].plot(x, o.trajectory["r_c_mm"], "o-", ms=2.5, label=_law(law, mu))
        ax[0][1].plot(x, o.trajectory["r_out_mm"], "o-", ms=2.5, label=_law(law, mu))
        drawn += 1
    for a, what in zip(ax[0], ("inner contact radius r_c", "outer end of contact r_out")):
        a.set(xlabel="N / N0 (gas in the cavity)", ylabel=f"{what.split()[-1]} (mm)",
              title=f"cup A, F1 = {fl.FIGURE_FORCE_N:g} N: {what}")
        if drawn:
            a.legend(fontsize=7)
    ctx.report.figure(fl.NAME, "fem_life_seal", fig,
                      f"Cup A held at {fl.FIGURE_FORCE_N:g} N on the fem route: the seal's radii along the "
                      f"branch, from the branch's start to the detachment, by contact law")


def _conclusion(ctx, outcomes, others, largest, seal, laws, forces) -> None:
    """The paragraph on the paper's ~88 N hold and its 80 N lifetimes, from the tables' numbers."""
    from validation.crosscheck import fem_life as fl

    if "A" not in largest:
        return
    held = {k[4:]: v for k, v in largest["A"].items() if k.startswith("fem ") and math.isfinite(v)}
    parts = []
    if held:
        best = max(held, key=held.get)
        listing = ", ".join(f"{k} {v:.3g} N" for k, v in held.items())
        r_need = 1e3 * suction_radius_m(fl.PAPER_HOLD_N, fl.P_A_PA)
        if held[best] >= fl.PAPER_HOLD_N:
            parts.append(f"**Friction does explain the paper's ~{fl.PAPER_HOLD_N:g} N hold of cup A**: with "
                         f"{best} the sealed FEM cup holds {held[best]:.3g} N ({listing}).")
        else:
            stick = held.get("sticking")
            parts.append(f"**Friction does not explain the paper's ~{fl.PAPER_HOLD_N:g} N hold of cup A.** "
                         f"The sealed FEM cup holds at most {held[best]:.3g} N ({best}; by law: {listing}), "
                         f"{100 * held[best] / fl.PAPER_HOLD_N:.0f} % of it"
                         + (f"; sticking, friction's mu -> inf limit, holds {stick:.3g} N, so no friction "
                            f"coefficient makes it hold {fl.PAPER_HOLD_N:g} N." if stick is not None else "."))
        for route in ("paper", "coupled"):
            if route in largest["A"] and math.isfinite(largest["A"][route]):
                parts.append(f"The {route} route holds {largest['A'][route]:.3g} N.")
        parts.append(f"Even a full vacuum (p_a = {fl.P_A_PA / 1e3:g} kPa) holds {fl.PAPER_HOLD_N:g} N only over a "
                     f"disc of radius r >= {r_need:.3g} mm (F = dp pi r^2); " + _reach(seal))
    if 80.0 in forces.get("A", ()):
        lives = {_law(law, mu): outcomes[("A", law, mu, 80.0)] for law, mu in laws}
        ok = [f"{k} {o.cell()}" for k, o in lives.items() if not o.failed and o.lifetime_s > 0]
        not_ok = [f"{k}: {o.cell()}" for k, o in lives.items() if o.failed or o.lifetime_s <= 0]
        paper80 = others["A"]["paper"][0][forces["A"].index(80.0)]
        parts.append(f"At 80 N the paper route gives {paper80}; the fem route gives "
                     + (f"a lifetime with {', '.join(ok)}" if ok else "no lifetime with any law")
                     + (f" ({'; '.join(not_ok)})." if not_ok else "."))
        if not ok:
            parts.append("The paper's 80 N lifetimes therefore rest on its own approximations (the rigid "
                         "cone of eqs 3-5, the force balance of eq 7 with beta), not on the FEM cup: to "
                         "reproduce them the model would need a seal that stays out at that radius under "
                         "suction, i.e. a cup whose wall is not pulled onto the plane and whose seal does "
                         "not move inwards (the real cup's wall, rim or the handle's load path), which no "
                         "contact law here provides.")
    ctx.report.text(fl.NAME, " ".join(parts))


def _reach(seal: dict) -> str:
    """How far out the FEM cup A's contact reaches at the sealed state and at detachment, by law."""
    for F in ("40N", "10N"):
        by_law = seal.get("A", {}).get(F)
        if not by_law:
            continue
        ends = {k: v["detachment"]["r_out_mm"] for k, v in by_law.items() if "detachment" in v}
        start = {k: v["sealed"]["r_out_mm"] for k, v in by_law.items()}
        if ends:
            lo, hi = min(ends.values()), max(ends.values())
            s = np.array([x for x in start.values() if math.isfinite(x)])
            return (f"cup A's contact reaches r_out = {s.min():.3g}-{s.max():.3g} mm when sealed and "
                    f"{lo:.3g}-{hi:.3g} mm at the detachment at {F[:-1]} N over the laws that detach "
                    f"({', '.join(f'{k} {v:.3g}' for k, v in ends.items())}; table above).")
    return "the seal table above gives the FEM cup's r_out."
