"""The design card's layering: fem knows nothing of leakage, reduced nothing of FEM."""

import subprocess
import sys

import pytest

_CHECK = """
import importlib, pkgutil, sys
pkg = importlib.import_module({pkg!r})
for m in pkgutil.walk_packages(pkg.__path__, prefix={pkg!r} + "."):
    importlib.import_module(m.name)
bad = sorted(name for name in sys.modules if name.split(".")[0] in {forbidden!r})
print(",".join(bad))
"""


@pytest.mark.parametrize("pkg,forbidden", [
    ("fem", ("reduced", "validation")),
    ("reduced", ("fem", "validation", "skfem", "pyvista", "vtk")),
])
def test_package_does_not_import(pkg, forbidden):
    out = subprocess.run([sys.executable, "-c", _CHECK.format(pkg=pkg, forbidden=set(forbidden))],
                         capture_output=True, text=True, check=True).stdout.strip()
    assert out == "", f"{pkg} imports {out}"
