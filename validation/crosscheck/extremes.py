"""Section 5: extremes. Every case converges and passes its own checks, or fails fast and says why.

FEM cases (cup A's r0, r1 and taper, frictionless, pressed to full flattening u = h1 unless the solver
stops first): the grid alpha x root thickness at nu = 0.49, E = 4 MPa; the nu axis (0.3, 0.49 and
0.4999, the last with the mixed u-p formulation, which does not lock) and the E axis (10 kPa, 4 MPa,
100 MPa) on cup A; Coulomb friction mu = 0.5 on the grid's four corners (alpha 5 and 70 deg, root
0.1 and 5 mm); the mixed formulation at nu = 0.4999 on the grid's thin walls (root 0.1 and 0.5 mm).
The FEM refuses a converged state that violates the contact conditions (`fem.integrity`): a
boundary facet dipping below the plane between its nodes by more than 5 % of the rim thickness
(node-based contact holds the nodes; where the contact edge falls inside a facet whose wall leaves
the plane steeply, the facet dips), or the wall's outline crossing itself (a fold: no
self-contact is modelled). The path ends there with the cause, the u and the place: a "failed
fast" row. Checks per FEM case that runs to the end, each with its tolerance:

* energy: the work int F0 du (trapezoid over the load steps) equals the stored energy W(u) where
  W > 1 % of its final value, to 2 %, summed over the stable steps (frictionless contact does no
  work; a step across an instability, buckling or a snap, `fem.solver`, jumps between equilibria
  and may only lose energy: "snap dissipation >= 0" checks that no such step creates more than 2 %
  of the final W, and the details give what the snaps dissipated; the budget is the
  trapezoid's O(du^2) error at load steps of <= 1 % of u_max, 5 % in --quick, which the steep end
  u -> h1 and a kink of F0, where the wall lands flat, make largest); if it is exceeded the case is
  rerun with the load step halved, up to three times, and judged on the finest run: a quadrature error
  drops ~4x per halving, a real energy defect does not (the table shows the sequence);
* reaction: the plate reaction equals the integrated contact pressure, to 1e-4 of max F0 (equilibrium;
  the Newton tolerance is 1e-6 of the reaction);
* penetration: the largest violation of z >= 0 is below 5 % of the rim thickness (the FEM ends a
  path that violates it, so this re-checks `fem.integrity` by the report's own sampling);
* Coulomb rows: instead of the energy equality, "dissipation >= 0": work - stored energy may not
  fall below -2 % of W anywhere (friction only dissipates; the budget is the trapezoid's), and
  "cone excess": no stuck node's tangential reaction beyond mu lambda by more than 1e-3 of the
  largest normal reaction (the solver's own refusal threshold);
* mesh (full run, geometry grid): F0 at u = 0.5 u_end of the coarse and medium meshes agree to 5 %;
* scaling (E axis): F0/E is the same for every E to 1e-5 of max F0/E. The neo-Hookean law has no
  stress scale but E, so any difference is solver error.

An invalid geometry (a thick wall offset along the normal can cross itself or the axis) is rejected by
the geometry's own check; that message is the outcome. A solver failure is reported with its step and
residual history (fem.solver.ConvergenceError).

Reduced-model cases (reference conventions, cup A, pmma-1.89 unless stated): F1 -> 0 and F1 -> the
largest holdable force; constant u_c from 1 nm to 10 um (lifetimes from milliseconds to beyond 1e9 s);
the water-filled cup, as a metastable liquid (any tension, p_b < 0) and with cavitation at water's
vapour pressure (a vapour bubble opens, the cup rises to where the force balance holds at that
pressure), up to beyond the largest holdable force. Checks: the lifetime agrees with the
independent quadrature t = int dN_eq/dh / Ndot dh (`lifetime_by_quadrature`) to 1e-4 (its
documented agreement is ~1e-5 at folds, 2e-6 otherwise); for water, p_b at t = 0 equals the force
balance p_a - (F0 + F1)/(pi r^2) at the start height to 1e-9 of p_a, and with cavitation p_b never
falls below the vapour pressure.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from reduced.cup import CUP_A
from validation.crosscheck.context import Context, pmma_uc_table
from validation.crosscheck.runs import FemRun

NAME = "extremes"
TITLE = "5. Extremes"

ALPHAS = (5.0, 15.0, 45.0, 70.0)
ROOTS_MM = (0.1, 0.5, 5.0)
NUS = ((0.3, "displacement"), (0.49, "displacement"), (0.4999, "mixed"))
MODULI = (1e4, 4e6, 1e8)
FULL = 1.0                       # u_max / h1: full flattening
QUICK_GRID = ((5.0, 5.0), (45.0, 0.5))
VAPOUR_PRESSURE_PA = 2339.0      # water at 20 C
STEP = 0.01                      # largest load step / u_max: the energy quadrature's resolution
CORNERS = ((5.0, 0.1), (5.0, 5.0), (70.0, 0.1), (70.0, 5.0))
CORNER_MU = 0.5
THIN_ROOTS_MM = (0.1, 0.5)
CONE_EXCESS_TOL = 1e-3           # the solver refuses a stuck node beyond 1e3 rtol of max lambda


def _base(**kw) -> FemRun:
    return FemRun(**{"cup": "A", "contact": "frictionless", "u_max_over_h1": FULL, "max_step": STEP, **kw})


def grid(quick: bool) -> list[FemRun]:
    if quick:
        return [_base(alpha_deg=a, d_root_mm=d, max_step=0.05) for a, d in QUICK_GRID]
    return [_base(alpha_deg=a, d_root_mm=d) for a in ALPHAS for d in ROOTS_MM]


def nu_axis(quick: bool) -> list[FemRun]:
    return [] if quick else [_base(nu=n, formulation=f) for n, f in NUS]


def e_axis(quick: bool) -> list[FemRun]:
    if quick:
        return [_base(E_Pa=E, max_step=0.1, u_max_over_h1=0.5) for E in (1e4, 4e6)]
    return [_base(E_Pa=E) for E in MODULI]


def coulomb_axis(quick: bool) -> list[FemRun]:
    """Coulomb's mu = 0.5 on the grid's corners (the extreme cone angles and root thicknesses)."""
    corners = QUICK_GRID[:1] if quick else CORNERS
    return [_base(alpha_deg=a, d_root_mm=d, contact="coulomb", friction=CORNER_MU,
                  **({"max_step": 0.05} if quick else {})) for a, d in corners]


def mixed_thin_axis(quick: bool) -> list[FemRun]:
    """The mixed u-p formulation at nu = 0.4999 on the grid's thin walls (not in --quick: 7x the
    displacement formulation's cost)."""
    return [] if quick else [_base(alpha_deg=a, d_root_mm=d, nu=0.4999, formulation="mixed")
                             for a in ALPHAS for d in THIN_ROOTS_MM]


