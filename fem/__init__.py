"""Axisymmetric large-deformation finite-element model of a truncated-cone suction cup.

Knows nothing of leakage: it produces the cup's response to a displacement-controlled top plate
(stiffness force, contact radius, strip width, enclosed volume, contact-pressure profile) and
under suction, as plain arrays, which `validation` hands to the reduced model.

    import fem
    mesh = fem.cup_mesh(fem.cup_geometry("A"), "coarse")
    resp = fem.compress_cup(mesh, fem.NeoHookean(E_Pa=4e6, nu=0.49), contact=fem.ContactLaw("sticking"))

The nouns below are imported on first use (PEP 562), so ``import fem`` alone stays cheap: it
loads neither scikit-fem nor scipy.
"""

from __future__ import annotations

import importlib

#: public name -> the module that defines it
_HOME = {
    # the cup job
    "compress_cup": "cup", "CupResponse": "cup", "cup_height": "cup", "CupSetup": "cup",
    "suction_grid": "suction", "SuctionGrid": "suction",
    "write_fields": "fields",
    # the design: shape, mesh, material, interface with the plane
    "cup_geometry": "geometry", "CupGeometry": "geometry", "Design": "design_file",
    "load_design": "design_file", "load_geometry": "design_file", "PRESETS": "geometry",
    "LinearThickness": "geometry", "TabulatedThickness": "geometry",
    "cup_mesh": "mesh", "mesh_spec": "mesh", "MeshSpec": "mesh", "FIDELITIES": "mesh",
    "DEFAULT_FIDELITY": "mesh", "read_mesh": "mesh_files", "write_mesh": "mesh_files",
    "NeoHookean": "material",
    "ContactLaw": "interface", "contact_law": "interface", "CONTACT_LAWS": "interface",
    "Frictionless": "laws", "Sticking": "laws", "Coulomb": "laws", "plane_law": "laws",
    # the solver and its failures
    "follow_path": "solver", "SolverOptions": "solver", "SolverStats": "solver",
    "ConvergenceError": "solver", "StateRejected": "integrity",
}

__all__ = sorted(_HOME)


def __getattr__(name: str) -> object:
    """Import a public noun's module on first use and cache the noun here."""
    try:
        module = _HOME[name]
    except KeyError:
        raise AttributeError(f"module 'fem' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
