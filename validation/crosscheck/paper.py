"""Section 6: every number the paper states about a measurement or its own calculation, beside what
cupcheck gives by each route, the ratio, and the reason for every gap wider than the paper's spread.

Routes (the `route` column): the paper's route, eqs (3)-(7) with the uniform strip pressure of
eq (6) and beta = 0.8, fed by three stiffness sources: `appendix-a` (the no-slip formula, d0 = 2 mm),
`fem-frictionless` (the FEM on a frictionless plane: the soap-lubricated glass on which the paper
measured the F0 its lifetimes use, Sec. 5.3-5.5) and `fem-sticking` (no slip, Appendix A's
assumption); the profile route on the frictionless FEM (its r_c, V and contact-pressure profile,
`reduced.seal`); and the coupled route on the frictionless FEM (the cup under the cavity's
suction on a (u, dp) grid, `reduced.coupled`: F1, V, the seal and the profile of every state from
the FEM, replacing eqs 3-7 and beta; r(t) is the seal radius; no water). Lifetimes are computed as
the paper computed its own: E_eff(t) relaxation (the default law through 4.4 MPa at 1 s and
1.8 MPa at 3e4 s), air at 293.15 K, p_a = 1e5 Pa, Table 1's cups, u_c from the calibrated surface
presets (Persson theory, EMT). Water runs without relaxation, with E = 4 MPa (the dashed lines of
the paper's Fig. 1rStart). Nothing is tuned to a measured lifetime.

`agrees` is yes when cupcheck's value lies in the paper's own spread: the precision of the number
as stated ("~200 nm": 150-250 nm), or the measured range; `by construction` marks numbers that
cupcheck's inputs were calibrated to (a check of the calibration, not of the physics).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from reduced.cup import CUP_A, CUPS
from validation.crosscheck.context import CROSSCHECK_FIDELITY, Context, pmma_uc_table
from validation.crosscheck.runs import FemRun

NAME = "paper"
TITLE = "6. The paper's numbers beside cupcheck's"

P_A = 1e5
SURFACES_RMS_UM = {"pmma-2.51": 2.51, "pmma-1.89": 1.89, "pmma-1.08": 1.08, "pmma-0.77": 0.77, "table": 7.7}
UC_1ATM_UM = {"pmma-2.51": 1.17, "pmma-1.89": 0.68, "pmma-1.08": 0.40, "pmma-0.77": 0.21, "table": 0.85}
COLUMNS = ["claim", "where", "paper", "route", "cupcheck", "unit", "ratio", "agrees", "reason"]


def requests(quick: bool) -> tuple[FemRun, ...]:
    laws = ("frictionless",) if quick else ("frictionless", "sticking")
    return tuple(FemRun(cup=c, contact=k, fidelity=CROSSCHECK_FIDELITY) for c in "AB" for k in laws)


@dataclass(frozen=True)
class Route:
    """One way to the paper's lifetimes: `life(cup, surface, F1, kappa=1, fluid="air", **options)`
    (options: the run options of `reduced.solve_lifetime`) returns a `reduced.Lifetime`;
    `holdable(cup)` the largest load held [N]; `radius(cup, result)` the contact radius r(t) [mm]
    along a result's trajectory; `stiffness(cup)` the F0 curve, for the stiffness rows of the
    stiffness sources (None for the routes that reuse one)."""

    name: str
    life: Callable[..., object]
    holdable: Callable[[str], float]
    radius: Callable[[str, object], np.ndarray]
    fluids: tuple[str, ...] = ("air", "water")
    stiffness: Callable[[str], object] | None = None


def routes(ctx: Context) -> list[Route]:
    """The paper's route fed by each stiffness source, the profile route and the coupled route on
    the frictionless FEM (module docstring)."""
    from reduced.appendix_a import appendix_a_curve

    def fem(law: str):
        return functools.cache(
            lambda cup: ctx.fem(FemRun(cup=cup, contact=law, fidelity=CROSSCHECK_FIDELITY)).stiffness_curve())

    out = [_model_route("appendix-a", functools.cache(
        lambda cup: appendix_a_curve(CUPS[cup], E_Pa=4e6, d0_m=2e-3)), "paper", stiffness=True)]
    for law in ("frictionless",) if ctx.quick else ("frictionless", "sticking"):
        out.append(_model_route(f"fem-{law}", fem(law), "paper", stiffness=True))
    out.append(_model_route("profile (fem-frictionless)", fem("frictionless"), "profile"))
    out.append(coupled_route(ctx))
    return out


def _model_route(name: str, curve: Callable[[str], object], route: str, stiffness: bool = False) -> Route:
    """A route of `reduced.solve_lifetime` fed by the stiffness curve of each cup."""
    from validation.bridge.lifetimes import lifetimes, route_options

    options = route_options(route)

    def life(cup, surface, F1, kappa=1.0, fluid="air", **run):
        return lifetimes(model(curve(cup), cup, surface, fluid=fluid, kappa=kappa), [F1], route, **run,
                         **options)[0]

    def holdable(cup):
        return lifetimes(model(curve(cup), cup, "pmma-1.89"), [], route, **options).largest_force_N

    return Route(name, life, holdable, lambda cup, result: result.trajectory["r_mm"],
                 stiffness=curve if stiffness else None)


def coupled_route(ctx: Context) -> Route:
    """The coupled route on the frictionless FEM's suction tables of cups A and B (built once per
    code version, in the run memo's cache directory when there is one); r(t) is the seal radius r_k
    of the table, interpolated at the trajectory's (u, dp / kappa(t)); the route has no ballistic
    share and no water."""
    from validation.bridge.coupled.build import DEFAULT_GRID, QUICK_GRID, suction_table_for
    from validation.bridge.lifetimes import lifetimes

    cache = None if ctx.memo.cache_dir is None else ctx.memo.cache_dir / "suction"

    @functools.cache
    def table(cup):
        ctx.progress(0.0, f"paper's numbers: suction table of cup {cup}")
        return suction_table_for(cup, fidelity=CROSSCHECK_FIDELITY, grid=QUICK_GRID if ctx.quick else DEFAULT_GRID,
                                 cache_dir=cache)

    @functools.cache
    def cavity(cup, surface, kappa):
        from reduced.gas import Gas
        from reduced.lifetime import LeakageModel
        from reduced.viscoelastic import default_relaxation, measurement_contact_time

        return LeakageModel(cup=CUPS[cup], suction=table(cup), u_c=pmma_uc_table(surface), gas=Gas(T_K=293.15),
                            p_a_Pa=P_A, kappa=kappa, relaxation=default_relaxation(),
                            phi0_s=measurement_contact_time(CUPS[cup]))

    def life(cup, surface, F1, kappa=1.0, fluid="air", **run):
        return lifetimes(cavity(cup, surface, kappa), [F1], "coupled", **run)[0]

    def holdable(cup):
        return lifetimes(cavity(cup, "pmma-1.89", 1.0), [], "coupled").largest_force_N

    def radius(cup, result):
        from scipy.interpolate import RegularGridInterpolator

        t, cols = table(cup), result.trajectory
        if not cols["u_mm"].size:
            return cols["u_mm"]
        seal = RegularGridInterpolator((t.u_m, t.dp_Pa), t.seal_r_m)
        return 1e3 * seal(np.column_stack([1e-3 * cols["u_mm"], (P_A - cols["p_b_Pa"]) / cols["kappa"]]))

    return Route("coupled (fem-frictionless)", life, holdable, radius, fluids=("air",))


def model(curve, cup: str, surface: str, *, fluid: str = "air", kappa: float = 1.0):
    """The paper's own lifetime calculation (module docstring) for one stiffness curve: Table 1's
    cup, relaxation in air, E = 4 MPa in water."""
    from reduced.gas import Gas
    from reduced.lifetime import LeakageModel
    from reduced.viscoelastic import default_relaxation

    return LeakageModel(cup=CUPS[cup], stiffness=curve, u_c=pmma_uc_table(surface), gas=Gas(T_K=293.15),
                        p_a_Pa=P_A, E_Pa=4e6, fluid=fluid, kappa=kappa,
                        relaxation=default_relaxation() if fluid == "air" else None)


class Rows(list):
    """The table's rows, with the ratio and the verdict filled in."""

    def add(self, claim: str, where: str, paper: str, route: str, value, unit: str,
            spread: tuple[float, float] | None = None, expect=None, reason: str = "",
            construction: bool = False, ref: float | None = None) -> None:
        if isinstance(value, str):
            ok = value == expect
            ratio = ""
        else:
            lo, hi = spread
            ok = lo <= value <= hi
            ratio = value / ref if ref else ""
        verdict = "by construction" if construction else ("yes" if ok else "no")
        self.append([claim, where, paper, route, value, unit, ratio, verdict, "" if ok else reason])


