"""Section 7: Coulomb friction between the two limits (issue 14).

Cups A and B pressed onto the plane with Coulomb friction (`fem.contact`, law "coulomb": a touching
node sticks while |t| <= mu lambda and slides with t = -mu lambda sign(slip) otherwise, one
backward-Euler increment per load step) for mu = 0, 0.1, 0.3, 0.5, 1, 2, beside the frictionless
law and the sticking law (mu = inf), on the default (medium) mesh, to 0.9 h1 with load steps of
at most 0.05 u_max (the cross-check runs' sampling). F0 at fixed u need not be monotone in mu at
large u (the path differs: where the wall lands, which part buckles); the table says where it is.

The mu matching the paper's dry small-u stiffness: k(mu) = F0(1 mm) / 1 mm of cup A from runs to
u = 1 mm (load steps <= 0.05 mm), first on the grid of mu above, then by bisection in the bracket
that crosses 2.5 N/mm down to a bracket width of 0.5 % of mu. If k is continuous there, the matching
mu is read off linearly; if k jumps across 2.5 N/mm inside the final bracket (a jump larger than
5 % of 2.5 N/mm), no mu matches, and the bracket's two ends are reported and both are followed
to 0.9 h1: their F0, r_c(h) and l(h), and the lifetime of cup A on pmma-1.89 in the reference
conventions of section 3 (F0 with the cone laws (3)-(5), and F0 with the FEM's own r_c, V, l, l
from eq (5) at the FEM's r_c where the FEM resolves no strip).
"""

from __future__ import annotations

import math

import numpy as np

from validation.crosscheck.context import SURFACE, Context, pmma_uc_table
from validation.crosscheck.report import new_figure
from validation.crosscheck.runs import FemResult, FemRun

NAME = "friction"
TITLE = "7. Coulomb friction between the limits"

MUS = (0.0, 0.1, 0.3, 0.5, 1.0, 2.0)
QUICK_MUS = (0.0, 1.5)
FIDELITY = "medium"               # the default level of `cupcheck stiffness`
QUICK_FIDELITY = "coarse"
PAPER_DRY_N_PER_MM = 2.5          # Appendix A's worked example, the paper's dry measurement
U_SMALL_M = 1e-3
SAMPLE_U_OVER_H1 = (0.3, 0.5, 0.7, 0.9)   # F0 sampled there and at u = 1 mm
MU_REL_TOL, QUICK_MU_REL_TOL = 5e-3, 0.25
JUMP = 0.05                       # a jump of k inside the final bracket, relative to 2.5 N/mm
FORCES_N = (5.0, 10.0, 20.0, 40.0, 60.0, 80.0)
QUICK_FORCES_N = (10.0, 40.0)
U_OVER_H1 = (0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9)


def _setup(quick: bool) -> tuple[tuple[str, ...], tuple[float, ...], str]:
    return (("A",), QUICK_MUS, QUICK_FIDELITY) if quick else (("A", "B"), MUS, FIDELITY)


def law_run(cup: str, mu: float | None, fidelity: str, u_max_over_h1: float = 0.9) -> FemRun:
    """mu None: the sticking law (mu = inf); a number: Coulomb with that mu."""
    if mu is None:
        return FemRun(cup=cup, contact="sticking", fidelity=fidelity, u_max_over_h1=u_max_over_h1)
    return FemRun(cup=cup, contact="coulomb", friction=float(mu), fidelity=fidelity,
                  u_max_over_h1=u_max_over_h1)


def requests(quick: bool) -> tuple[FemRun, ...]:
    cups, mus, fid = _setup(quick)
    runs = [FemRun(cup=c, contact="frictionless", fidelity=fid) for c in cups]
    runs += [law_run(c, m, fid) for c in cups for m in (*mus, None)]
    return tuple(runs)


def _mu_text(mu: float | None) -> str:
    return "inf (sticking)" if mu is None else f"{mu:g}"


def small_u_stiffness(ctx: Context, mu: float | None, fidelity: str) -> float:
    """k = F0(1 mm) / 1 mm [N/mm] of cup A from a run to u = 1 mm (raises the run's failure)."""
    h1 = FemRun(cup="A").geometry().h1_m
    res = ctx.fem(law_run("A", mu, fidelity, U_SMALL_M / h1))
    return float(res.F0_N[-1]) / (1e3 * float(res.u_m[-1]))


