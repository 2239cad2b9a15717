"""Speed against accuracy of the whole pipeline (the `speed` section of `cupcheck validate`).

For cup A, both contact laws: Appendix A, the FEM at coarse / medium / fine Q2 and coarse / medium
P2-triangle meshes, and the reduced model's rtol levels; wall time and the relative error of F0(1 mm),
F0 and l at the start state and the lifetime at F1 = 20 N (pmma-1.89) against the Richardson
reference. Every FEM run is computed afresh (no cache), one after the other. Run from the repository:

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_fidelity.py [--quick]

Prints the section's tables and recommendation (Markdown). FEM wall times are single runs: on a
shared machine repeat the script and take the median.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
os.environ.setdefault("MPLBACKEND", "Agg")

from validation.crosscheck import run_validation  # noqa: E402
from validation.output import terminal_progress  # noqa: E402


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="coarse level only (no extrapolation)")
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        report = run_validation(tmp, quick=args.quick, only=["speed"], scene=False,
                                progress=terminal_progress("bench_fidelity"))
        print("".join(report.pages["speed"][1:]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
