"""The end-to-end example: cup A lifetime against the pull force F1 = 5, 10, ..., 80 N.

Reference mode (Appendix A stiffness, E = 4 MPa, no relaxation, air at 293.15 K, p_a = 1e5 Pa)
with the ILLUSTRATIVE u_c table of reduced/data (a power law through the paper's 0.68 um at
p/E = 0.025; a stand-in until rough-contact tables exist). Writes to DIR:

  lifetime_vs_force.csv   force_N, lifetime_s, reason, ballistic_share, r_final_mm, p_b_final_Pa
  lifetime_vs_force.png   the lifetime against F1, and r(t), p_b(t) for every force (cf. Fig. 1time.2r)
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

NAME = "example"
HELP = "cup A lifetime against pull force (reference mode, illustrative u_c): CSV and PNG"

FORCES_N = tuple(float(f) for f in range(5, 85, 5))


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (written atomically)")
    p.add_argument("--cup", default="A", metavar="A|B", help="Table 1 cup preset (default: A)")
    p.add_argument("--uc-table", default=None, metavar="FILE.csv",
                   help="critical gap table, columns p_over_E,u_c_m (u_c in m) "
                        "(default: the illustrative table)")


def lifetime_vs_force(model, forces_N=FORCES_N, progress=None):
    """The lifetime sweep of the example: a list of `LifetimeResult`, one per force."""
    from reduced.lifetime import lifetime_sweep
    return lifetime_sweep(model, forces_N, progress=progress, refine=8)


def write_table(results, path: Path) -> None:
    cols = ("force_N", "lifetime_s", "reason", "ballistic_share", "r_final_mm", "p_b_final_Pa")
    with open(path, "w") as f:
        f.write(",".join(cols) + "\n")
        for r in results:
            s = r.summary()
            life = "inf" if s["lifetime_s"] is None else f"{s['lifetime_s']:.8g}"
            f.write(f"{r.force_N:g},{life},{r.reason},{s['ballistic_share']:.6f},"
                    f"{s['r_final_mm']:.6f},{s['p_b_final_Pa']:.6g}\n")


def plot(results, path: Path, title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(13, 4), constrained_layout=True)
    finite = [r for r in results if math.isfinite(r.lifetime_s) and r.lifetime_s > 0]
    ax[0].semilogy([r.force_N for r in finite], [r.lifetime_s for r in finite], "o-")
    ax[0].set(xlabel="pull force $F_1$ (N)", ylabel="lifetime (s)", title=title)
    cmap = plt.get_cmap("viridis")
    for i, r in enumerate(results):
        c = cmap(i / max(len(results) - 1, 1))
        ax[1].plot(r.t_s, 1e3 * r.r_m, color=c)
        ax[2].plot(r.t_s, 1e-3 * r.p_b_Pa, color=c, label=f"{r.force_N:g} N" if i % 3 == 0 else None)
    ax[1].set(xlabel="time (s)", ylabel="inner contact radius r (mm)")
    ax[2].set(xlabel="time (s)", ylabel="cavity pressure $p_b$ (kPa)")
    ax[2].legend(fontsize=7)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run(args: argparse.Namespace) -> int:
    from reduced.critical_gap import ILLUSTRATIVE_UC_CSV, UcTable
    from reduced.cup import cup_by_name
    from reduced.lifetime import reference_model
    from validation.output import atomic_directory

    cup = cup_by_name(args.cup)
    uc = UcTable.from_csv(args.uc_table or ILLUSTRATIVE_UC_CSV)
    model = reference_model(cup, uc)
    with atomic_directory(args.out) as tmp:
        results = lifetime_vs_force(model)
        write_table(results, tmp / "lifetime_vs_force.csv")
        label = "illustrative u_c" if args.uc_table is None else Path(args.uc_table).name
        plot(results, tmp / "lifetime_vs_force.png", f"cup {cup.name}, reference mode, {label}")
    print(f"cup {cup.name} lifetime vs pull force (reference mode, "
          f"{'ILLUSTRATIVE u_c table' if args.uc_table is None else args.uc_table}):")
    for r in results:
        life = f"{r.lifetime_s:.4g} s" if math.isfinite(r.lifetime_s) else "inf"
        print(f"  F1 = {r.force_N:4g} N: {life:>10} ({r.reason})")
    print(f"wrote {Path(args.out) / 'lifetime_vs_force.csv'} and lifetime_vs_force.png")
    return 0