def matching_mu(ctx: Context, mus, fidelity: str, rel_tol: float) -> dict:
    """The bracket of mu where k(mu) crosses the paper's 2.5 N/mm (module docstring)."""
    grid = [(m, small_u_stiffness(ctx, m, fidelity)) for m in mus]
    out = {"grid": grid, "target_N_per_mm": PAPER_DRY_N_PER_MM}
    pairs = [(a, b) for a, b in zip(grid, grid[1:]) if a[1] < PAPER_DRY_N_PER_MM <= b[1]]
    if not pairs:
        out["found"] = False
        return out
    (lo, k_lo), (hi, k_hi) = pairs[0]
    while hi - lo > rel_tol * hi:
        mid = 0.5 * (lo + hi)
        k = small_u_stiffness(ctx, mid, fidelity)
        (lo, k_lo), (hi, k_hi) = ((mid, k), (hi, k_hi)) if k < PAPER_DRY_N_PER_MM else ((lo, k_lo), (mid, k))
    jump = k_hi - k_lo > JUMP * PAPER_DRY_N_PER_MM
    mu = math.nan if jump else lo + (hi - lo) * (PAPER_DRY_N_PER_MM - k_lo) / (k_hi - k_lo)
    out.update(found=True, lo=lo, hi=hi, k_lo=k_lo, k_hi=k_hi, jump=jump, mu=mu)
    return out


def run(ctx: Context) -> None:
    rep = ctx.report
    rep.text(NAME, __doc__.split("\n\n", 1)[1])
    cups, mus, fid = _setup(ctx.quick)
    curves = {c: {m: ctx.outcome(law_run(c, m, fid)) for m in (*mus, None)} for c in cups}
    free = {c: ctx.outcome(FemRun(cup=c, contact="frictionless", fidelity=fid)) for c in cups}
    _curve_table(ctx, curves, free, fid)
    _figure_curves(ctx, curves, free, fid)
    match = matching_mu(ctx, mus, fid, QUICK_MU_REL_TOL if ctx.quick else MU_REL_TOL)
    _report_match(ctx, match, fid)
    if match["found"]:
        ends = ("hi",) if ctx.quick else ("lo", "hi")       # --quick: the sticking end only
        laws = {"mu 0": 0.0, **{f"mu {match[e]:.4g}": match[e] for e in ends}, "sticking": None}
        if not match["jump"]:
            laws = {"mu 0": 0.0, f"mu {match['mu']:.4g}": match["mu"], "sticking": None}
        runs = {k: ctx.outcome(law_run("A", m, fid)) for k, m in laws.items()}
        runs = {k: v for k, v in runs.items() if not isinstance(v, Exception)}
        _geometry_table(ctx, runs)
        _lifetimes(ctx, runs)


