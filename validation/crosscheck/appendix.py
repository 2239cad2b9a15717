"""Section 1: Appendix A against the FEM, F0(u) for cups A and B and a sweep over alpha and d0.

Appendix A flattens the cone with no slip (each radial segment dx becomes dx cos(alpha) on the
substrate): its energy is pure radial compression, E eps^2/2 with eps = 1 - cos(alpha). It is
compared with two readings of the thickness:

* ``paper``: d0 = 2 mm at x0 = r0, d1 = 0 at x1 = r1, the paper's worked example (2.5 N/mm);
* ``geometry``: d0, d1 of the FEM's own thickness line at r0 and r1 (like with like). With d1 > 0
  the closed form has F0(0) = pi (1-cos a)^2 (cos a/sin a) E x1 d1 > 0: flattening the first
  rim segment costs energy in proportion to u, so the force jumps at u = 0.
"""

from __future__ import annotations

import math

import numpy as np

from reduced.appendix_a import appendix_a_force, appendix_a_small_u_slope
from validation.crosscheck.context import CROSSCHECK_FIDELITY, Context
from validation.crosscheck.report import new_figure
from validation.crosscheck.runs import FemRun

NAME = "appendix"
TITLE = "1. Appendix A against the FEM"

CONTACTS = ("frictionless", "sticking")
SWEEP_ALPHA_DEG = (10.0, 20.0, 33.0, 45.0, 60.0)
SWEEP_D0_MM = (0.5, 1.0, 2.0, 4.0)
U_OVER_H1 = np.round(np.linspace(0.02, 0.9, 45), 4)
WITHIN = 0.2          # the 20 %
E_PA, D0_PAPER_M, R0_M, R1_M = 4e6, 2e-3, 5e-3, 19e-3


def requests(quick: bool) -> tuple[FemRun, ...]:
    cups = ("A",) if quick else ("A", "B")
    runs = [FemRun(cup=c, contact=k, fidelity=CROSSCHECK_FIDELITY) for c in cups for k in CONTACTS]
    if not quick:
        runs += [FemRun(cup="A", contact=k, alpha_deg=a, d_root_mm=d)
                 for a in SWEEP_ALPHA_DEG for d in SWEEP_D0_MM for k in CONTACTS]
    return tuple(runs)


def appendix_a(u_m, alpha_deg: float, reading: str, request: FemRun | None = None):
    """Appendix A's F0(u) [N] with the 'paper' (d0 = 2 mm, d1 = 0) or 'geometry' thickness reading."""
    if reading == "paper":
        d0, d1 = D0_PAPER_M, 0.0
    else:
        d0, d1 = request.thickness_at_ends_m()
    return appendix_a_force(u_m, alpha_deg, E_PA, d0, R0_M, R1_M, d1)


def within_intervals(x: np.ndarray, ratio: np.ndarray, tol: float = WITHIN) -> str:
    """The x intervals where |ratio - 1| <= tol, as text ('none' if empty)."""
    ok = np.abs(ratio - 1.0) <= tol
    spans, start = [], None
    for i, flag in enumerate(ok):
        if flag and start is None:
            start = i
        if (not flag or i == len(ok) - 1) and start is not None:
            end = i if flag else i - 1
            spans.append(f"{x[start]:.2f}-{x[end]:.2f}")
            start = None
    return ", ".join(spans) if spans else "none"


def secant_N_per_mm(F0_at_1mm: float) -> float:
    return float(F0_at_1mm)          # F0(1 mm) / 1 mm


def run(ctx: Context) -> None:
    rep, S = ctx.report, NAME
    rep.text(S, __doc__.split("\n\n", 1)[1])
    cups = ("A",) if ctx.quick else ("A", "B")
    rows, curves = [], {}
    for cup in cups:
        for contact in CONTACTS:
            req = FemRun(cup=cup, contact=contact, fidelity=CROSSCHECK_FIDELITY)
            res = ctx.fem(req)
            alpha = req.geometry().alpha_deg
            u = U_OVER_H1 * res.h1_m
            F = res.F0_at(u)
            for reading in ("paper", "geometry"):
                ratio = F / appendix_a(u, alpha, reading, req)
                curves[(cup, contact, reading)] = (U_OVER_H1, ratio)
                rows.append([cup, contact, reading, float(np.interp(0.1, U_OVER_H1, ratio)),
                             float(np.interp(0.5, U_OVER_H1, ratio)), float(np.interp(0.9, U_OVER_H1, ratio)),
                             within_intervals(U_OVER_H1, ratio)])
    rep.table(S, "appendix_a_ratio", ["cup", "contact", "appendix_a_reading", "ratio_at_u_0.1h1",
                                      "ratio_at_u_0.5h1", "ratio_at_u_0.9h1", "u_over_h1_within_20pct"],
              rows, "FEM / Appendix A over u (coarse mesh)")

    # the headline: cup A small-u stiffness, F0(1 mm) / 1 mm
    reqA = {k: FemRun(cup="A", contact=k, fidelity=CROSSCHECK_FIDELITY) for k in CONTACTS}
    fem_slope = {k: float(ctx.fem(r).F0_at(1e-3)) for k, r in reqA.items()}
    tangent = appendix_a_small_u_slope(33.0, E_PA, D0_PAPER_M, R0_M, R1_M) * 1e-3
    sec_paper = float(appendix_a(1e-3, 33.0, "paper"))
    sec_geom = float(appendix_a(1e-3, 33.0, "geometry", reqA["sticking"]))
    F00_geom = float(appendix_a(0.0, 33.0, "geometry", reqA["sticking"]))
    rows = [["FEM frictionless", fem_slope["frictionless"], "secant F0(1 mm)/1 mm"],
            ["FEM sticking", fem_slope["sticking"], "secant F0(1 mm)/1 mm"],
            ["Appendix A, paper reading (d0 2 mm, d1 0)", tangent, "tangent at u = 0 (closed form)"],
            ["Appendix A, paper reading (d0 2 mm, d1 0)", sec_paper, "secant F0(1 mm)/1 mm"],
            ["Appendix A, FEM thickness line (d0 2.5, d1 0.447 mm)", sec_geom,
             f"secant F0(1 mm)/1 mm (includes F0(0) = {F00_geom:.3g} N)"]]
    rep.table(S, "cupA_small_u_stiffness", ["model", "stiffness_N_per_mm", "definition"], rows,
              "Cup A small-u stiffness (E = 4 MPa, nu = 0.49)")
    rep.summary.update({
        "appendix_a_slope_N_per_mm": tangent,
        "appendix_a_secant_1mm_N_per_mm": sec_paper,
        "appendix_a_geometry_secant_1mm_N_per_mm": sec_geom,
        "fem_slope_frictionless_N_per_mm": fem_slope["frictionless"],
        "fem_slope_sticking_N_per_mm": fem_slope["sticking"],
        "slope_definitions": "appendix_a_slope_N_per_mm: closed-form small-u tangent, d0 = 2 mm, d1 = 0, "
                             "x0 = r0, x1 = r1, E = 4 MPa (the paper's 2.5 N/mm); fem_slope_*: F0(1 mm)/1 mm "
                             "of cup A, coarse mesh, E = 4 MPa, nu = 0.49, thickness normal to the wall",
    })
    _figure(ctx, curves, cups)
    if not ctx.quick:
        _sweep(ctx)
    rep.text(S, _discussion(fem_slope, tangent, sec_geom))