def run(ctx: Context) -> None:
    rep = ctx.report
    rep.text(NAME, __doc__.split("\n\n", 1)[1])
    rows = Rows()
    all_routes = routes(ctx)
    _estimates(rows)
    _stiffness(rows, {r.name: {cup: r.stiffness(cup) for cup in "AB"} for r in all_routes if r.stiffness})
    _rough_contact(rows)
    for route in all_routes:
        ctx.progress(0.0, f"paper's numbers: {route.name}")
        _holding(rows, route)
        _lifetimes(rows, route, ctx.quick)
    rep.table(NAME, "paper_numbers", COLUMNS, rows, "The paper's numbers and cupcheck's (generated)")
    counts = {k: sum(r[7] == k for r in rows) for k in ("yes", "no", "by construction")}
    rep.summary["paper_numbers"] = counts
    rep.text(NAME, f"{counts['yes']} rows agree within the paper's spread, {counts['no']} do not (each "
                   f"with its reason), {counts['by construction']} agree by construction.")


# ------------------------------------------------------------------ route-independent numbers
def _estimates(rows: Rows) -> None:
    """Sec. 2: the u_c that lets 1 cm^3 of air leak in within 1 hour / 1 year, and the flow regime."""
    from scipy.optimize import brentq

    from reduced.gas import AIR, ballistic_share, interpolated_leak_rate

    N_b = P_A * 1e-6 / AIR.kT_J                          # 1 cm^3 of air at p_a
    why = ("the paper's estimate is eq (2): ballistic flow only, v = 500 m/s and the prefactor 10 = "
           "(1/2) L_y/L_x; cupcheck solves eq (19) (ballistic + diffusive, v = 463 m/s) at L_y/L_x = 20, "
           "p_b = 0. Eq (2) itself gives (V_b / (10 v t))^(1/2) = {eq2:.3g} nm here")
    for label, t, value, spread in (("1 hour", 3600.0, 200e-9, (150e-9, 250e-9)),
                                    ("1 year", 3e8, 2e-9, (1.5e-9, 2.5e-9))):
        uc = math.exp(brentq(lambda x: math.log(interpolated_leak_rate(AIR, P_A, 0.0, math.exp(x), 20.0) * t / N_b),
                             math.log(1e-12), math.log(1e-3)))
        eq2 = 1e9 * math.sqrt(1e-6 / (10 * 500.0 * t))
        note = why.format(eq2=eq2) + (": the paper's 2 nm does not follow from its own formula" if t > 1e6 else "")
        rows.add(f"u_c for a {label} lifetime (V_b = 1 cm^3)", "Sec. 2", f"~{value * 1e9:g} nm", "eq (19)",
                 uc * 1e9, "nm", tuple(1e9 * s for s in spread), reason=note, ref=value * 1e9)
    lam = AIR.mean_free_path_m(P_A)
    rows.add("mean free path of air at 1 atm", "Sec. 2", "~100 nm", "eq (12)", lam * 1e9, "nm", (50, 200),
             ref=100.0)
    share = float(ballistic_share(AIR, P_A, P_A, 0.5e-6))
    rows.add("ballistic share of the flow at u_c = 0.5 um", "Sec. 5.1", "about equal (0.5)", "eq (19)",
             share, "-", (0.4, 0.6), ref=0.5)


