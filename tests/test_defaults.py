"""One set of defaults, stated once: the surface (pmma-1.89 everywhere, the illustrative u_c table
only by name), the contact law (frictionless everywhere), the cache (one per user, never the
working directory), and the scene and sweep keys documented from the parsers' own tables."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from validation.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_lifetime_defaults_to_the_calibrated_surface(capsys):
    """`lifetime` without a surface is the model on pmma-1.89 (built here from the library: the
    calibrated preset's Persson u_c table), not the illustrative power law."""
    from reduced.critical_gap import ILLUSTRATIVE_UC_CSV, UcTable
    from reduced.cup import CUP_A
    from reduced.lifetime import reference_model, solve_lifetime
    from reduced.roughness import uc_table
    from reduced.roughness.surfaces import preset

    code, out, err = _run(capsys, "lifetime", "--cup", "A", "--force", "10", "--json")
    assert code == 0 and err == ""
    got = json.loads(out)[0]["lifetime_s"]
    pmma = reference_model(CUP_A, uc_table(preset("pmma-1.89").spectrum(), 0.5))
    assert got == pytest.approx(solve_lifetime(pmma, 10.0, route="paper").lifetime_s, rel=1e-9)
    code, out, _ = _run(capsys, "lifetime", "--cup", "A", "--force", "10", "--surface", "pmma-1.89", "--json")
    assert json.loads(out)[0]["lifetime_s"] == got
    code, out, err = _run(capsys, "lifetime", "--cup", "A", "--force", "10", "--surface", "illustrative")
    illustrative = solve_lifetime(reference_model(CUP_A, UcTable.from_csv(ILLUSTRATIVE_UC_CSV)), 10.0,
                                  route="paper").lifetime_s
    assert code == 0 and "ILLUSTRATIVE" in err
    assert f"{illustrative:.6g}" in out and abs(illustrative - got) > 1.0


def test_one_default_surface_and_contact_law():
    """The scene, the sweep and the commands default to the same surface and contact law."""
    from validation.cli import build_parser
    from validation.bridge.pipeline import DEFAULT_SURFACE
    from validation.scenes.schema import scene_from_mapping
    from validation.sweeps.spec import sweep_from_mapping

    scene = scene_from_mapping({"outputs": [{"kind": "lifetimes"}]})
    sweep = sweep_from_mapping({})
    assert scene["surface"]["preset"] == sweep.base["surface"] == DEFAULT_SURFACE
    assert scene["contact"]["law"] == sweep.base["contact"] == "frictionless"
    args = build_parser().parse_args(["stiffness", "--out", "x.csv"])
    assert args.contact is None          # resolved to frictionless without a design file's [contact]


def test_committed_key_docs_match_the_parsers():
    """docs/scenes.md and docs/sweeps.md are what scripts/keys_docs.py generates from the parsers."""
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "keys_docs.py"), "--check"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_every_documented_key_is_parsed():
    """The MEANING tables name exactly the keys the parsers accept (no stale, no missing entry)."""
    from validation.scenes import schema
    from validation.sweeps import spec

    for module in (schema, spec):
        documented = {row[0] for row in module.key_rows()}
        assert documented == set(module.MEANING)
    scene_keys = {f"{t}.{k}" for t, keys in schema._TABLES.items() for k in keys}
    assert scene_keys <= set(schema.MEANING)
    sweep_keys = {f"base.{k}" for k in (*spec._BASE_DEFAULTS, *spec._OPTIONAL)}
    assert sweep_keys <= set(spec.MEANING)


def test_user_cache_dir(monkeypatch, tmp_path):
    from validation.bridge.cache import user_cache_dir

    monkeypatch.setenv("CUPCHECK_CACHE_DIR", str(tmp_path / "mine"))
    assert user_cache_dir("scenes") == tmp_path / "mine" / "scenes"
    monkeypatch.delenv("CUPCHECK_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    if sys.platform.startswith("linux"):
        assert user_cache_dir() == tmp_path / "xdg" / "cupcheck"
    assert Path.cwd() not in user_cache_dir().parents


def test_a_scene_runs_in_a_read_only_working_directory(tmp_path):
    """A real process in a read-only (mode 555) working directory: the scene runs, its products go
    to the user's cache, nothing is written in the working directory (as root, who could write
    there, this is what shows it), and a second run reads them."""
    work = tmp_path / "work"
    work.mkdir()
    (work / "s.toml").write_text('[stiffness]\nsource = "appendix-a"\n[loads]\nF1_N = [10]\n'
                                 '[[outputs]]\nkind = "lifetimes"\n')
    work.chmod(0o555)
    env = {**os.environ, "CUPCHECK_CACHE_DIR": str(tmp_path / "cache"), "PYTHONPATH": str(ROOT),
           "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg"}
    try:
        for _ in range(2):
            done = subprocess.run([sys.executable, "-m", "validation.cli", "run", "s.toml", "--out",
                                   str(tmp_path / "out")], cwd=work, env=env, capture_output=True, text=True,
                                  timeout=300)
            assert done.returncode == 0, done.stderr
            assert done.stderr == ""
        assert sorted(p.name for p in work.iterdir()) == ["s.toml"]
        assert any((tmp_path / "cache" / "scenes").rglob("output.pkl"))
    finally:
        work.chmod(0o755)
