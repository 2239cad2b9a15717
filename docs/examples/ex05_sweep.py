"""05 A small design sweep on a dask cluster.

Two variants of cup A, cone angles 30 and 36 degrees (the paper's cup has 33), each evaluated on
a worker of a real `dask.distributed.LocalCluster` (one worker process here; give a scheduler's
address to `Client` to use a bigger cluster): the coarse frictionless FEM stiffness curve, its
small-u stiffness F0(1 mm)/1 mm against Appendix A's for the same cone (d0 = the wall at r0,
thinning to 0 at r1), and the profile route's lifetime at F1 = 10 N on `pmma-1.89` with the
largest holdable force. `cupcheck sweep SWEEP.toml` does the same at scale (grids, samples,
restarts, Parquet); this is the pattern underneath it.

Prints one row per design: alpha [deg], h1 [mm], the small-u stiffness [N/mm], its ratio to
Appendix A, the lifetime at 10 N [s] with its end, and the largest holdable force [N]. Writes
``alpha_<deg>.csv`` (+ ``.json``), each design's stiffness curve, and ``sweep.csv``, the rows.
"""

import csv
from dataclasses import replace
from pathlib import Path

import fem
import reduced
import validation

MM = 1e-3
F1_N = 10.0


def evaluate(alpha_deg: float, out_dir: str) -> dict:
    """One design, end to end, on a worker: FEM curve -> small-u stiffness -> profile lifetime."""
    geometry = fem.cup_geometry("A", alpha_deg=alpha_deg, name=f"cup A at {alpha_deg:g} deg")
    _, curve = validation.fem_stiffness(geometry, validation.neo_hookean(E_Pa=4e6, nu=0.49),
                                        fem.ContactLaw("frictionless"), "coarse")
    curve.to_csv(Path(out_dir) / f"alpha_{alpha_deg:g}.csv")
    cup = validation.resolve_cup(curve, laws="curve").cup       # r, V, l from the curve: no l0, l1 needed
    d0_m = float(geometry.thickness(geometry.r0_m))
    appendix = reduced.appendix_a_curve(cup, E_Pa=4e6, d0_m=d0_m)
    k_fem = float(curve.force(curve.h1_m - 1 * MM))
    k_app = float(appendix.force(appendix.h1_m - 1 * MM))
    model = replace(reduced.reference_model(cup, validation.surface_uc_table("pmma-1.89")), stiffness=curve)
    life = reduced.solve_lifetime(model, F1_N, route="profile")
    return {"alpha_deg": alpha_deg, "h1_mm": geometry.h1_m / MM, "small_u_stiffness_N_per_mm": k_fem,
            "appendix_a_ratio": k_fem / k_app, "lifetime_s": life.lifetime_s, "reason": life.reason,
            "largest_force_N": reduced.largest_holdable_force(model, route="profile")}


def main() -> None:
    from dask.distributed import Client, LocalCluster

    alphas = (30.0, 36.0)
    out_dir = str(Path.cwd())
    with LocalCluster(n_workers=1, threads_per_worker=1, dashboard_address=None) as cluster, Client(cluster) as client:
        rows = client.gather(client.map(evaluate, alphas, out_dir=out_dir))
    with open("sweep.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"cup A by cone angle, coarse frictionless FEM, pmma-1.89, profile route at F1 = {F1_N:g} N "
          f"(1 dask worker)")
    print(f"  {'alpha_deg':>9} {'h1_mm':>7} {'k_N_per_mm':>10} {'/AppA':>6} {'lifetime_s':>10} {'end':>11} "
          f"{'largest_N':>9}")
    for r in rows:
        print(f"  {r['alpha_deg']:9g} {r['h1_mm']:7.3f} {r['small_u_stiffness_N_per_mm']:10.4f} "
              f"{r['appendix_a_ratio']:6.3f} {r['lifetime_s']:10.4g} {r['reason']:>11} {r['largest_force_N']:9.4g}")
    print("wrote " + ", ".join(f"alpha_{a:g}.csv" for a in alphas) + ", sweep.csv")


if __name__ == "__main__":        # the worker processes import this file: run the sweep only here
    main()
