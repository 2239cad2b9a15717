"""Rough contact wired into the lifetime: one surface, two routes, the same numbers."""

import json
import subprocess
import sys

import numpy as np
import pytest

from reduced.roughness import critical_gap_table, preset, uc_table
from reduced.roughness.persson import UC_TABLE_P_OVER_E


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "validation.cli", *args], capture_output=True, text=True)


def test_uc_table_interpolates_persson_theory_between_its_rows():
    spectrum = preset("pmma-1.89").spectrum()
    table = uc_table(spectrum, 0.5)
    # midpoints (in log p) of the rows in the range the cup visits, 1e-4 < p/E < 0.05
    rows = UC_TABLE_P_OVER_E[(UC_TABLE_P_OVER_E > 1e-4) & (UC_TABLE_P_OVER_E < 0.05)]
    mid = np.sqrt(rows[:-1] * rows[1:])[::7]
    direct = critical_gap_table(spectrum, 4e6, 0.5, mid).u_c_m
    # 40 rows per decade on a smooth log-log curve: the interpolation error is O(dlnp^2) ~ 0.1 %
    np.testing.assert_allclose(table(mid), direct, rtol=5e-3)


def test_surface_option_equals_the_table_written_by_cupcheck_uc(tmp_path):
    csv = tmp_path / "uc.csv"
    grid = UC_TABLE_P_OVER_E
    p_kPa = [f"{v:.17g}" for v in grid * 4e6 / 1e3]
    made = _cli("uc", "--surface", "pmma-1.89", "--E-MPa", "4", "--p-kPa", *p_kPa, "--out", str(csv))
    assert made.returncode == 0, made.stderr
    common = ["--force", "5", "40", "--rtol", "1e-11", "--json"]
    by_surface = _cli("lifetime", "--surface", "pmma-1.89", *common)
    by_table = _cli("lifetime", "--uc-table", str(csv), *common)
    assert by_surface.returncode == 0 and by_table.returncode == 0, by_surface.stderr + by_table.stderr
    a, b = json.loads(by_surface.stdout), json.loads(by_table.stdout)
    for x, y in zip(a, b):
        # the CSV keeps 10 significant digits (u_c to ~5e-10, lifetime ~ u_c^-3 to ~2e-9) and the
        # integrator runs at rtol 1e-11 (its error on the kinked log-log table is ~100x rtol), so
        # the two routes must agree to 1e-7
        assert x["lifetime_s"] == pytest.approx(y["lifetime_s"], rel=1e-7)
        assert x["reason"] == y["reason"]


@pytest.mark.parametrize("args,field", [
    (["--surface", "pmma-1.89", "--uc-table", "x.csv"], "--uc-table"),
    (["--surface", "no-such-surface"], "surface"),
    (["--surface", "pmma-1.89", "--a-c", "1.5"], "a_c"),
    (["--surface", "pmma-1.89", "--nu", "0.7"], "nu"),
])
def test_bad_surface_options_exit_2_naming_the_field(args, field, tmp_path):
    out = tmp_path / "out"
    run = _cli("lifetime", *args, "--out", str(out))
    assert run.returncode == 2
    assert field in run.stderr and len(run.stderr.strip().splitlines()) <= 2 + 20  # argparse adds usage
    assert not out.exists()