def _stiffness(rows: Rows, curves) -> None:
    """Appendix A's 2.5 N/mm and 'cup A nearly twice as stiff as cup B' (Sec. 5.5)."""
    for route, by_cup in curves.items():
        a, b = by_cup["A"], by_cup["B"]
        slope = float(a.force(a.h1_m - 1e-3)) / 1.0                      # F0(1 mm) / 1 mm
        rows.add("cup A small-u stiffness F0(1 mm)/1 mm (dry glass)", "App. A", "2.5 N/mm", route, slope,
                 "N/mm", (2.25, 2.75), ref=2.5,
                 reason="frictionless contact lets the rim slide out; the dry measurement sticks"
                 if "frictionless" in route else "no slip stiffens the small-u response beyond the dry glass")
        u = np.array([1e-3, 2e-3, 3e-3])
        ratio = float(np.mean(a.force(a.h1_m - u) / b.force(b.h1_m - u)))
        rows.add("stiffness of cup A / cup B before contact stiffening", "Sec. 5.5", "nearly 2", route, ratio,
                 "-", (1.7, 2.3), ref=2.0, reason="mean of F0_A/F0_B at u = 1, 2, 3 mm; the paper "
                 "reads it off measured curves on lubricated glass")


def _rough_contact(rows: Rows) -> None:
    """u_c at 1 atm for the five surfaces (Sec. 5.1) and E_eff at 1 s and 3e4 s (Sec. 5.2)."""
    from reduced.viscoelastic import default_relaxation

    for surface, target in UC_1ATM_UM.items():
        uc = float(pmma_uc_table(surface)(101325.0 / 4e6)) * 1e6
        rows.add(f"u_c at 1 atm, {surface}", "Sec. 5.1", f"{target:g} um", "Persson EMT", uc, "um",
                 (target - 0.005, target + 0.005), ref=target, construction=True)
    relax = default_relaxation()
    for t, E in ((1.0, 4.4), (3e4, 1.8)):
        rows.add(f"E_eff at {t:g} s", "Sec. 5.2", f"{E:g} MPa", "default law", float(relax(t)) / 1e6, "MPa",
                 (E - 0.05, E + 0.05), ref=E, construction=True)


