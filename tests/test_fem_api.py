"""fem's public face: its nouns from `import fem`, a cheap import, and no import circles."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import fem

FEM = Path(fem.__file__).parent


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


def _imports(path: Path) -> set[str]:
    """The fem modules a file imports (relative or absolute, at any level of the file)."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            parts = node.module.split(".")
            if node.level == 1:
                out.add(parts[0])
            elif node.level == 0 and parts[0] == "fem" and len(parts) > 1:
                out.add(parts[1])
        elif isinstance(node, ast.Import):
            out |= {a.name.split(".")[1] for a in node.names if a.name.startswith("fem.")}
    return out


def test_no_fem_modules_import_each_other_in_a_loop():
    graph = {p.stem: _imports(p) for p in FEM.glob("*.py")}
    for start in graph:
        seen, todo = set(), list(graph[start])
        while todo:
            m = todo.pop()
            assert m != start, f"import circle through fem.{start}"
            if m not in seen:
                seen.add(m)
                todo.extend(graph.get(m, ()))