def _curve_table(ctx: Context, curves, free, fid: str) -> None:
    rows, summary = [], {}
    blank = [math.nan] * (len(SAMPLE_U_OVER_H1) + 3)
    for cup, by_mu in curves.items():
        ok = {m: r for m, r in by_mu.items() if not isinstance(r, Exception)}
        stick = ok.get(None)
        for m, r in by_mu.items():
            if isinstance(r, Exception):
                rows.append([cup, _mu_text(m), "failed", math.nan, math.nan, 0, *blank,
                             str(r).splitlines()[0][:500]])
                continue
            F = [_at(r, u) for u in _samples(r.h1_m)]
            excess = 0.0 if r.cone_excess is None else float(np.max(r.cone_excess))
            ratio = r.wall_s / stick.wall_s if stick is not None else math.nan
            rows.append([cup, _mu_text(m), "converged", r.wall_s, ratio, r.newton_iterations, *F,
                         F[0] / (1e3 * U_SMALL_M), excess, f"u_end {1e3 * r.u_m[-1]:.3g} mm"])
            summary.setdefault(cup, {})[_mu_text(m)] = F[0] / (1e3 * U_SMALL_M)
        rows += _limit_checks(cup, ok, free[cup], blank)
    cols = ["cup", "mu", "outcome", "wall_s", "time_over_sticking", "newton_iterations"] + \
           ["F0_1mm_N"] + [f"F0_{x:g}h1_N" for x in SAMPLE_U_OVER_H1] + \
           ["F0_1mm_over_1mm_N_per_mm", "max_cone_excess", "note"]
    ctx.report.table(NAME, "friction_F0_by_mu", cols, rows,
                     f"F0(u) by Coulomb's mu ({fid} mesh, to 0.9 h1; time_over_sticking: wall time / the "
                     f"sticking run's, one run each on a shared machine; max_cone_excess: the largest "
                     f"tangential reaction of a stuck node beyond mu lambda, / max lambda)")
    ctx.report.summary["friction_small_u_stiffness_N_per_mm"] = summary
    ratios = {cup: [r[4] for r in rows if r[0] == cup and r[2] == "converged" and r[1] != "inf (sticking)"]
              for cup in curves}
    text = "; ".join(f"cup {c} {min(v):.3g}-{max(v):.3g}x" for c, v in ratios.items() if v)
    failed = [f"cup {r[0]} mu {r[1]}" for r in rows if r[2] == "failed"]
    ctx.report.text(NAME, f"Cost: a Coulomb curve takes {text} the sticking curve's time (one run "
                          f"each; the issue's target is 2x)."
                    + (f" Not converged: {', '.join(failed)} (the row gives the step and the cause)."
                       if failed else ""))
    ctx.report.summary["friction_time_over_sticking"] = {c: [min(v), max(v)] for c, v in ratios.items() if v}


def _samples(h1_m: float) -> list[float]:
    """The sampled plate displacements [m]: 1 mm, then SAMPLE_U_OVER_H1 of h1."""
    return [U_SMALL_M] + [x * h1_m for x in SAMPLE_U_OVER_H1]


def _at(res: FemResult, u_m: float) -> float:
    return float(res.F0_at(u_m)) if u_m <= res.u_m[-1] else math.nan


def _limit_checks(cup: str, ok: dict, free, blank: list) -> list[list]:
    """Rows saying how mu = 0 compares with frictionless and the largest mu with sticking, and
    where F0 at the sampled u is not monotone in mu (information, not a pass/fail)."""
    rows = []
    us = _samples(next(iter(ok.values())).h1_m) if ok else []
    if 0.0 in ok and not isinstance(free, Exception):
        dev = max(abs(_at(ok[0.0], u) / _at(free, u) - 1) for u in us)
        rows.append([cup, "0 vs frictionless", "check", math.nan, math.nan, 0, *blank,
                     f"largest |F0(mu 0) / F0(frictionless) - 1| at the sampled u: {dev:.2g} "
                     f"(PCHIP between each run's own load steps)"])
    finite = sorted(m for m in ok if m is not None)
    bad = []
    for u in us:
        seq = [_at(ok[m], u) for m in finite] + ([_at(ok[None], u)] if None in ok else [])
        if any(b < a for a, b in zip(seq, seq[1:])):
            bad.append(f"{1e3 * u:.3g}")
    rows.append([cup, "monotone in mu", "check", math.nan, math.nan, 0, *blank,
                 "F0 nondecreasing in mu (then sticking) at every sampled u" if not bad else
                 f"F0 not monotone in mu (then sticking) at u = {', '.join(bad)} mm (path dependence)"])
    return rows


def _figure_curves(ctx: Context, curves, free, fid: str) -> None:
    fig, ax = new_figure(len(curves), 1, 4.6, 3.6)
    for a, (cup, by_mu) in zip(ax[0], curves.items()):
        if not isinstance(free[cup], Exception):
            a.plot(1e3 * free[cup].u_m, free[cup].F0_N, "k--", lw=1, label="frictionless")
        for m, r in by_mu.items():
            if not isinstance(r, Exception):
                a.plot(1e3 * r.u_m, r.F0_N, "-" if m is not None else "k-", label=f"mu {_mu_text(m)}")
        a.set(xlabel="u (mm)", ylabel="F0 (N)", title=f"cup {cup}, Coulomb friction ({fid})")
        a.legend(fontsize=7)
    ctx.report.figure(NAME, "friction_F0_by_mu", fig, "F0(u) by Coulomb's mu, between frictionless and sticking")