# ------------------------------------------------------------------ route-dependent numbers
def _holding(rows: Rows, route: Route) -> None:
    """F_max = pi r1^2 p_a = 113 N (full vacuum) and the ~9 kg measured on a smooth substrate."""
    if route.name == "appendix-a":
        rows.add("full-vacuum force pi r1^2 p_a", "Sec. 5.4", "113 N", "-", math.pi * CUP_A.r1_m ** 2 * P_A,
                 "N", (112.5, 113.5), ref=113.0)
    why = ("the trapped gas is fixed by r_start = 12 mm (Table 1); the paper's 9 kg was pressed on by "
           "hand, its r_start unknown, and 'no complete vacuum was obtained'")
    if route.name.startswith("coupled"):
        why = ("under suction the FEM pulls the inner wall onto the plane and the seal moves inwards "
               "(r_k = 13.7 mm at 100 kPa for cup A), so the sucked area is smaller than the rigid "
               "cone's pi r^2; " + why)
    rows.add("largest load held (smooth substrate)", "Sec. 5.4", "~9 kg = 88 N", route.name,
             route.holdable("A"), "N", (83.0, 93.0), ref=88.3, reason=why)


def _lifetimes(rows: Rows, route: Route, quick: bool) -> None:
    name, life = route.name, route.life
    by_surface = {s: life("A", s, 10.0) for s in SURFACES_RMS_UM}
    rows.add("lifetime at 10 N on a rough surface", "Sec. 2", "of order 100 s", name,
             by_surface["pmma-1.89"].lifetime_s, "s", (30.0, 300.0), ref=100.0,
             reason="pmma-1.89, cup A, F1 = 10 N")
    share = by_surface["pmma-1.89"].details.get("ballistic_share")
    if share is not None:
        rows.add("air flow on pmma-1.89 mainly diffusive (ballistic share < 0.5)", "Sec. 5.4", "yes", name,
                 "yes" if share < 0.5 else "no", "-", expect="yes", reason=f"ballistic share {share:.2f}")
    above = [s for s, rms in SURFACES_RMS_UM.items() if rms > 1.0]
    grows = [s for s in above if _grows_continuously(by_surface[s], route.radius("A", by_surface[s]))]
    rows.add("r(t) grows continuously for rms > 1 um", "Sec. 5.4", "yes", name,
             "yes" if len(grows) == len(above) else "no", "-", expect="yes",
             reason=f"continuous on {', '.join(grows) or 'none'} of {', '.join(above)}")
    rows.add("r(t) stalls for rms < 1 um (pmma-0.77)", "Sec. 5.4", "yes (measured)", name,
             "no" if _grows_continuously(by_surface["pmma-0.77"], route.radius("A", by_surface["pmma-0.77"]))
             else "yes", "-", expect="yes",
             reason="the measured stall is plasticizer filling the constrictions (the paper's "
                    "explanation); neither the paper's theory nor cupcheck models it")
    dry = by_surface["table"]
    rows.add("table surface, dry, 10 N", "Sec. 5.4", "3-6 s", name, dry.lifetime_s, "s", (3.0, 6.0), ref=4.5,
             reason=f"{dry.reason}; the paper's table spectrum is not published: the preset "
             "matches its u_c(1 atm) = 0.85 um only, close to pmma-1.89's 0.68 um, so the lifetimes are "
             "alike; the strip pressures on the way are below 1 atm, where the real table's u_c(p) "
             "(a hump near q = 1e5 1/m) is unknown")
    if "water" in route.fluids:
        wet = life("A", "table", 10.0, fluid="water")
        rows.add("table surface, in water, 10 N", "Sec. 5.4", "1e3-1e4 s", name, wet.lifetime_s, "s",
                 (1e3, 1e4), ref=math.sqrt(1e7), reason=f"{wet.reason}; r_start 12 mm is the dry one: "
                 "the paper notes r_start is smaller in water, and the lifetime very sensitive to it")
    forces = (10.0, 40.0) if quick else (5.0, 10.0, 20.0, 40.0, 60.0, 80.0)
    both = [(life("B", "pmma-1.89", F).lifetime_s, life("A", "pmma-1.89", F).lifetime_s) for F in forces]
    sooner = [F for F, (b, a) in zip(forces, both) if b < a]
    held = [F for F, (b, a) in zip(forces, both) if a > 0]
    rows.add("cup B fails sooner than cup A (pmma-1.89)", "Sec. 5.5", "yes", name,
             "yes" if len(sooner) == len(held) and held else "no", "-", expect="yes",
             reason=f"sooner at {len(sooner)} of the {len(held)} forces cup A holds ({len(forces)} tried)")
    kappas, life_k = _kappa_sweep(life, quick)
    ok = {F: np.array([x for x in life_k[F] if math.isfinite(x)]) for F in (10.0, 60.0)}
    rising = all(v.size >= 3 and np.all(np.diff(v) > 0) for v in ok.values())   # over the runs that ran
    text = "; ".join(f"{F:g} N: " + ", ".join("failed" if math.isnan(x) else f"{x:.3g}" for x in life_k[F])
                     + " s" for F in life_k)
    over = " (0 s: the cup cannot hold that force at all)" if any(x == 0 for v in life_k.values() for x in v) else ""
    rows.add("lifetime grows with kappa at F1 = 10 and 60 N", "Sec. 5.4", "yes", name,
             "yes" if rising else "no", "-", expect="yes", reason=f"kappa = {kappas}: {text}{over}")
    rows.add("at F1 = 0.1 N the lifetime first drops with kappa", "Sec. 5.4", "yes", name,
             "yes" if life_k[0.1][1] < life_k[0.1][0] else "no", "-", expect="yes",
             reason=f"not reproduced: at 0.1 N it rises from kappa = {kappas[0]:g} on ({text.split(';')[0]}); "
                    f"the paper names no mechanism for the drop, and at 0.1 N the leak through the strip "
                    f"decides alone, which a stiffer cup narrows")