def requests(quick: bool) -> tuple[FemRun, ...]:
    runs = grid(quick) + nu_axis(quick) + e_axis(quick) + coulomb_axis(quick) + mixed_thin_axis(quick)
    if not quick:
        runs += [FemRun(**{**r.__dict__, "fidelity": "medium"}) for r in grid(quick)]
    return tuple(runs)


def fem_checks(res, rim_m: float) -> dict[str, tuple[float, float]]:
    """check -> (value, tolerance); see the module docstring for the tolerances."""
    steps = _step_energy_defects(res)
    stable = ~_unstable(res)[1:]
    defect = np.concatenate([[0.0], np.cumsum(np.where(stable, steps, 0.0))])
    big = res.energy_J > 0.01 * res.energy_J[-1]
    energy = float(np.max(np.abs(defect[big] / res.energy_J[big]))) if big.any() else math.nan
    reaction = float(np.max(np.abs(res.F0_N - res.F0_contact_N)) / max(np.max(np.abs(res.F0_N)), 1e-300))
    pen = float(np.max(np.maximum(res.penetration_m, 0.0)) / rim_m)
    checks = {"energy": (energy, 2e-2), "reaction": (reaction, 1e-4), "penetration/rim": (pen, 5e-2)}
    if res.request.contact == "coulomb":
        # friction dissipates: work - stored energy >= 0 (the trapezoid's budget below 0), and no
        # stuck node outside the cone
        del checks["energy"]
        total = np.concatenate([[0.0], np.cumsum(steps)])            # every step dissipates
        dissipated = float(-np.min(total[big] / res.energy_J[big])) if big.any() else math.nan
        checks = {"dissipation >= 0": (max(dissipated, 0.0), 2e-2), **checks,
                  "cone excess": (float(np.max(res.cone_excess, initial=0.0))
                                  if res.cone_excess is not None else 0.0, CONE_EXCESS_TOL)}
    if not stable.all():
        # a snap across an instability may only lose energy (to the dynamics the quasi-static path
        # skips): work - stored energy change >= 0 at each unstable step, to the trapezoid's budget
        created = float(np.max(-steps[~stable], initial=0.0)) / res.energy_J[-1]
        checks["snap dissipation >= 0"] = (created, 2e-2)
    return checks


