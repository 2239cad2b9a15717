"""`cupcheck suction` and `cupcheck lifetime --route coupled` end to end on a small coarse table:
the table the command writes holds the global balance, the route's lifetime agrees with the
library's, and bad input is one line, exit 2, nothing written."""

import json
import math

import numpy as np
import pytest

from reduced.coupled import CoupledCavity
from reduced.critical_gap import ILLUSTRATIVE_UC_CSV, UcTable
from reduced.cup import CUP_A
from reduced.gas import Gas
from reduced.profile_leak import ContactProfile
from reduced.suction_table import SuctionTable
from validation.cli import main
from validation.coupled.table import fem_beta


def _run(capsys, *argv):
    try:
        code = main(list(argv))
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def table_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("suction") / "cupA.json"
    code = main(["suction", "--cup", "A", "--fidelity", "coarse", "--u-mm", "0.05", "1", "3", "5",
                 "--dp-kPa", "0", "2", "5", "10", "20", "40", "--out", str(path)])
    assert code == 0
    return path


def test_suction_table_balances(table_path):
    t = SuctionTable.from_json(table_path)
    assert t.provenance["geometry"]["name"] and t.provenance["source"] == "fem.suction"
    N = np.array([[p.force_N if p is not None else 0.0 for p in row] for row in t.profiles])
    # the plane's reaction less dp on the zone beyond the seal, plus the pull, is the suction's
    # resultant dp pi r_k^2 (the profile's trapezoid integral: a coarse check of the lumping)
    suction = t.dp_Pa * np.pi * t.seal_r_m**2
    reaction = N - t.dp_Pa * np.pi * (t.cut_r_m**2 - t.seal_r_m**2)
    assert np.allclose(t.F1_N + reaction, suction, atol=0.05 * suction.max())


def test_coupled_route_matches_the_library(capsys, table_path, tmp_path):
    code, out, _ = _run(capsys, "lifetime", "--route", "coupled", "--suction-table", str(table_path),
                        "--cup", "A", "--force", "2", "15", "--json", "--out", str(tmp_path / "run"))
    assert code == 0
    rows = json.loads(out)
    model = CoupledCavity(SuctionTable.from_json(table_path), UcTable.from_csv(ILLUSTRATIVE_UC_CSV),
                          Gas(T_K=293.15), 1e5)
    u_start = CUP_A.h1_m - CUP_A.h_start_m
    for r in rows:
        expected = model.lifetime(r["force_N"], u_start)
        assert r["lifetime_s"] == pytest.approx(expected.lifetime_s, rel=1e-12)
        assert r["reason"] in ("table_edge", "fold") and math.isfinite(r["lifetime_s"])
    assert rows[0]["lifetime_s"] > rows[1]["lifetime_s"] > 0
    assert (tmp_path / "run" / "trajectory_F1_2N.csv").read_text().startswith("cup,t_s,u_mm")


@pytest.mark.parametrize("argv, field", [
    (["lifetime", "--route", "coupled", "--force", "5"], "--suction-table"),
    (["lifetime", "--route", "coupled", "--suction-table", "TABLE", "--relaxation", "default"], "--route"),
    (["lifetime", "--route", "coupled", "--suction-table", "nowhere.json"], "--suction-table"),
    (["lifetime", "--suction-table", "TABLE", "--force", "5"], "--suction-table"),
    (["lifetime", "--route", "coupled", "--suction-table", "TABLE", "--kappa", "-1"], "--kappa"),
    (["example", "--route", "coupled", "--suction-table", "nowhere.json"], "--suction-table"),
])
def test_coupled_route_bad_input(capsys, table_path, tmp_path, argv, field):
    argv = [str(table_path) if a == "TABLE" else a for a in argv]
    if argv[0] == "example":
        argv += ["--out", str(tmp_path / "ex")]
    code, out, err = _run(capsys, *argv)
    assert code == 2 and len(err.strip().splitlines()) == 1 and field in err
    assert not (tmp_path / "ex").exists()


@pytest.mark.parametrize("extra, field", [
    (["--dp-kPa", "10", "20"], "dp_kPa"), (["--dp-kPa", "0", "2000"], "dp_kPa"),
    (["--u-mm", "0", "1"], "u_mm"), (["--u-mm", "3", "1"], "u_mm"), (["--u-mm", "50"], "u_mm"),
    (["--nu", "0.499"], "nu"), (["--E-MPa", "-1"], "E"),
])
def test_suction_bad_input(capsys, tmp_path, extra, field):
    out = tmp_path / "t.json"
    code, _, err = _run(capsys, "suction", "--fidelity", "coarse", *extra, "--out", str(out))
    assert code == 2 and len(err.strip().splitlines()) == 1 and field in err
    assert not out.exists()


def test_suction_refuses_a_csv_output(capsys, tmp_path):
    code, _, err = _run(capsys, "suction", "--out", str(tmp_path / "t.csv"))
    assert code == 2 and "out" in err and not (tmp_path / "t.csv").exists()


def test_fem_beta_reads_back_a_known_strip_load():
    """fem_beta on a table whose contact force grows by b dp 2 pi r_k l over a uniform strip of
    width l (force-quartile width exact for a uniform strip) returns b at every node."""
    r_k, l, b, F0 = 0.015, 2e-3, 0.7, 3.0
    u, dp = np.array([1e-3, 2e-3]), np.array([0.0, 1e4, 5e4])
    N = F0 + b * dp * 2 * np.pi * r_k * l
    F1 = np.tile(dp * np.pi * r_k**2 - N, (2, 1))
    strip = ContactProfile(np.linspace(r_k, r_k + l, 41), np.full(41, 1e5))
    table = SuctionTable(u, dp, F1, np.full((2, 3), 1e-6), np.full((2, 3), r_k),
                         np.full((2, 3), r_k + l), ((strip,) * 3,) * 2, E_Pa=4e6)
    assert np.allclose(fem_beta(table), b, rtol=1e-9)
