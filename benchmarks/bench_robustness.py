"""Robustness benchmark: the FEM cases of the cross-check that used to fail, with their outcome and cost.

Cases (cup A's r0 = 5, r1 = 19 mm; the thickness line of cup A scaled to the root thickness d0, as
`validation.crosscheck.runs.FemRun` builds it; coarse mesh, E = 4 MPa, nu = 0.49):

* sweep: the alpha-d0 sweep of the Appendix A cross-check (u to 0.9 h1, max_step 0.05) cases that
  failed with ConvergenceError before the projected-Newton contact solver (13 of 40; 10 of them
  still failed before the robustness work of issue 3);
* extremes: the alpha x root-thickness grid of the extremes section (frictionless, u to h1,
  max_step 0.01) cases that failed or missed the energy check.

Per case it prints: outcome (ok, or the step where it failed, the likely cause and the first and
last relative residual of its history), load steps, Newton iterations, cut-backs (including the
steps redone because they jumped off the path, `fem.solver`), the Cholesky factorizations
attempted and failed (the diagonal shift search of unstable steps), wall time, and the checks of a
converged path: the energy balance (the largest |int F0 du - W| / W where W > 1 % of its final
value; frictionless only, sticking dissipates), the dissipated energy the solver reports
(`SolverStats.dissipated_J`) over the final stored energy, and that dissipation split by step:
snaps/W, the sum of W0 + work - W1 over the steps flagged unstable (the energy the snaps lose),
and quad./W, the sum of its absolute values over the stable steps (for frictionless contact the
trapezoid's error on F0(u), largest at u -> h1 where the wall is squeezed flat; for sticking
also the slips). Run from the repository:

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_robustness.py \
        [--only sweep|extremes] [--fidelity coarse|medium|fine] [--case frictionless/45/0.5 ...]

(--case: only the sweep cases named contact/alpha_deg/d_root_mm, e.g. the two medium-level
frictionless cases of issue 3: --fidelity medium --case frictionless/45/0.5 frictionless/60/1.)
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import cumulative_trapezoid

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fem.cup import compress_cup  # noqa: E402
from fem.mesh import cup_mesh  # noqa: E402
from validation.crosscheck.runs import FemRun  # noqa: E402

SWEEP = [(45.0, 0.5, "frictionless"), (60.0, 0.5, "frictionless"), (60.0, 1.0, "frictionless"),
         (20.0, 0.5, "sticking"), (33.0, 0.5, "sticking"), (33.0, 1.0, "sticking"),
         (45.0, 0.5, "sticking"), (45.0, 1.0, "sticking"), (45.0, 2.0, "sticking"),
         (60.0, 0.5, "sticking"), (60.0, 1.0, "sticking"), (60.0, 2.0, "sticking"),
         (60.0, 4.0, "sticking")]
EXTREMES = [(5.0, 0.1), (15.0, 0.1), (45.0, 0.1), (70.0, 0.1), (45.0, 0.5), (70.0, 0.5),
            (70.0, 5.0), (5.0, 0.5), (15.0, 0.5)]


def cases(only: str | None, fidelity: str, named: list[str] | None = None) -> list[tuple[str, FemRun]]:
    if named:
        picked = [c.split("/") for c in named]
        return [("sweep", FemRun(cup="A", contact=c, fidelity=fidelity, alpha_deg=float(a),
                                 d_root_mm=float(d))) for c, a, d in picked]
    out = []
    if only in (None, "sweep"):
        out += [("sweep", FemRun(cup="A", contact=c, fidelity=fidelity, alpha_deg=a, d_root_mm=d))
                for a, d, c in SWEEP]
    if only in (None, "extremes"):
        out += [("extremes", FemRun(cup="A", contact="frictionless", fidelity=fidelity, alpha_deg=a,
                                    d_root_mm=d, u_max_over_h1=1.0, max_step=0.01))
                for a, d in EXTREMES]
    return out


def run(req: FemRun) -> dict:
    geometry = req.geometry()
    mesh = cup_mesh(geometry, req.fidelity)
    t0 = time.perf_counter()
    try:
        r = compress_cup(mesh, req.material(), contact=req.contact,
                         u_max_m=req.u_max_over_h1 * geometry.h1_m, max_step=req.max_step)
    except RuntimeError as exc:
        return {"outcome": _short(exc), "time": time.perf_counter() - t0}
    wall = time.perf_counter() - t0
    work = cumulative_trapezoid(r.F0_N, r.u_m, initial=0.0)
    big = r.energy_J > 0.01 * r.energy_J[-1]
    energy = float(np.max(np.abs(work[big] / r.energy_J[big] - 1.0)))
    W_end = r.energy_J[-1]
    dissipated = getattr(r.stats, "dissipated_J", float("nan")) / W_end
    # per step: W0 + trapezoid work - W1; a snap across an instability (unstable steps) or the
    # trapezoid's error on F0(u) (stable steps, largest where F0 rises steeply at u -> h1)
    defect = r.energy_J[:-1] + np.diff(work) - r.energy_J[1:]
    unstable = np.asarray(r.unstable[1:], bool)
    return {"outcome": "ok", "time": wall, "steps": r.stats.steps, "its": r.stats.newton_iterations,
            "cutbacks": r.stats.cutbacks, "energy": energy, "dissipated": dissipated,
            "fact": r.stats.factorizations, "failed": r.stats.failed_factorizations,
            "snaps": float(np.sum(defect[unstable]) / W_end),
            "quadrature": float(np.sum(np.abs(defect[~unstable])) / W_end),
            "u_end": r.u_m[-1] / r.h1_m}


def _short(exc: Exception) -> str:
    """Where a solver failure happened and its likely cause (without the residual history)."""
    text = str(exc)
    where = text.split(" did not converge")[0]
    cause = text.split("): ", 1)[-1].split("; residual history")[0]
    history = text.split("residual history ")[-1].split(", ")
    return f"{type(exc).__name__}: {where}: {cause} (residual {history[0]} ... {history[-1]})"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", choices=("sweep", "extremes"))
    parser.add_argument("--fidelity", default="coarse", choices=("coarse", "medium", "fine"))
    parser.add_argument("--case", nargs="+", metavar="CONTACT/ALPHA_DEG/D_ROOT_MM",
                        help="only these cases, e.g. frictionless/45/0.5")
    args = parser.parse_args()
    print(f"{'set':8} {'case':34} {'steps':>5} {'Newton':>6} {'cuts':>4} {'fact.':>6} {'failed':>6} {'time/s':>7} "
          f"{'|W-int F du|/W':>14} {'dissip./W':>9} {'snaps/W':>8} {'quad./W':>8}  outcome")
    total, failed = 0.0, 0
    todo = cases(args.only, args.fidelity, args.case)
    total_cases = len(todo)
    for kind, req in todo:
        res = run(req)
        total += res["time"]
        label = f"{req.contact[:5]} a{req.alpha_deg:g} d0 {req.d_root_mm:g} u<={req.u_max_over_h1:g}h1"
        if res["outcome"] != "ok":
            failed += 1
            print(f"{kind:8} {label:34} {'':>5} {'':>6} {'':>4} {'':>6} {'':>6} {res['time']:7.2f} {'':>14} {'':>9} "
                  f"{'':>8} {'':>8}  {res['outcome']}", flush=True)
            continue
        print(f"{kind:8} {label:34} {res['steps']:5d} {res['its']:6d} {res['cutbacks']:4d} "
              f"{res['fact']:6d} {res['failed']:6d} {res['time']:7.2f} {res['energy']:14.2e} {res['dissipated']:9.2e} "
              f"{res['snaps']:8.1e} {res['quadrature']:8.1e}  ok", flush=True)
    print(f"{failed} failed of {total_cases}; total wall time {total:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