def _step_energy_defects(res) -> np.ndarray:
    """Per load step: the work int F0 du (trapezoid) minus the change of stored energy [J]."""
    work = 0.5 * (res.F0_N[1:] + res.F0_N[:-1]) * np.diff(res.u_m)
    return work - np.diff(res.energy_J)


def _unstable(res) -> np.ndarray:
    return np.zeros(len(res.u_m), bool) if res.unstable is None else np.asarray(res.unstable, bool)


def _snaps(res) -> str:
    """Where the path crossed instabilities and what they dissipated (empty if none)."""
    flags = _unstable(res)
    if not flags.any():
        return ""
    lost = float(np.sum(_step_energy_defects(res)[flags[1:]]))
    u = res.u_m[flags] / res.h1_m
    return (f"; {flags.sum()} unstable steps (buckling/snap) at u/h1 = {u.min():.3g}-{u.max():.3g}, "
            f"dissipating {100 * lost / res.energy_J[-1]:.3g} % of the final W")


def _verdict(checks: dict[str, tuple[float, float]]) -> tuple[str, str]:
    failed = [k for k, (v, tol) in checks.items() if not (v <= tol)]
    text = "; ".join(f"{k} {v:.2g} (tol {tol:g})" for k, (v, tol) in checks.items())
    return ("pass" if not failed else "FAIL: " + ", ".join(failed)), text


def _first_line(exc: Exception) -> str:
    return f"{type(exc).__name__}: {str(exc).splitlines()[0]}"


def fem_row(ctx: Context, req: FemRun, axis: str) -> list:
    params = f"alpha {req.geometry_alpha():g} deg, d0 {req.thickness_at_ends_m()[0] * 1e3:g} mm, " \
             f"nu {req.nu:g} ({req.formulation}), E {req.E_Pa / 1e6:g} MPa" + \
             (f", Coulomb mu {req.friction:g}" if req.friction is not None else "")
    try:
        req.geometry()
    except ValueError as exc:
        return [axis, params, "rejected (invalid geometry)", "", _first_line(exc)]
    out = ctx.outcome(req)
    if isinstance(out, Exception):
        return [axis, params, "failed fast (solver)", "", _first_line(out)[:700]]
    checks = fem_checks(out, req.thickness_at_ends_m()[1])
    halvings = ""
    if "energy" in checks:
        checks["energy"], halvings = _energy_with_step_halving(ctx, req, checks["energy"])
    if axis == "grid" and not ctx.quick:
        fine = ctx.outcome(FemRun(**{**req.__dict__, "fidelity": "medium"}))
        if isinstance(fine, Exception):
            checks["mesh"] = (math.nan, 5e-2)
        else:
            u = 0.5 * min(out.u_m[-1], fine.u_m[-1])
            checks["mesh"] = (abs(float(fine.F0_at(u) / out.F0_at(u)) - 1.0), 5e-2)
    verdict, text = _verdict(checks)
    if halvings:
        text += f" (energy mismatch with the load step halved: {halvings})"
    reached = out.u_m[-1] / out.h1_m
    return [axis, params, verdict, text, f"u_end = {reached:.3g} h1, F0_end = {out.F0_N[-1]:.4g} N, "
                                         f"{out.steps} steps, {out.wall_s:.3g} s{_snaps(out)}"]


def _energy_with_step_halving(ctx: Context, req: FemRun, energy: tuple[float, float],
                              halvings: int = 3) -> tuple[tuple[float, float], str]:
    """The energy check's budget is the trapezoid's O(du^2) error, largest at the steep end
    (u -> h1). If it is exceeded, rerun with the load step halved (up to `halvings` times; the
    thinnest flat cone, 5 deg / 0.1 mm, needs three: 0.5 -> 0.14 -> 0.037 -> ..., 3.6x and 3.8x): a
    quadrature error drops ~4x per halving and the check is judged on the finest run; a real
    energy defect (a non-conservative solution) would not drop. Returns the check and the
    sequence of mismatches ("" if no rerun was needed)."""
    seq = [energy[0]]
    step = req.max_step
    while not seq[-1] <= energy[1] and len(seq) <= halvings:
        step /= 2
        res = ctx.outcome(FemRun(**{**req.__dict__, "max_step": step}))
        if isinstance(res, Exception):
            break
        seq.append(fem_checks(res, req.thickness_at_ends_m()[1])["energy"][0])
    text = "" if len(seq) == 1 else (" -> ".join(f"{e:.2g}" for e in seq) +
                                     f" at max_step {req.max_step:g} ... {step:g} u_max")
    return (seq[-1], energy[1]), text


