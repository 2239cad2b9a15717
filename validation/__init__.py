"""Cross-checks, benchmarks, scenes, figures and the `cupcheck` command line (composes fem and reduced).

The public nouns, imported on first use (``import validation`` imports no fem, skfem,
matplotlib or dask): a case end to end (`Study` with its parts `CupDesign`, `Material`, `Contact`,
`Surface`, `Loads`, and its lazy cached `Products`), the FEM pipeline (`fem_stiffness`,
`fem_path`, `fem_curve`, `neo_hookean`, `surface_uc_table`), every lifetime (`lifetimes`,
`Lifetimes`, `route_options`, `ROUTES`), the cup a curve was computed for (`resolve_cup`,
`CupChoice`), the hand-off (`stiffness_curve`, `write_sidecar`), the cache (`Cache`), the
coupled route (`CoupledOptions`, `coupled_model`, `suction_table_for` and its grid
`SuctionGridSpec`) and scenes (`run_scene`).
"""

from __future__ import annotations

import importlib
from typing import Any

#: public name -> the module that defines it
_WHERE = {
    "fem_stiffness": "validation.bridge.pipeline", "fem_path": "validation.bridge.pipeline", "fem_curve": "validation.bridge.pipeline",
    "neo_hookean": "validation.bridge.pipeline",
    "lifetimes": "validation.bridge.lifetimes", "Lifetimes": "validation.bridge.lifetimes", "route_options": "validation.bridge.lifetimes",
    "surface_uc_table": "validation.bridge.pipeline", "DEFAULT_SURFACE": "validation.bridge.pipeline",
    "ROUTES": "validation.bridge.lifetimes",
    "resolve_cup": "validation.bridge.design", "CupChoice": "validation.bridge.design",
    "stiffness_curve": "validation.bridge.handoff", "write_sidecar": "validation.bridge.handoff",
    "Cache": "validation.bridge.cache",
    "CoupledOptions": "validation.bridge.coupled.route", "coupled_model": "validation.bridge.coupled.route",
    "suction_table_for": "validation.bridge.coupled.build", "SuctionGridSpec": "validation.bridge.coupled.build",
    "run_scene": "validation.scenes.outputs",
    "Study": "validation.bridge.study", "CupDesign": "validation.bridge.study", "Material": "validation.bridge.study",
    "Contact": "validation.bridge.study", "Surface": "validation.bridge.study", "Loads": "validation.bridge.study",
    "Products": "validation.bridge.products",
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
