"""The table-coupled route from the paper's start as the study's products build it: cup A coarse,
frictionless, pmma-1.89, the table around the paths of 5, 10, 20, 40 N and the largest holdable
force (`goal_for`), in a fresh cache: its states and CPU, the lifetimes and the largest force.
    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_coupled_paper_start.py [--counters] [--exact]
--counters: also the build's paths by kind (bench_coupled_counters.py); --exact: every digit.
"""
import argparse
import contextlib
import dataclasses
import tempfile
import time

import reduced
from validation.bridge.coupled.adaptive import goal_for
from validation.bridge.coupled.build import suction_table_for
from validation.bridge.pipeline import surface_uc_table

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--counters", action="store_true", help="the build's paths by kind")
parser.add_argument("--asked", default=None, help="with --counters: write the states asked, in order (JSON)")
parser.add_argument("--exact", action="store_true", help="also print the lifetimes and the force to every digit")
args = parser.parse_args()
if args.counters:
    from bench_coupled_counters import counting
forces = (5.0, 10.0, 20.0, 40.0)
model = reduced.reference_model(reduced.CUP_A, surface_uc_table())
t = time.process_time()
with tempfile.TemporaryDirectory() as cache, (counting() if args.counters else contextlib.nullcontext()) as counted:
    table = suction_table_for("A", fidelity="coarse", goal=goal_for(model, forces), cache_dir=cache)
build = time.process_time() - t
print(f"build: {table.provenance.get('states_solved')} states solved, {build:.1f} s CPU", flush=True)
if counted is not None:
    print(counted.report(), flush=True)
    print("rounds (states built, missing):", table.provenance.get("rounds"), flush=True)
    if args.asked:
        import json
        with open(args.asked, "w") as f:
            json.dump(counted.asked, f)
m = dataclasses.replace(model, suction=table)
for F in forces:
    r = reduced.solve_lifetime(m, F, route="coupled")
    print(f"F1 = {F:g} N: {r.lifetime_s:.4g} s, {r.reason}" + (f" ({r.lifetime_s!r})" if args.exact else ""),
          flush=True)
largest = reduced.largest_holdable_force(m, route='coupled')
print(f"largest holdable force {largest:.4g} N" + (f" ({largest!r})" if args.exact else "")
      + f"; total {time.process_time() - t:.1f} s CPU")