def scaling_row(ctx: Context, runs: list[FemRun]) -> list:
    res = [ctx.outcome(r) for r in runs]
    if any(isinstance(r, Exception) for r in res):
        return ["E scaling", "", "failed fast (solver)", "", "; ".join(_first_line(r) for r in res
                                                                       if isinstance(r, Exception))]
    base = res[0]
    u = base.u_m[base.u_m <= min(r.u_m[-1] for r in res)]
    ref = base.F0_at(u) / base.request.E_Pa
    worst = max(float(np.max(np.abs(r.F0_at(u) / r.request.E_Pa - ref))) for r in res[1:])
    rel = worst / float(np.max(np.abs(ref)))
    verdict, text = _verdict({"F0/E spread": (rel, 1e-5)})
    Es = ", ".join(f"{r.request.E_Pa / 1e6:g}" for r in res)
    return ["E scaling", f"E = {Es} MPa", verdict, text, f"F0/E at u_end: {ref[-1]:.6g} m"]


def reduced_rows(ctx: Context) -> list[list]:
    from reduced.critical_gap import UcTable
    from reduced.lifetime import reference_model
    from validation.bridge.lifetimes import lifetimes

    uc = pmma_uc_table()
    model = reference_model(CUP_A, uc)
    Fmax = lifetimes(model, [], "paper", cup_laws="cone").largest_force_N
    cases = [("F1 = 1 mN (-> 0)", model, 1e-3),
             (f"F1 = (1 - 1e-3) F_max = {(1 - 1e-3) * Fmax:.4g} N", model, (1 - 1e-3) * Fmax),
             (f"F1 = F_max = {Fmax:.4g} N", model, Fmax)]
    uc_values = (1e-9, 1e-6, 1e-5) if ctx.quick else (1e-9, 1e-8, 1e-7, 1e-6, 1e-5)
    for u in uc_values:
        table = UcTable(np.array([1e-4, 1.0]), np.array([u, u]), provenance="constant")
        cases.append((f"u_c = {u * 1e9:g} nm (constant), F1 = 20 N", reference_model(CUP_A, table), 20.0))
    rows = [_reduced_case(ctx, label, m, F1, _air_verdict) for label, m, F1 in cases]
    return rows + water_rows(ctx, uc)


def water_rows(ctx: Context, uc) -> list[list]:
    """The water-filled cup, as a metastable liquid (any tension) and with cavitation at water's
    vapour pressure, from a moderate pull to beyond the largest holdable force."""
    from dataclasses import replace

    from reduced.lifetime import reference_model
    from validation.bridge.lifetimes import lifetimes

    rows = []
    for p_cav in (None, VAPOUR_PRESSURE_PA):
        model = replace(reference_model(CUP_A, uc), fluid="water", cavitation_pressure_Pa=p_cav)
        kind = "metastable (any tension)" if p_cav is None else f"cavitation at {p_cav / 1e3:g} kPa"
        F_cav = lifetimes(replace(model, cavitation_pressure_Pa=VAPOUR_PRESSURE_PA), [], "paper",
                          cup_laws="cone").largest_force_N
        rows += [_reduced_case(ctx, f"water, {kind}, F1 = {F1:.4g} N", model, F1, _water_verdict)
                 for F1 in (20.0, 60.0, 100.0, 1.05 * F_cav)]
    return rows


def _reduced_case(ctx: Context, label: str, model, F1: float, judge) -> list:
    """One reduced-model case: its lifetime judged by `judge(model, result, F1) -> (outcome,
    checks, details)`, or the error it fails fast with."""
    from validation.bridge.lifetimes import lifetimes

    ctx.progress(0.0, f"reduced: {label}")
    try:
        r = lifetimes(model, [F1], "paper", cup_laws="cone")[0]
    except (ValueError, RuntimeError) as exc:
        return ["reduced", label, "failed fast", "", _first_line(exc)]
    return ["reduced", label, *judge(model, r, F1)]


