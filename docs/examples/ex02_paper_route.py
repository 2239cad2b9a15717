"""02 The paper route: Appendix A's stiffness and the FEM's, through eq (6)'s strip.

Cup A of Table 1 on the sandblasted PMMA of 1.89 um rms (`pmma-1.89`: u_c(p/E) from Persson
theory), in the paper's reference conventions (no relaxation, E = 4 MPa, air at 293.15 K,
p_a = 1e5 Pa, the rigid cone of eqs 3-5, beta = 0.8). The model's stiffness F0(h) comes first
from Appendix A (the paper's inputs: d0 = 2 mm), then from the coarse frictionless FEM of the
same cup, written to ``cupA_coarse.csv`` (+ ``.json``) so that ``cupcheck lifetime --stiffness``
can read it.

Prints, per pull force F1 = 5, 10, 20, 40 N, the lifetime [s] and how it ended on each
stiffness, then the largest force each cup holds at all [N].
"""

from dataclasses import replace

import fem
import reduced
import validation

FORCES_N = (5.0, 10.0, 20.0, 40.0)

u_c = validation.surface_uc_table("pmma-1.89")
appendix = reduced.reference_model(reduced.CUP_A, u_c)          # Appendix A's F0, d0 = 2 mm

_, curve = validation.fem_stiffness("A", validation.neo_hookean(E_Pa=4e6, nu=0.49),
                                    fem.ContactLaw("frictionless"), "coarse")
curve.to_csv("cupA_coarse.csv")
fem_fed = replace(appendix, stiffness=curve, label="FEM-fed")   # the FEM's F0, the rest unchanged

print("cup A, pmma-1.89, paper route (eqs 3-7, beta 0.8)")
print(f"  {'F1_N':>5}  {'Appendix A (s)':>15} {'end':>11}  {'FEM coarse (s)':>15} {'end':>11}")
for F in FORCES_N:
    a = reduced.solve_lifetime(appendix, F, route="paper")
    f = reduced.solve_lifetime(fem_fed, F, route="paper")
    print(f"  {F:5g}  {a.lifetime_s:15.4g} {a.reason:>11}  {f.lifetime_s:15.4g} {f.reason:>11}")
print(f"largest holdable force: Appendix A {reduced.largest_holdable_force(appendix, route='paper'):.4g} N, "
      f"FEM coarse {reduced.largest_holdable_force(fem_fed, route='paper'):.4g} N")
print("wrote cupA_coarse.csv, cupA_coarse.json")
