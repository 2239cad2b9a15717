"""04 The coupled route on a small suction table (a coarse illustration).

The coupled route lets the cavity's suction act on the FEM cup: for every plate displacement u and
pressure difference dp = p_a - p_b the FEM gives the pull F1, the cavity volume, the seal radius
and the contact-pressure profile, and the reduced model moves through those states as air leaks
in (no rigid cone, no eqs 5-7, no beta). Here the table is small, cup A's coarse frictionless
FEM on 9 u x 8 dp states (~15 s), where the default grid has 105 x 101 (~5 min); its lifetimes
move by several per cent from the default table's, so they illustrate, they do not measure.

Prints the table's size and the cup's starting displacement u_start [mm], then per F1 = 5, 10,
20 N the lifetime [s], how it ended and the final u [mm], then the largest holdable force [N].
The table is written to ``suction_table.json`` (``cupcheck lifetime --route coupled
--suction-table`` reads it).
"""

import fem
import reduced
import validation

FORCES_N = (5.0, 10.0, 20.0)

grid = validation.SuctionGridSpec(u_fractions=(0.005, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8),   # of h1
                                  dp_kPa=(0.0, 2.0, 5.0, 10.0, 20.0, 40.0, 70.0, 100.0))
table = validation.suction_table_for("A", fidelity="coarse", contact=fem.ContactLaw("frictionless"), grid=grid)
table.to_json("suction_table.json")

model = reduced.LeakageModel(cup=reduced.CUP_A, suction=table, u_c=validation.surface_uc_table("pmma-1.89"),
                             label="coupled, small table")
u_start_m = table.h1_m - reduced.CUP_A.h_start_m
print(f"cup A, coarse frictionless FEM suction table {table.F1_N.shape[0]} u x {table.F1_N.shape[1]} dp, "
      f"pmma-1.89, coupled route; u_start = {1e3 * u_start_m:.4g} mm")
print(f"  {'F1_N':>5}  {'lifetime (s)':>12} {'end':>11} {'u_end_mm':>8}")
for F in FORCES_N:
    life = reduced.solve_lifetime(model, F, route="coupled")
    print(f"  {F:5g}  {life.lifetime_s:12.4g} {life.reason:>11} {life.trajectory['u_mm'][-1]:8.3f}")
print(f"largest holdable force: {reduced.largest_holdable_force(model, route='coupled'):.4g} N")
print("wrote suction_table.json")
