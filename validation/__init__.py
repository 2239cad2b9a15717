"""Cross-checks, benchmarks, scenes, figures and the `cupcheck` command line (composes fem and reduced).

The public nouns, imported on first use (``import validation`` imports no fem, skfem,
matplotlib or dask): a case end to end (`Study` with its parts `CupDesign`, `Material`, `Contact`,
`Surface`, `Loads`, and its lazy cached `Products`), the FEM pipeline (`fem_stiffness`,
`fem_path`, `fem_curve`, `neo_hookean`, `surface_uc_table`), every lifetime (`lifetimes`,
`Lifetimes`, `route_options`, `ROUTES`), the cup a curve was computed for (`resolve_cup`,
`CupChoice`), the hand-off (`stiffness_curve`, `write_sidecar`), the cache (`Cache`), the
coupled route (`CoupledOptions`, `coupled_model`, `suction_table_for`) and scenes (`run_scene`).
"""

from __future__ import annotations

import importlib
from typing import Any

#: public name -> the module that defines it
_WHERE = {
    "fem_stiffness": "validation.pipeline", "fem_path": "validation.pipeline", "fem_curve": "validation.pipeline",
    "neo_hookean": "validation.pipeline",
    "lifetimes": "validation.lifetimes", "Lifetimes": "validation.lifetimes", "route_options": "validation.lifetimes",
    "surface_uc_table": "validation.pipeline", "DEFAULT_SURFACE": "validation.pipeline",
    "ROUTES": "validation.lifetimes",
    "resolve_cup": "validation.design", "CupChoice": "validation.design",
    "stiffness_curve": "validation.handoff", "write_sidecar": "validation.handoff",
    "Cache": "validation.cache",
    "CoupledOptions": "validation.coupled.route", "coupled_model": "validation.coupled.route",
    "suction_table_for": "validation.coupled.build",
    "run_scene": "validation.scenes.outputs",
    "Study": "validation.study", "CupDesign": "validation.study", "Material": "validation.study",
    "Contact": "validation.study", "Surface": "validation.study", "Loads": "validation.study",
    "Products": "validation.products",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module 'validation' has no attribute {name!r}")
    value = getattr(importlib.import_module(_WHERE[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
