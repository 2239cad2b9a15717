"""The coupled route's accuracy and cost: lifetimes of cup A on pmma-1.89 from FEM suction tables
of several grids and meshes, beside the paper route, and beta as the FEM sees it.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_coupled.py [--tables DIR]
    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_coupled.py --adaptive [--tables DIR]
    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_coupled.py --around [--tables DIR]

Tables (frictionless cup A, `fem.suction`; built once and kept as JSON in --tables, default
out/bench_coupled): the default grid of `cupcheck suction` (u = 0.001 ... 0.8 h1, 105 values;
dp = 0 ... 100 kPa in 1 kPa) on the coarse and medium meshes, and on the coarse
mesh the same with every other u or dp dropped, every u or dp interval halved, and one more u at
0.0025 h1. Prints per
table its build time and the lifetimes at F1 = 5, 10, 20, 30 N (interface gas linear), their
differences from the refined grids (the interpolation error) and from the medium mesh, the
largest holdable force, the lifetime cost, and eq 6's beta from the medium table.

--adaptive: the coarse default grid's table against the adaptive one built for F1 = 5, 10, 20,
40 N (`validation.bridge.coupled.adaptive`): states solved and CPU seconds of each, the lifetimes,
the largest holdable force and their differences (the adaptive table's interpolation error).

--around: the same for the table with holes built around the paths of those forces
(`validation.bridge.coupled.around`): states solved, rounds, CPU seconds of the build (the FEM
and the lifetimes it runs), the lifetimes and largest holdable force against the full table's.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from fem.cup import cup_height
from fem.geometry import cup_geometry
from fem.material import NeoHookean
from fem.mesh import cup_mesh
from fem.suction import suction_grid
from reduced.lifetime import LeakageModel, largest_holdable_force, solve_lifetime
from reduced.suction_table import SuctionTable
from validation.cli import build_parser
from validation.commands.lifetime import build_model, build_uc
from validation.bridge.coupled.build import DEFAULT_GRID

U_FRACTIONS, DP_KPA = DEFAULT_GRID.u_fractions, DEFAULT_GRID.dp_kPa
from validation.bridge.coupled.table import fem_beta, suction_table

FORCES_N = (5.0, 10.0, 20.0, 30.0)


def _halved(x: np.ndarray) -> np.ndarray:
    return np.sort(np.concatenate([x, 0.5 * (x[1:] + x[:-1])]))


def grids() -> dict[str, tuple[str, np.ndarray, np.ndarray]]:
    u, dp = np.array(U_FRACTIONS), np.array(DP_KPA)
    return {"coarse": ("coarse", u, dp), "coarse u/2": ("coarse", _halved(u), dp),
            "coarse dp/2": ("coarse", u, _halved(dp)),
            "coarse +u_min/2": ("coarse", np.concatenate([[u[0] / 2], u]), dp),
            "coarse u*2": ("coarse", u[::2], dp), "coarse dp*2": ("coarse", u, dp[::2]),
            "medium": ("medium", u, dp)}


def table(name: str, level: str, u_frac: np.ndarray, dp_kPa: np.ndarray, folder: Path) -> tuple[SuctionTable, float]:
    path = folder / f"{level}_{u_frac.size}x{dp_kPa.size}_{u_frac[0]:g}.json"
    if path.exists():
        t = SuctionTable.from_json(path)
        return t, float(t.provenance["solver"]["wall_time_s"])
    mesh = cup_mesh(cup_geometry("A"), level)
    g = suction_grid(mesh, NeoHookean(), u_frac * cup_height(mesh), 1e3 * dp_kPa)
    t = suction_table(g, {"fidelity": level})
    folder.mkdir(parents=True, exist_ok=True)
    t.to_json(path)
    return t, g.stats.wall_time_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tables", type=Path, default=Path("out/bench_coupled"))
    parser.add_argument("--adaptive", action="store_true", help="the adaptive table against the full one")
    parser.add_argument("--around", action="store_true", help="the table around the paths against the full one")
    args = parser.parse_args()
    cli = build_parser().parse_args(["lifetime", "--surface", "pmma-1.89", "--force", "5"])
    uc, paper = build_uc(cli), build_model(cli).model
    if args.adaptive or args.around:
        adaptive_against_full(paper, uc, args.tables, "around" if args.around else "adaptive")
        return
    u_start = paper.cup.h1_m - paper.cup.h_start_m
    print(f"paper route: " + ", ".join(f"{solve_lifetime(paper, F, route='paper').lifetime_s:.4g}" for F in FORCES_N)
          + f" s at F1 = {', '.join(f'{F:g}' for F in FORCES_N)} N")
    rows = {}
    for name, (level, u, dp) in grids().items():
        t, build_s = table(name, level, u, dp, args.tables)
        model = LeakageModel(cup=paper.cup, suction=t, u_c=uc, gas=paper.gas, p_a_Pa=paper.p_a_Pa)
        start = time.perf_counter()
        life = np.array([solve_lifetime(model, F, route="coupled", u_start_m=u_start).lifetime_s
                         for F in FORCES_N])
        cost = (time.perf_counter() - start) / len(FORCES_N)
        rows[name] = life
        print(f"{name:>16}: {t.u_m.size:2d} x {t.dp_Pa.size:2d} states, table {build_s:6.1f} s; lifetimes "
              + ", ".join(f"{x:.4g}" for x in life) + f" s ({1e3 * cost:.0f} ms each); largest "
              f"holdable force {largest_holdable_force(model, route='coupled', u_start_m=u_start):.4g} N")
    base = rows["coarse"]
    for name in ("coarse u*2", "coarse dp*2", "coarse u/2", "coarse dp/2", "coarse +u_min/2", "medium"):
        diff = 100 * (base / rows[name] - 1)
        print(f"coarse default grid against {name:>16}: " + ", ".join(f"{d:+.2f} %" for d in diff))
    medium, _ = table("medium", *grids()["medium"], args.tables)
    beta = fem_beta(medium)
    rows_u = [0.1, 0.25, 0.4, 0.55, 0.7]
    cols = [int(np.argmin(np.abs(medium.dp_Pa[1:] - 1e3 * d))) for d in (10, 30, 60, 100)]
    print("beta (medium), dp = 10 / 30 / 60 / 100 kPa:")
    for f in rows_u:
        i = int(np.argmin(np.abs(np.array(U_FRACTIONS) - f)))
        print(f"  u = {f:g} h1: " + " / ".join(f"{beta[i, j]:.2f}" for j in cols))


ADAPTIVE_FORCES_N = (5.0, 10.0, 20.0, 40.0)


def adaptive_against_full(paper, uc, folder: Path, kind: str = "adaptive") -> None:
    """Lifetimes, largest holdable force and cost of the full coarse table and the adaptive one
    (kind 'adaptive': a tensor sub-grid; 'around': the table with holes around the paths)."""
    from validation.bridge.coupled.build import AdaptiveSpec, AroundSpec, SuctionGoal, suction_table_for

    goal = SuctionGoal(LeakageModel(cup=paper.cup, u_c=uc, gas=paper.gas, p_a_Pa=paper.p_a_Pa), ADAPTIVE_FORCES_N)
    u, dp = np.array(U_FRACTIONS), np.array(DP_KPA)
    full, _ = table("coarse", "coarse", u, dp, folder)
    cpu = time.process_time()
    adaptive = suction_table_for("A", fidelity="coarse", goal=goal,
                                 adaptive=AroundSpec() if kind == "around" else AdaptiveSpec())
    adaptive_cpu = time.process_time() - cpu
    if kind == "around":
        print(f"around the paths: {int(adaptive.built.sum())} states in the table, rounds (states, missing): "
              f"{adaptive.provenance['rounds']}")
    rows = {}
    for name, t in (("full", full), (kind, adaptive)):
        model = replace(goal.model, suction=t)
        cpu = time.process_time()
        life = [solve_lifetime(model, F, route="coupled") for F in ADAPTIVE_FORCES_N]
        largest = largest_holdable_force(model, route="coupled")
        rows[name] = (np.array([r.lifetime_s for r in life]), largest, [r.reason for r in life])
        states = t.provenance.get("states_solved", t.u_m.size * t.dp_Pa.size)
        built = t.provenance["solver"]["wall_time_s"]
        print(f"{name:>8}: {t.provenance.get('grid', f'{t.u_m.size} u x {t.dp_Pa.size} dp')}, {states} states solved, "
              f"FEM {built:.1f} s wall" + (f", {adaptive_cpu:.1f} s CPU to build the product" if name == kind else "")
              + f"; lifetimes " + ", ".join(f"{x:.8g} ({r})" for x, r in zip(rows[name][0], rows[name][2]))
              + f" s at {', '.join(f'{F:g}' for F in ADAPTIVE_FORCES_N)} N; largest holdable {largest:.8g} N; "
              f"lifetimes and largest force {time.process_time() - cpu:.1f} s CPU")
    (a, fa, _), (b, fb, _) = rows[kind], rows["full"]
    diff = np.where(b > 0, 100 * (a / np.where(b > 0, b, 1) - 1), 0.0)
    print(f"{kind} against full: " + ", ".join(f"{d:+.2e} %" for d in diff)
          + f"; largest holdable force {100 * (fa / fb - 1):+.2e} %")


if __name__ == "__main__":
    main()
