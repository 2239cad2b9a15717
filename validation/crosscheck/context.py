"""What every section gets: the run memo, the report, the quick flag, and the shared inputs."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

from validation.crosscheck.report import Report
from validation.crosscheck.runs import FemRun, RunMemo

__all__ = ["Context", "SURFACE", "pmma_uc_table", "CROSSCHECK_FIDELITY"]

#: the calibrated surface of the lifetime sections (Sec. 5: sandblasted PMMA, 1.89 um rms)
SURFACE = "pmma-1.89"
#: the FEM level the cross-checks use unless a section studies the level itself: they sweep designs and laws (80 FEM runs): the coarse level, ~2 % in F0 (section 4
#: of the report measures it); `cupcheck stiffness` defaults to `fem.mesh.DEFAULT_FIDELITY`
CROSSCHECK_FIDELITY = "coarse"


@functools.lru_cache(maxsize=4)
def pmma_uc_table(surface: str = SURFACE, nu: float = 0.5):
    """u_c(p/E) of a calibrated surface by Persson theory (EMT, the paper's route)."""
    from reduced.roughness import uc_table
    from reduced.roughness.surfaces import preset
    return uc_table(preset(surface).spectrum(), nu)


@dataclass
class Context:
    memo: RunMemo
    report: Report
    quick: bool
    progress: Callable[[float, str], None]

    def fem(self, request: FemRun):
        """The memo's result for `request` (showing progress), raising the run's failure."""
        self.progress(0.0, request.label())
        return self.memo.get(request)

    def outcome(self, request: FemRun):
        self.progress(0.0, request.label())
        return self.memo.outcome(request)
