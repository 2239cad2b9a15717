"""Axisymmetric large-deformation finite-element model of a truncated-cone suction cup.

Knows nothing of leakage: it produces the cup's response to a displacement-controlled top plate
(stiffness force, contact radius, strip width, enclosed volume, contact-pressure profile) as
plain arrays, which `validation` hands to the reduced model as a `StiffnessCurve`.
"""
