"""Accuracy per DOF of the fidelity levels: F0 (both contact laws) and the strip width l.

Cup A (E = 4 MPa, nu = 0.49) pressed from u = 0 to 0.9 h1 at each level of `fem.mesh.FIDELITIES`
with small load steps (max_step 0.01 of the range, so that sampling the curves between steps by
PCHIP adds no error of its own). The reference is the Richardson extrapolation of the three
levels (constant refinement ratio 2, `fem.postprocess.richardson`): finer than any level, and
where the three values are not in the asymptotic range (no monotone convergence) the fine level
itself. Prints per contact law and level: DOFs, steps, wall time, and the largest relative error
against the reference of

  F0            over u/h1 = 0.10, 0.15, ..., 0.90 (sticking: outside the mid-wall touchdown, see
                below), and at 0.9 h1 alone;
  l_q           the hand-off's strip width `CupResponse.l_m`: the force-quartile width
                (`postprocess.quartile_width`, innermost zone) over u/h1 = 0.50 ... 0.90;
  l_m           the median-force width (`CupResponse.l_median_m`) over the same range.

  l shift       where l(u) is steep (the sticking strip spreads from 1 to 5 mm between 0.7 and
                0.8 h1) a small shift of the curve in u is a large relative error at fixed u:
                the horizontal distance instead, max |u_level(l*) - u| / h1 over u >= 0.7 h1,
                u_level(l*) the plate displacement at which the level reaches the reference's l*.

`--extra NAxNT` runs one more mesh of the same grading (e.g. 288x16: the fine level with twice
the elements along the wall) and prints its curves and errors next to the three levels: an
independent check on the extrapolation where the convergence is not yet asymptotic.

Sticking contact (cup A): the wall rolls over its stuck rim, F0 passes a maximum and falls until
the middle of the wall touches down (u_td ~ 0.54 h1), after which F0 rises steeply (x2.5 within
0.05 h1). Near u_td the F0 error measures where each level puts the touchdown, not how well it
resolves a state, so samples within [u_td - 0.05, u_td + 0.1] h1 are left out of the F0 error
and the touchdown shift Delta u_td of each level is printed instead.

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_mesh_levels.py \\
        [--contact frictionless sticking] [--cache DIR] [--detail]

The fine level dominates the cost (30-60 s per law on one core; --extra 288x16 about 2 min);
--cache DIR keeps each level's sampled curves in DIR (an .npz per level and law) so that a second
call only prints.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fem.cup import compress_cup  # noqa: E402
from fem.geometry import cup_geometry  # noqa: E402
from fem.material import NeoHookean  # noqa: E402
from fem.mesh import FIDELITIES, MeshSpec, cup_mesh  # noqa: E402
from fem.postprocess import richardson  # noqa: E402

U_F0 = np.round(np.arange(0.10, 0.901, 0.05), 4)      # u / h1 for F0
U_L = np.round(np.arange(0.50, 0.901, 0.05), 4)       # u / h1 for the strip widths
U_DENSE = np.linspace(0.5, 0.9, 801)                # u / h1 for the horizontal l error
U_MAX = 0.9
MAX_STEP = 0.01


def run_level(level: str, contact: str, cache: Path | None, spec: MeshSpec | None = None) -> dict:
    """One level's curves sampled at U_F0 / U_L and l_q densely on U_DENSE (from `cache` if there,
    else computed); `spec` overrides the level's mesh (named `level` in the cache)."""
    spec = spec or FIDELITIES[level]
    file = cache / f"{contact}_{level}.npz" if cache else None
    if file and file.is_file():
        data = dict(np.load(file, allow_pickle=True))
        if data["spec"].item() == repr(spec) and "l_q_dense" in data and "mesh" in data:
            return {k: (v.item() if v.ndim == 0 else v) for k, v in data.items()}
    geometry = cup_geometry("A")
    t0 = time.perf_counter()
    resp = compress_cup(cup_mesh(geometry, spec), NeoHookean(), contact=contact,
                        u_max_m=U_MAX * geometry.h1_m, max_step=MAX_STEP)
    x = resp.u_m / resp.h1_m
    sample = lambda y, at: PchipInterpolator(x, y)(at)     # noqa: E731
    u_fine = np.linspace(0.3, U_MAX, 601)
    out = {"spec": repr(spec), "mesh": f"{spec.n_along}x{spec.n_through}", "dofs": int(resp.stats.dofs), "steps": int(resp.stats.steps),
           "time_s": time.perf_counter() - t0, "F0": sample(resp.F0_N, U_F0),
           "l_q": sample(resp.l_m, U_L), "l_m": sample(resp.l_median_m, U_L),
           "l_q_dense": sample(resp.l_m, U_DENSE),
           "u_td": touchdown(u_fine, sample(resp.F0_N, u_fine))}
    if file:
        file.parent.mkdir(parents=True, exist_ok=True)
        np.savez(file, **out)
    return out


def touchdown(u: np.ndarray, F0: np.ndarray) -> float:
    """u/h1 of the smallest F0 on u >= 0.3 h1 if F0 falls there before it rises (the sticking
    wall's mid-wall touchdown); NaN if the smallest value is the first (F0 only grows)."""
    k = int(np.argmin(F0))
    return float(u[k]) if k > 0 else float("nan")