def _figure(ctx: Context, curves, cups) -> None:
    fig, ax = new_figure(2, 1, 5.2, 3.8)
    for (cup, contact, reading), (x, ratio) in curves.items():
        a = ax[0][0 if reading == "paper" else 1]
        a.plot(x, ratio, ("-" if contact == "sticking" else "--") + ("" if cup == "A" else "."),
               label=f"cup {cup}, {contact}")
    for a, reading in zip(ax[0], ("paper reading d0 = 2 mm, d1 = 0", "FEM's thickness line")):
        a.axhspan(1 - WITHIN, 1 + WITHIN, color="0.9")
        a.set(xlabel="u / h1", ylabel="F0 FEM / F0 Appendix A", yscale="log",
              title=f"Appendix A, {reading}")
        a.legend(fontsize=7)
    ctx.report.figure(NAME, "appendix_a_ratio", fig, "FEM / Appendix A over u; grey: within 20 %")


def _sweep(ctx: Context) -> None:
    rows = []
    for alpha in SWEEP_ALPHA_DEG:
        for d0 in SWEEP_D0_MM:
            row = [alpha, d0]
            for contact in CONTACTS:
                req = FemRun(cup="A", contact=contact, alpha_deg=alpha, d_root_mm=d0)
                out = ctx.outcome(req)
                if isinstance(out, Exception):
                    row += [math.nan, math.nan, f"failed: {str(out).splitlines()[0][:80]}"]
                    continue
                u = U_OVER_H1 * out.h1_m
                ratio = out.F0_at(u) / appendix_a(u, alpha, "geometry", req)
                row += [float(np.interp(0.1, U_OVER_H1, ratio)), float(np.interp(0.5, U_OVER_H1, ratio)),
                        within_intervals(U_OVER_H1, ratio)]
            rows.append(row)
    ctx.report.table(NAME, "appendix_a_sweep",
                     ["alpha_deg", "d0_mm", "frictionless_ratio_0.1h1", "frictionless_ratio_0.5h1",
                      "frictionless_u_over_h1_within_20pct", "sticking_ratio_0.1h1", "sticking_ratio_0.5h1",
                      "sticking_u_over_h1_within_20pct"], rows,
                     "Sweep at r0 = 5, r1 = 19 mm: FEM / Appendix A (FEM's thickness line, cup A's taper "
                     "scaled to d0)")


def _discussion(fem_slope, tangent, sec_geom) -> str:
    return f"""
**Reading.** Appendix A assumes no slip, so it corresponds to the *sticking* FEM: a point of the wall
that touches the substrate stays there, and flattening the cone must compress it radially by
1 - cos(alpha). With frictionless contact the wall slides outwards instead of being compressed, and
what remains is bending and hoop strain of the free part. Cup A's small-u stiffness F0(1 mm)/1 mm:
{fem_slope['frictionless']:.3g} N/mm frictionless, {fem_slope['sticking']:.3g} N/mm sticking; Appendix A
{tangent:.3g} N/mm as the paper reads it (d0 = 2 mm, tangent at u = 0), {sec_geom:.3g} N/mm with the
FEM's own thickness line (secant, including the force jump at u = 0). Appendix A neglects bending and
the strain of the part not yet in contact, and it strains the whole flattened volume uniformly.
Implication for the paper's measurements (Sec. 5.3; the figures' data are not in the source, so this
is a prediction, not a comparison): the dry curve (~2.5 N/mm, matched by Appendix A in the paper) must
lie between the frictionless and the sticking FEM, since dry PVC on glass is neither free nor fully
stuck; the soap-water-lubricated and silanized curves (which the paper says are alike) should approach
the frictionless FEM, i.e. be several times softer than the dry curve at small u. The measured 2.5 N/mm
therefore does not confirm Appendix A's mechanism: it sits between two FEM limits that differ by a
factor of {fem_slope['sticking'] / fem_slope['frictionless']:.2g}.
"""
