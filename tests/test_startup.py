"""A command imports only what it uses: `cupcheck --help` and bare `cupcheck` import no command
module (nor numpy); a reduced-model-only command (`lifetime --route paper`, `uc`) imports no FEM
machinery, no plotting, no dask, no pyvista, no scipy.signal; the paper route's lifetime on a preset
surface imports no scipy at all (its u_c table is stored, its interpolants and roots are the
project's own: scipy.interpolate and scipy.optimize cost ~0.5 s to import, more than the command);
the profile route's lifetime on an FEM curve's CSV imports no scipy either (its flow tables' spline
is the project's own); a stiffness curve without a mesh file imports no meshio, nor scipy.optimize.
Each case is a fresh process (the modules a test session has already loaded say nothing), its
`sys.modules` read after the command ran.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from validation.cli import COMMANDS

ROOT = Path(__file__).resolve().parents[1]
#: top-level packages no reduced-model-only command may import
HEAVY = ("skfem", "matplotlib", "dask", "distributed", "pyvista", "vtk", "meshio", "pandas", "joblib")
#: the only fem modules a reduced-model command may touch: the numpy-only design records (a Table 1
#: cup's shape, its interface with the plane), never the mesh, forms or solver
FEM_RECORDS = {"fem", "fem.geometry", "fem.interface"}


def _modules_after(argv: list[str], tmp_path: Path) -> set[str]:
    """The modules loaded in a fresh process that ran `cupcheck ARGV` (exit status 0 asserted)."""
    code = ("import contextlib, io, json, sys\n"
            "from validation.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    try:\n"
            f"        status = main({argv!r})\n"
            "    except SystemExit as exc:\n"
            "        status = exc.code\n"
            "print(json.dumps({'status': status, 'modules': sorted(sys.modules)}))\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "CUPCHECK_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["status"] in (0, None), done.stderr
    return set(result["modules"])


def _top(modules: set[str]) -> set[str]:
    return {m.split(".")[0] for m in modules}


@pytest.mark.parametrize("argv", [[], ["--help"], ["--version"]], ids=["bare", "help", "version"])
def test_listing_the_commands_imports_none_of_them(argv, tmp_path):
    modules = _modules_after(argv, tmp_path)
    assert not {m for m in modules if m.startswith("validation.commands.")}
    assert not _top(modules) & {"numpy", "scipy", "fem", "reduced", *HEAVY}


@pytest.mark.parametrize("argv", [
    ["lifetime", "--cup", "A", "--force", "10", "--route", "paper"],
    ["uc", "--surface", "pmma-1.89", "--E-MPa", "4", "--p-kPa", "10", "50"],
], ids=["lifetime-paper", "uc"])
def test_a_reduced_model_command_imports_no_fem_and_no_plotting(argv, tmp_path):
    modules = _modules_after(argv, tmp_path)
    assert not _top(modules) & set(HEAVY), sorted(m for m in modules if m.split(".")[0] in HEAVY)[:10]
    assert "scipy.signal" not in modules
    assert {m for m in modules if m.split(".")[0] == "fem"} <= FEM_RECORDS
    assert "validation.crosscheck" not in modules
    # the test can fail: the command did run the reduced model
    assert "reduced.lifetime" in modules or "reduced.roughness" in modules


@pytest.mark.parametrize("argv", [
    ["lifetime", "--cup", "A", "--force", "10", "--route", "paper"],
    ["lifetime", "--reference-mode", "--force", "5", "80"],
    ["lifetime", "--cup", "B", "--force", "10", "40", "--surface", "table", "--relaxation", "default"],
], ids=["paper", "reference-mode", "relaxed"])
def test_the_paper_route_imports_no_scipy(argv, tmp_path):
    modules = _modules_after(argv, tmp_path)
    assert "scipy" not in _top(modules), sorted(m for m in modules if m.startswith("scipy"))[:10]
    # the test can fail: the lifetime was computed, on the force balance and a u_c table
    assert {"reduced.force_balance", "reduced.critical_gap", "reduced.roughness.stored"} <= modules


@pytest.fixture(scope="module")
def coarse_curve(tmp_path_factory) -> tuple[Path, set[str]]:
    """A coarse cup A curve (CSV and sidecar with its profiles) and the modules its command loaded."""
    tmp = tmp_path_factory.mktemp("coarse")
    modules = _modules_after(["stiffness", "--cup", "A", "--fidelity", "coarse", "--out", str(tmp / "c.csv")], tmp)
    return tmp / "c.csv", modules


def test_a_fem_command_does_import_the_fem(coarse_curve):
    """The checks above see imports: a command that runs the FEM shows skfem (and scipy); without
    a mesh file it reads none (no meshio); its contact step's NNLS is scipy's compiled one, without
    the package scipy.optimize (`fem.nnls`: ~0.17 s of its import)."""
    _, modules = coarse_curve
    assert {"skfem", "scipy"} <= _top(modules)
    assert "meshio" not in _top(modules)
    assert "fem.nnls" in modules
    from tests.test_fem_nnls import ships_the_kernel
    if ships_the_kernel():                                   # scipy >= 1.15 (the lower bound 1.11 has not)
        assert "scipy.optimize._slsqplib" in modules
        assert not {"scipy.optimize", "scipy.special", "scipy.fft"} & modules


def test_the_profile_route_on_a_curve_imports_no_scipy(coarse_curve, tmp_path):
    curve, _ = coarse_curve
    modules = _modules_after(["lifetime", "--stiffness", str(curve), "--route", "profile", "--surface",
                              "pmma-1.89", "--force", "10", "40"], tmp_path)
    assert "scipy" not in _top(modules), sorted(m for m in modules if m.startswith("scipy"))[:10]
    assert not _top(modules) & set(HEAVY)
    # the test can fail: the lifetime went through the profile's flow tables
    assert {"reduced.seal", "reduced.profile_leak", "reduced.fast_curve"} <= modules


@pytest.mark.parametrize("name", COMMANDS)
def test_the_table_names_each_commands_module_and_its_help(name):
    """The listing's one line is the command module's own HELP, and the module is a command."""
    module_name, line = COMMANDS[name]
    module = importlib.import_module(module_name)
    assert module.HELP == line
    assert callable(module.add_arguments) and callable(module.run)


@pytest.mark.skipif("not __import__('validation.scenes.drawing').scenes.drawing.can_fork()",
                    reason="the figures are drawn in a second process only where it can fork")
def test_a_scene_run_leaves_the_plotting_to_the_drawing_process(tmp_path):
    """`cupcheck run` of a scene with figures: matplotlib is imported in the drawing process, which
    draws while the products are computed, never in the main process (~0.3 s off its path)."""
    scene = tmp_path / "s.toml"
    scene.write_text('[stiffness]\nsource = "appendix-a"\n[loads]\nF1_N = [10, 40]\n[[outputs]]\nkind = "lifetimes"\n'
                     '[[outputs]]\nkind = "figure"\nfigure = "lifetime_vs_force"\n')
    modules = _modules_after(["run", str(scene), "--no-cache", "--out", str(tmp_path / "out")], tmp_path)
    assert not _top(modules) & {"matplotlib", "PIL"}, sorted(m for m in modules if m.startswith("matplotlib"))[:5]
    # the test can fail: the figure was drawn
    assert {p.name for p in (tmp_path / "out").iterdir()} >= {"lifetime_vs_force.png", "lifetime_vs_force.svg"}
