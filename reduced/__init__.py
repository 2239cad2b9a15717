"""The reduced suction-cup leakage model of Tiwari & Persson (eqs 3-24), and its inputs.

Knows nothing of finite elements: the cup's stiffness arrives as a `StiffnessCurve`, from a CSV,
the Appendix A formula or anything else that can fill one.
"""

from reduced.stiffness_curve import StiffnessCurve

__all__ = ["StiffnessCurve"]
# The reduced model's nouns live in their modules (import them from there):
#   reduced.cup (CupParameters, CUP_A, CUP_B), reduced.appendix_a (appendix_a_curve),
#   reduced.gas (Gas, AIR, leak-rate laws), reduced.viscoelastic (RelaxationModulus),
#   reduced.critical_gap (UcTable), reduced.lifetime (LeakageModel, reference_model, lifetime).
