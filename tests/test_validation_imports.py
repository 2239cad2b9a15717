"""No import circles in fem, reduced or validation: no two modules of a package import each other,
directly or through others, counting the imports inside functions too (the parse of every file)."""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def import_graph(package: str = "validation") -> dict[str, set[str]]:
    """module -> the modules of `package` it imports (anywhere in the file)."""
    modules = {_module_name(p): p for p in (ROOT / package).rglob("*.py")}
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        edges = graph.setdefault(name, set())
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and (node.module or node.level):
                module = _absolute(name, path, node.module, node.level)
                targets = [f"{module}.{a.name}" if f"{module}.{a.name}" in modules else module
                           for a in node.names]
            else:
                continue
            edges.update(t for t in targets if t in modules and t != name)
    return graph


def _absolute(name: str, path: Path, module: str | None, level: int) -> str:
    """The absolute name of an import `from <level dots><module> import ...` in module `name`."""
    if level == 0:
        return module
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    base = package[:len(package) - (level - 1)]
    return ".".join(base + ([module] if module else []))


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_circle_finder_finds_a_circle():
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert circles({"a": {"b"}, "b": set()}) == []


@pytest.mark.parametrize("package, importer", [("validation", "validation.commands.lifetime"),
                                               ("reduced", "reduced.lifetime.routes"),
                                               ("fem", "fem.cup")])
def test_no_package_has_import_circles(package, importer):
    graph = import_graph(package)
    assert graph[importer]                 # the parse sees imports (absolute and relative)
    assert circles(graph) == []


def test_the_public_nouns_are_lazy():
    # `import validation` imports no heavy package; each name of __all__ resolves to its noun
    import subprocess
    import sys

    code = ("import sys, validation; heavy = [m for m in ('fem', 'skfem', 'matplotlib', 'dask') if m in sys.modules];"
            "print(heavy, len(validation.__all__));"
            "[getattr(validation, n) for n in validation.__all__]; print('ok')")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    assert out.splitlines() == [f"[] {len(__import__('validation').__all__)}", "ok"]