def _report_match(ctx: Context, match: dict, fid: str) -> None:
    rows = [[_mu_text(m), k] for m, k in match["grid"]]
    ctx.report.table(NAME, "friction_small_u_stiffness", ["mu", "F0_1mm_over_1mm_N_per_mm"], rows,
                     f"Cup A small-u stiffness k = F0(1 mm)/1 mm by mu (runs to 1 mm, {fid})")
    s = ctx.report.summary
    if not match["found"]:
        text = (f"No mu in the grid brackets the paper's {PAPER_DRY_N_PER_MM} N/mm "
                f"(k from {match['grid'][0][1]:.3g} to {match['grid'][-1][1]:.3g} N/mm).")
        s["friction_matching_mu"] = {"found": False}
    elif match["jump"]:
        text = (f"**No mu matches {PAPER_DRY_N_PER_MM} N/mm**: k(mu) jumps across it, from "
                f"{match['k_lo']:.3g} N/mm at mu = {match['lo']:.4g} to {match['k_hi']:.3g} N/mm at mu = "
                f"{match['hi']:.4g} (bisection to a bracket of {100 * (match['hi'] / match['lo'] - 1):.2g} %). "
                f"At u = 1 mm only the sharp rim corner touches the plane; the jump is that corner "
                f"passing from sliding to sticking, where mu crosses its tangential/normal reaction "
                f"ratio. Both ends of the bracket are followed below.")
        s["friction_matching_mu"] = {k: match[k] for k in ("lo", "hi", "k_lo", "k_hi", "jump")}
    else:
        text = (f"k(mu) = {PAPER_DRY_N_PER_MM} N/mm at mu = {match['mu']:.4g} (linear in the bracket "
                f"{match['lo']:.4g}-{match['hi']:.4g}, k {match['k_lo']:.3g}-{match['k_hi']:.3g} N/mm).")
        s["friction_matching_mu"] = {k: match[k] for k in ("mu", "lo", "hi", "k_lo", "k_hi", "jump")}
    ctx.report.text(NAME, text)


def _geometry_table(ctx: Context, runs: dict) -> None:
    """r_c(h) and l(h) of cup A for the laws around the matching mu, beside eqs (3), (5)."""
    from reduced.cup import CUP_A

    any_run = next(iter(runs.values()))
    h1 = any_run.h1_m
    rows = []
    for x in U_OVER_H1:
        u = x * h1
        r_cone = CUP_A.radius(h1 - u) if h1 - u > 0 else math.nan
        row = [x, 1e3 * r_cone, 1e3 * max(CUP_A.contact_width(r_cone), 0.0)]
        for r in runs.values():
            ok = u <= r.u_m[-1] * (1 + 1e-9)
            row += [1e3 * float(r.r_c_at(u)) if ok else math.nan, 1e3 * float(r.l_at(u)) if ok else math.nan]
        rows.append(row)
    cols = ["u_over_h1", "r_eq3_mm", "l_eq5_mm"]
    for k in runs:
        tag = k.replace(" ", "_")
        cols += [f"r_c_{tag}_mm", f"l_{tag}_mm"]
    ctx.report.table(NAME, "friction_geometry", cols, rows,
                     "Cup A contact radius r_c and strip width l (FEM, force-quartile width; 0: no strip "
                     "resolved) around the matching mu, beside the cone laws")