def u_shift(l_dense: np.ndarray, l_ref: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Per reference sample (u, l*): the nearest u' on the level's dense curve with l(u') = l*,
    minus u [h1]; NaN where the curve never reaches l*."""
    out = np.full(u.shape, np.nan)
    for k, (uk, lk) in enumerate(zip(u, l_ref)):
        side = np.sign(l_dense - lk)
        cross = np.flatnonzero(side[:-1] * side[1:] <= 0)
        if cross.size:
            a, b = l_dense[cross], l_dense[cross + 1]
            t = np.where(b != a, (lk - a) / np.where(b != a, b - a, 1.0), 0.0)
            uc = U_DENSE[cross] + t * (U_DENSE[cross + 1] - U_DENSE[cross])
            out[k] = uc[np.argmin(np.abs(uc - uk))] - uk
    return out


def report(contact: str, runs: list[dict], detail: bool, extra: dict | None = None) -> None:
    rich = {q: richardson(*(r[q] for r in runs)) for q in ("F0", "l_q", "l_m")}
    u_td = runs[-1]["u_td"]
    smooth = np.ones(U_F0.size, bool) if np.isnan(u_td) else \
        (U_F0 < u_td - 0.05 - 1e-9) | (U_F0 > u_td + 0.10 + 1e-9)
    print(f"\ncup A, {contact} contact, u = 0 .. {U_MAX} h1, max_step {MAX_STEP}; reference: Richardson "
          f"extrapolation of the levels ({', '.join(f'{s.n_along}x{s.n_through}' for s in FIDELITIES.values())})")
    if not np.isnan(u_td):
        print(f"  mid-wall touchdown at u_td = {u_td:.3f} h1 (fine level); F0 errors leave out "
              f"u/h1 in [{u_td - 0.05:.2f}, {u_td + 0.10:.2f}]")
    print(f"{'level':8} {'mesh':>7} {'DOFs':>6} {'steps':>5} {'time/s':>7} | {'F0 err':>7} {'<=0.85':>6} "
          f"{'@0.9':>6} {'du_td':>6} | {'l_q err':>7} {'l_m err':>7} {'l_q>=.7':>7} {'shift':>6}  "
          f"(l: u >= {U_L[0]} h1; last two u >= 0.7 h1, shift in h1)")
    late = U_L >= 0.7 - 1e-9
    named = list(zip(FIDELITIES, runs)) + ([("extra", extra)] if extra else [])
    for level, r in named:
        e = {q: np.abs(r[q] / rich[q].extrapolated - 1) for q in rich}
        shift = u_shift(r["l_q_dense"], rich["l_q"].extrapolated[late], U_L[late])
        print(f"{level:8} {r['mesh']:>7} {r['dofs']:>6} {r['steps']:>5} {r['time_s']:>7.1f} | "
              f"{100 * e['F0'][smooth].max():>6.2f}% {100 * e['F0'][smooth & (U_F0 <= 0.85)].max():>5.2f}% "
              f"{100 * e['F0'][-1]:>5.2f}% {r['u_td'] - u_td:>+6.3f} | "
              f"{100 * e['l_q'].max():>6.2f}% {100 * e['l_m'].max():>6.2f}% {100 * e['l_q'][late].max():>6.2f}% "
              f"{np.nanmax(np.abs(shift)):>6.4f}")
    for q in ("F0", "l_q", "l_m"):
        order = rich[q].order
        ok = np.isfinite(order)
        print(f"  observed order of {q:4}: median {np.median(order[ok]) if ok.any() else float('nan'):.2f} "
              f"over {ok.sum()}/{order.size} samples in the asymptotic range")
    if detail:
        for q, grid, unit in (("F0", U_F0, 1.0), ("l_q", U_L, 1e3), ("l_m", U_L, 1e3)):
            print(f"  {q} per u/h1: coarse, medium, fine | extrapolated, order" + (" | extra" if extra else ""))
            for k, u in enumerate(grid):
                vals = " ".join(f"{unit * r[q][k]:9.4f}" for r in runs)
                more = f" | {unit * extra[q][k]:9.4f}" if extra else ""
                print(f"    {u:4.2f} {vals} | {unit * rich[q].extrapolated[k]:9.4f} {rich[q].order[k]:5.2f}{more}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--contact", choices=("frictionless", "sticking"), nargs="+",
                        default=["frictionless", "sticking"])
    parser.add_argument("--cache", type=Path, default=None, help="directory for the sampled curves")
    parser.add_argument("--detail", action="store_true", help="also print the sampled curves per u")
    parser.add_argument("--extra", metavar="NAxNT", default=None,
                        help="one more mesh of the same grading, n_along x n_through (e.g. 288x16)")
    args = parser.parse_args()
    print("levels:", {k: asdict(v) for k, v in FIDELITIES.items()}["coarse"], "(coarse; x2, x4)")
    for contact in args.contact:
        runs, failures = [], []
        for level in FIDELITIES:
            try:
                runs.append(run_level(level, contact, args.cache))
            except RuntimeError as exc:       # a level whose path cannot be followed: say so
                failures.append(f"{level}: {exc}")
        if failures:
            print(f"\ncup A, {contact} contact: no Richardson reference, a level failed")
            for r in runs:
                print(f"  {r['dofs']:>6} DOFs {r['steps']:>4} steps {r['time_s']:>7.1f} s  F0(0.9 h1) = {r['F0'][-1]:.4g} N")
            for failure in failures:
                print(f"  FAILED {failure}")
        else:
            extra = None
            if args.extra:
                na, nt = (int(k) for k in args.extra.lower().split("x"))
                spec = replace(FIDELITIES["fine"], n_along=na, n_through=nt)
                extra = run_level(f"extra_{na}x{nt}", contact, args.cache, spec)
            report(contact, runs, args.detail, extra)
    return 0


if __name__ == "__main__":
    sys.exit(main())
