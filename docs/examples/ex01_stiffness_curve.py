"""01 The stiffness curve of a new design.

A cup that is not in the paper: r0 = 5 mm, r1 = 25 mm, a 40 degree cone, and a wall whose
thickness is a table (2.2 mm at the top plate, 1.0 mm halfway, 0.4 mm at the rim). The
axisymmetric finite-strain FEM (coarse mesh, compressible neo-Hookean E = 4 MPa, nu = 0.49,
frictionless plane) presses it to 0.9 h1; the hand-off `StiffnessCurve` is written to
``new_cup.csv`` (u_mm,h_mm,F0_N,r_c_mm,l_mm,V_mm3) with its provenance, the design included, in
the sidecar ``new_cup.json``.

Prints the design's height h1, then F0 at u = 0.5, 1, 2, 4 mm, the small-u stiffness F0(0.5 mm)/0.5 mm
next to Appendix A's closed form for the same cone (wall d0 = 2.2 mm at r0, thinning to 0 at r1,
E = 4 MPa), and the files written.
"""

import math

import fem
import reduced
import validation

MM = 1e-3

design = fem.Design(
    geometry=fem.CupGeometry(
        r0_m=5 * MM, r1_m=25 * MM, alpha_deg=40.0, name="new cup",
        thickness=fem.TabulatedThickness(r_m=(5 * MM, 15 * MM, 25 * MM), d_m=(2.2 * MM, 1.0 * MM, 0.4 * MM))),
    contact=fem.ContactLaw("frictionless"))

material = validation.neo_hookean(E_Pa=4e6, nu=0.49)
response, curve = validation.fem_stiffness(design.geometry, material, design.contact, "coarse")
curve.to_csv("new_cup.csv")             # and new_cup.json, the provenance

g = design.geometry
print(f"design: r0 {g.r0_m / MM:g} mm, r1 {g.r1_m / MM:g} mm, alpha {g.alpha_deg:g} deg, "
      f"h1 = {g.h1_m / MM:.4f} mm; FEM coarse, {response.stats.steps} steps")
print("   u_mm     F0_N")
for u_mm in (0.5, 1.0, 2.0, 4.0):
    print(f"  {u_mm:5.2f}  {float(curve.force(curve.h1_m - u_mm * MM)):7.4f}")

# Appendix A: the same cone flattened with d(x) falling linearly from d0 at r0 to 0 at r1
cup = validation.resolve_cup(curve).cup
appendix = reduced.appendix_a_curve(cup, E_Pa=4e6, d0_m=2.2 * MM)
k_fem = float(curve.force(curve.h1_m - 0.5 * MM)) / 0.5
k_app = float(appendix.force(appendix.h1_m - 0.5 * MM)) / 0.5
print(f"small-u stiffness F0(0.5 mm)/0.5 mm: FEM {k_fem:.4f} N/mm, Appendix A {k_app:.4f} N/mm "
      f"(ratio {k_fem / k_app:.3f})")
print("wrote new_cup.csv, new_cup.json")