def _lifetimes(ctx: Context, runs: dict) -> None:
    from validation.crosscheck.lifetimes import fem_width, leakage_model
    from validation.bridge.lifetimes import lifetimes

    uc = pmma_uc_table()
    forces = QUICK_FORCES_N if ctx.quick else FORCES_N
    cols, columns, reasons = ["force_N"], [], {}
    for k, r in runs.items():
        curve = r.stiffness_curve()
        for geometry, src, tag in (("cone", curve, "cone"), ("curve", fem_width(curve), "own")):
            model = leakage_model(src, uc, f"{k}, {tag}")
            ctx.progress(0.0, f"friction lifetimes {k} {tag}")
            try:
                res = lifetimes(model, forces, "paper", cup_laws=geometry)
                columns.append([(x.lifetime_s, x.reason) for x in res])
            except (ValueError, RuntimeError, ArithmeticError) as exc:
                columns.append([(math.nan, f"failed: {str(exc).splitlines()[0][:80]}")] * len(forces))
            cols.append(f"{k.replace(' ', '_')}_{tag}_s")
            reasons[k, tag] = {why for _, why in columns[-1]}
    rows = [[F] + [f"{c[i][0]:.4g}" + ("" if c[i][1] == "reached_r1" else f" ({c[i][1]})") for c in columns]
            for i, F in enumerate(forces)]
    ctx.report.table(NAME, "friction_lifetimes", cols, rows,
                     f"Cup A lifetime [s] on {SURFACE} (reference conventions) by contact law: FEM F0 with "
                     f"the cone laws (cone) or with the FEM's own r_c, V, l (own); reason when not reached_r1")
    ctx.report.summary["friction_lifetime_s"] = {
        c: {f"{F:g}N": col[i][0] for i, F in enumerate(forces)} for c, col in zip(cols[1:], columns)}
    notes = [n for k, r in runs.items()
             for n in _why_not_reached(k, r, reasons[k, "cone"], reasons[k, "own"])]
    if notes:
        ctx.report.text(NAME, "Why some cells end otherwise: " + " ".join(notes))
    _figure_geometry(ctx, runs)


def _why_not_reached(law: str, r: FemResult, cone: set[str], own: set[str]) -> list[str]:
    """The sentences that explain a law's folds with the cone laws (F0 falls after a slip: the force
    balance has no state past that peak) and its "sealed" cells with its own geometry (a strip
    narrower than the mesh resolves carries the force: the rough contact is closed); `cone`, `own`:
    the reasons of its lifetimes with each geometry."""
    out = []
    u, F, l = 1e3 * np.asarray(r.u_m), np.asarray(r.F0_N), 1e3 * np.asarray(r.l_m)
    drop = F[:-1] - F[1:]
    i = int(np.argmax(drop)) if drop.size else 0
    if {"fold", "over_force"} & cone and drop.size and drop[i] > 0.5 * F[i]:
        out.append(f"{law}: F0 drops from {F[i]:.3g} to {F[i + 1]:.3g} N at u = {u[i + 1]:.3g} mm (a slip), "
                   f"so with the cone laws the force balance folds past that peak.")
    thin = (l > 0) & (l < 0.2)
    if "sealed" in own and thin.any():
        out.append(f"{law}: its FEM strip is {l[thin].min():.2g}-{l[thin].max():.2g} mm wide at u = "
                   f"{u[thin].min():.3g}-{u[thin].max():.3g} mm (the rim corner alone, a fraction of an element), "
                   f"and the force on it closes the rough contact (u_c = 0): 'sealed' there is the mesh's "
                   f"strip width, not a strip's.")
    return out


def _figure_geometry(ctx: Context, runs: dict) -> None:
    from reduced.cup import CUP_A

    fig, ax = new_figure(2, 1, 4.4, 3.4)
    for k, r in runs.items():
        h = 1e3 * (r.h1_m - r.u_m)
        ax[0][0].plot(h, 1e3 * r.r_c_m, label=k)
        ax[0][1].plot(h, 1e3 * r.l_m, label=k)
    h = np.linspace(0.1, 0.7, 30) * next(iter(runs.values())).h1_m
    r = np.array([CUP_A.radius(x) for x in h])
    ax[0][0].plot(1e3 * h, 1e3 * r, "k:", label="eq (3)")
    ax[0][1].plot(1e3 * h, 1e3 * np.maximum([CUP_A.contact_width(x) for x in r], 0), "k:", label="eq (5)")
    ax[0][0].set(xlabel="h (mm)", ylabel="r_c (mm)", title="cup A: contact radius")
    ax[0][1].set(xlabel="h (mm)", ylabel="l (mm)", title="cup A: strip width")
    for a in ax[0]:
        a.legend(fontsize=7)
    ctx.report.figure(NAME, "friction_geometry", fig, "Cup A r_c(h) and l(h) around the matching mu")