def _quadrature_error(model, r, F1: float) -> float:
    """|lifetime by quadrature / lifetime - 1| (`lifetime_by_quadrature`, no time stepping)."""
    from reduced.lifetime import lifetime_by_quadrature

    with warnings.catch_warnings():      # quad's round-off warning: the check judges the result
        warnings.simplefilter("ignore")
        return abs(lifetime_by_quadrature(model, F1) / r.lifetime_s - 1)


def _air_verdict(model, r, F1: float) -> tuple[str, str, str]:
    """The lifetime against the quadrature; an over-force detaches at t = 0."""
    info = f"lifetime {r.lifetime_s:.4g} s ({r.reason})"
    if r.reason in ("reached_r1", "fold"):
        return (*_verdict({"quadrature": (_quadrature_error(model, r, F1), 1e-4)}), info)
    if r.reason == "over_force":
        return (*_verdict({"lifetime at F1 >= F_max": (r.lifetime_s, 0.0)}), info)
    return "pass", "no leak path: nothing to integrate", info


def _water_verdict(model, r, F1: float) -> tuple[str, str, str]:
    """Checks: p_b(0) from the force balance (7) at the start height (h_start, or h_c after
    cavitation), never below the cavitation pressure, and the quadrature lifetime."""
    p_cav = model.cavitation_pressure_Pa
    p_b = r.trajectory["p_b_Pa"]
    note = f"lifetime {r.lifetime_s:.4g} s ({r.reason}), p_b(0) = {p_b[0] / 1e3:.4g} kPa"
    if r.reason == "over_force":
        checks = {"lifetime at F1 >= F_max": (r.lifetime_s, 0.0)}
        return (*_verdict(checks), note + f"; F_max = {r.largest_force_N:.4g} N")
    h0 = r.trajectory["h_mm"][0] / 1e3
    radius = CUP_A.radius(h0)
    pb = model.p_a_Pa - (float(model.stiffness.force(h0)) + F1) / (math.pi * radius * radius)
    checks = {"p_b(0) force balance": (abs(p_b[0] - pb) / model.p_a_Pa, 1e-9),
              "quadrature": (_quadrature_error(model, r, F1), 1e-4)}
    if p_cav is not None:
        checks["p_b >= p_cav"] = (max(0.0, (p_cav - p_b.min()) / model.p_a_Pa), 1e-9)
        if "cavitation" in r.message:
            note += f"; {r.message.split('; ', 1)[1]}"
    elif p_b.min() < VAPOUR_PRESSURE_PA:
        note += (f"; p_b reaches {p_b.min() / 1e3:.4g} kPa, below water's vapour pressure: a "
                 f"metastable liquid under tension (the paper's Sec. 6; see the cavitation rows)")
    return (*_verdict(checks), note)


def run(ctx: Context) -> None:
    rep = ctx.report
    rep.text(NAME, __doc__.split("\n\n", 1)[1])
    rows = [fem_row(ctx, r, "grid") for r in grid(ctx.quick)]
    rows += [fem_row(ctx, r, "nu") for r in nu_axis(ctx.quick)]
    rows += [fem_row(ctx, r, "E") for r in e_axis(ctx.quick)]
    rows += [fem_row(ctx, r, "coulomb") for r in coulomb_axis(ctx.quick)]
    rows += [fem_row(ctx, r, "mixed thin") for r in mixed_thin_axis(ctx.quick)]
    rows.append(scaling_row(ctx, e_axis(ctx.quick)))
    rows += reduced_rows(ctx)
    rep.table(NAME, "extremes_outcomes", ["axis", "case", "outcome", "checks", "details"], rows,
              "Outcome of every extreme case (generated)")
    counts: dict[str, int] = {}
    for r in rows:
        key = r[2].split(":")[0].split(" (")[0]
        counts[key] = counts.get(key, 0) + 1
    rep.summary["extremes_outcomes"] = counts
    rep.text(NAME, f"**Outcomes**: {len(rows)} cases, " + ", ".join(f"{n} {k}" for k, n in sorted(counts.items()))
             + ("" if "FAIL" in counts else ", none FAILs a check") + ".")
    rep.summary["extremes_lifetime_span_s"] = _lifetime_span(rows)


def _lifetime_span(rows) -> list[float]:
    vals = []
    for r in rows:
        text = r[4]
        if text.startswith("lifetime "):
            try:
                v = float(text.split()[1])
            except ValueError:
                continue
            if v > 0 and math.isfinite(v):
                vals.append(v)
    return [min(vals), max(vals)] if vals else []
