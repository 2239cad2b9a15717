"""The reduced suction-cup leakage model of Tiwari & Persson (eqs 3-24), and its inputs.

Knows nothing of finite elements: the cup's stiffness arrives as a `StiffnessCurve`, from a CSV,
the Appendix A formula or anything else that can fill one.
"""

from reduced.stiffness_curve import StiffnessCurve

__all__ = ["StiffnessCurve"]
