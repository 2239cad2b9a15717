"""Section 2: the rigid-cone laws, eqs (3)-(5), against the FEM's r_c(h), V(h) and l(h).

At the same plate height h = h1 - u, the FEM's inner contact radius r_c, its enclosed cavity
volume V and its strip width l (the force-quartile width of the sealing strip, `fem.cup`) are
compared with r = r0 (1 + h/h0) (eq 3), V = V0 [(r/r0)^3 - 1] (eq 4, at the cone's r) and
l = l0 + l_a (1 - r/r0) (eq 5 with Table 1's l0, l1, at the cone's r). Samples: u/h1 = 0.25 ... 0.9, where a contact strip exists (before
that only the rim corner touches, r_c = r1 and l -> 0 with the mesh).
"""

from __future__ import annotations

import numpy as np

from reduced.cup import cup_by_name
from validation.crosscheck.context import CROSSCHECK_FIDELITY, Context
from validation.crosscheck.report import new_figure
from validation.crosscheck.runs import FemRun

NAME = "cone_laws"
TITLE = "2. Rigid-cone laws (3)-(5) against the FEM"

CONTACTS = ("frictionless", "sticking")
U_OVER_H1 = np.round(np.linspace(0.25, 0.9, 27), 4)


def requests(quick: bool) -> tuple[FemRun, ...]:
    cups = ("A",) if quick else ("A", "B")
    return tuple(FemRun(cup=c, contact=k, fidelity=CROSSCHECK_FIDELITY) for c in cups for k in CONTACTS)


def cone_laws(cup_name: str, h_m: np.ndarray) -> dict[str, np.ndarray]:
    """r (eq 3), V (eq 4) and l (eq 5) of the Table 1 cup at heights h [m]."""
    cup = cup_by_name(cup_name)
    r = np.array([cup.radius(h) for h in h_m])
    return {"r": r, "V": np.array([cup.volume(x) for x in r]), "l": np.array([cup.contact_width(x) for x in r])}


def run(ctx: Context) -> None:
    rep = ctx.report
    rep.text(NAME, __doc__.split("\n\n", 1)[1])
    cups = ("A",) if ctx.quick else ("A", "B")
    rows, plots = [], []
    for cup in cups:
        for contact in CONTACTS:
            res = ctx.fem(FemRun(cup=cup, contact=contact, fidelity=CROSSCHECK_FIDELITY))
            u = U_OVER_H1 * res.h1_m
            h = res.h1_m - u
            law = cone_laws(cup, h)
            fem = {"r": res.r_c_at(u), "V": res.V_at(u), "l": res.l_at(u)}
            dev = {k: fem[k] / law[k] - 1.0 for k in law}
            i_mid = int(np.argmin(np.abs(law["r"] - cup_by_name(cup).r_start_m)))
            for k, unit in (("r", "r_c"), ("V", "V"), ("l", "l")):
                j = int(np.argmax(np.abs(dev[k])))
                rows.append([cup, contact, unit, float(dev[k][i_mid]), float(dev[k][j]),
                             float(U_OVER_H1[j])])
            plots.append((cup, contact, h, law, fem))
    rep.table(NAME, "cone_laws_deviation",
              ["cup", "contact", "quantity", "rel_dev_at_r_start", "largest_rel_dev", "at_u_over_h1"], rows,
              "FEM / cone law - 1 (r_start = 12 mm on the cone; u/h1 in [0.25, 0.9])")
    _figure(ctx, plots)
    worst = {q: max(abs(r[4]) for r in rows if r[2] == q and r[0] == "A") for q in ("r_c", "V", "l")}
    at_start = {q: [r[3] for r in rows if r[2] == q and r[0] == "A"] for q in ("r_c", "V", "l")}
    rep.summary["cone_laws_cupA_largest_rel_dev"] = worst
    rep.summary["cone_laws_cupA_rel_dev_at_r_start"] = {
        q: dict(zip(CONTACTS, v)) for q, v in at_start.items()}


def _figure(ctx: Context, plots) -> None:
    fig, ax = new_figure(3, 1, 4.3, 3.6)
    for cup, contact, h, law, fem in plots:
        style = "-" if contact == "sticking" else "--"
        for a, k, scale in zip(ax[0], ("r", "V", "l"), (1e3, 1e9, 1e3)):
            line, = a.plot(1e3 * h, scale * fem[k], style, label=f"FEM cup {cup} {contact}")
            if contact == "sticking":
                a.plot(1e3 * h, scale * law[k], ":", color="k" if cup == "A" else "0.5",
                       label=f"cone law cup {cup}")
    for a, lab in zip(ax[0], ("inner contact radius r (mm)", "cavity volume V (mm$^3$)",
                              "strip width l (mm)")):
        a.set(xlabel="plate height h (mm)", ylabel=lab)
    ax[0][2].legend(fontsize=6)
    ctx.report.figure(NAME, "cone_laws", fig, "FEM r_c(h), V(h), l(h) against eqs (3)-(5)")
