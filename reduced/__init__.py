"""The reduced suction-cup leakage model of Tiwari & Persson (eqs 3-24), and its inputs.

Knows nothing of finite elements: the cup's stiffness arrives as a `StiffnessCurve` (from a CSV,
the Appendix A formula or anything else that can fill one), its response to suction as a
`SuctionTable`. A lifetime on any route:

    import reduced
    model = reduced.reference_model(reduced.CUP_A, reduced.uc_table(spectrum, 0.5))
    life = reduced.solve_lifetime(model, 10.0, route="paper")      # a reduced.Lifetime

The nouns are loaded on first use (PEP 562), so `import reduced` stays cheap.
"""

from __future__ import annotations

from reduced._lazy import lazy_exports

#: public name -> the module that defines it
_WHERE = {
    "CupParameters": "reduced.cup", "CUP_A": "reduced.cup", "CUP_B": "reduced.cup", "CUPS": "reduced.cup",
    "StiffnessCurve": "reduced.stiffness_curve", "appendix_a_curve": "reduced.appendix_a",
    "CupShape": "reduced.design", "ContactRecord": "reduced.design",
    "Gas": "reduced.gas", "AIR": "reduced.gas",
    "RelaxationModulus": "reduced.viscoelastic", "default_relaxation": "reduced.viscoelastic",
    "measurement_contact_time": "reduced.viscoelastic",
    "UcTable": "reduced.critical_gap", "uc_table": "reduced.roughness", "preset": "reduced.roughness",
    "ContactProfile": "reduced.profile_leak", "SuctionTable": "reduced.suction_table",
    "LeakageModel": "reduced.model", "reference_model": "reduced.model",
    "solve_lifetime": "reduced.lifetime", "largest_holdable_force": "reduced.lifetime",
    "Lifetime": "reduced.lifetime", "REASONS": "reduced.lifetime", "ROUTES": "reduced.lifetime",
    "Route": "reduced.lifetime", "Run": "reduced.lifetime", "register_route": "reduced.lifetime",
}

__all__ = list(_WHERE)


__getattr__, __dir__ = lazy_exports("reduced", _WHERE, globals())
