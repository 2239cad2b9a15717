"""03 The profile route: the leak crosses the FEM's own contact-pressure profile.

Cup A's coarse frictionless FEM curve carries, at every step, the contact radius r_c, the cavity
volume V and the contact-pressure profile p(r). The profile route (`route="profile"`) takes r and
V from the curve instead of the rigid cone and lets the air leak ring by ring across the profile
(eqs 13/19 locally, in series), raised by beta (p_a - p_b) for the suction's share. On
`pmma-1.89` the u_c table carries a patch length (202 um): the profile is averaged over patches
that wide before u_c(p) is read, which is what makes the route mesh-converged.

Prints the u_c table's patch length [um], then per F1 = 5, 10, 20, 40 N the profile route's
lifetime [s], how it ended and the ballistic share of the leak, then the largest holdable force [N].
The curve is written to ``cupA_coarse.csv`` (+ ``.json``, which holds the profiles).
"""

from dataclasses import replace

import fem
import reduced
import validation

FORCES_N = (5.0, 10.0, 20.0, 40.0)

u_c = validation.surface_uc_table("pmma-1.89")
_, curve = validation.fem_stiffness("A", validation.neo_hookean(E_Pa=4e6, nu=0.49),
                                    fem.ContactLaw("frictionless"), "coarse")
curve.to_csv("cupA_coarse.csv")
cup = validation.resolve_cup(curve).cup                   # the curve records its design: cup A
model = replace(reduced.reference_model(cup, u_c), stiffness=curve, label="FEM profile")

print(f"cup A, coarse frictionless FEM, pmma-1.89 (patch length {1e6 * u_c.patch_length_m:.0f} um), profile route")
print(f"  {'F1_N':>5}  {'lifetime (s)':>12} {'end':>11} {'ballistic':>9}")
for F in FORCES_N:
    life = reduced.solve_lifetime(model, F, route="profile")
    print(f"  {F:5g}  {life.lifetime_s:12.4g} {life.reason:>11} {life.details['ballistic_share']:9.3f}")
print(f"largest holdable force: {reduced.largest_holdable_force(model, route='profile'):.4g} N")
print("wrote cupA_coarse.csv, cupA_coarse.json")
