"""fem's public face: its nouns from `import fem` and a cheap import (import circles:
tests/test_validation_imports.py, for every package)."""

from __future__ import annotations

import importlib
import subprocess
import sys

import fem



def test_import_fem_loads_no_numerical_library():
    """`import fem` alone (as a command that needs no FEM does) imports neither skfem nor scipy."""
    code = ("import sys, fem; print(','.join(m for m in ('skfem', 'scipy', 'meshio') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_every_public_noun_is_its_modules_own():
    """Each name of fem.__all__ is the object its home module defines (and lists in __all__)."""
    for name in fem.__all__:
        home = importlib.import_module(f"fem.{fem._HOME[name]}")
        assert getattr(fem, name) is getattr(home, name), name
        assert name in home.__all__, name