def _grows_continuously(result, r: np.ndarray) -> bool:
    """r(t) grows on the way rather than stalling and jumping (the paper's observation below
    1 um rms): a stall is r moving by less than 10 % of its total rise during the first 90 % of the
    lifetime, the detachment a "rapid increase" at the end. `r`: the radius along the trajectory."""
    t = result.trajectory["t_s"]
    if result.reason not in ("reached_r1", "fold", "table_edge") or r.size < 3:
        return False
    early = t <= 0.9 * result.lifetime_s
    return float(np.ptp(r[early])) >= 0.1 * (r[-1] - r[0])


def _kappa_sweep(life, quick: bool) -> tuple[tuple[float, ...], dict[float, list[float]]]:
    """Lifetimes [s] of cup A on pmma-1.89 with F0 scaled by kappa (Fig. 1stiffnessFactor)."""
    kappas = (0.5, 1.0, 2.0) if quick else (0.25, 0.5, 1.0, 2.0, 4.0)
    return kappas, {F: [_lifetime_or_nan(life, k, F) for k in kappas] for F in (0.1, 10.0, 60.0)}


def _lifetime_or_nan(life, kappa: float, F: float) -> float:
    """The lifetime [s], or NaN where this extreme model fails (the table then says so): a soft
    cup (kappa = 0.25) on the FEM's own geometry can leave the curve or meet a dynamic fold, and
    the coupled route's table can end before the cup does."""
    try:
        return life("A", "pmma-1.89", F, kappa=kappa, t_max_s=1e10).lifetime_s
    except (ValueError, RuntimeError):
        return math.nan
