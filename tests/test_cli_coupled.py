"""`cupcheck suction` and `cupcheck lifetime --route coupled` end to end on a small coarse table:
the table the command writes holds the global balance, the route's lifetime agrees with the
library's, and bad input is one line, exit 2, nothing written."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from fem.solver import SolverOptions
from reduced.coupled import CoupledCavity
from reduced.critical_gap import ILLUSTRATIVE_UC_CSV, UcTable
from reduced.cup import CUP_A
from reduced.gas import Gas
from reduced.lifetime import LeakageModel, solve_lifetime
from reduced.profile_leak import ContactProfile
from reduced.suction_table import SuctionTable
from reduced.viscoelastic import default_relaxation, measurement_contact_time
from tests.cli import run_cli as _run
from validation.cli import main
from validation.bridge.coupled.table import fem_beta



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
                        "--cup", "A", "--force", "2", "15", "--surface", "illustrative", "--json",
                        "--out", str(tmp_path / "run"))
    assert code == 0
    rows = json.loads(out)
    model = LeakageModel(cup=CUP_A, suction=SuctionTable.from_json(table_path),
                         u_c=UcTable.from_csv(ILLUSTRATIVE_UC_CSV), gas=Gas(T_K=293.15), p_a_Pa=1e5)
    u_start = CUP_A.h1_m - CUP_A.h_start_m
    for r in rows:
        expected = solve_lifetime(model, r["force_N"], route="coupled", u_start_m=u_start)
        assert r["lifetime_s"] == pytest.approx(expected.lifetime_s, rel=1e-12)
        assert r["reason"] in ("table_edge", "fold") and math.isfinite(r["lifetime_s"])
    assert rows[0]["lifetime_s"] > rows[1]["lifetime_s"] > 0
    assert (tmp_path / "run" / "trajectory_F1_2N.csv").read_text().startswith("cup,t_s,u_mm")


@pytest.mark.parametrize("argv, field", [
    (["lifetime", "--route", "coupled", "--force", "5"], "--suction-table"),
    (["lifetime", "--route", "coupled", "--suction-table", "TABLE", "--fluid", "water"], "--route"),
    (["lifetime", "--route", "coupled", "--suction-table", "TABLE", "--relaxation", "default",
      "--phi0-s", "0"], "--phi0-s"),
    (["lifetime", "--route", "coupled", "--suction-table", "TABLE", "--relaxation", "default",
      "--phi0-s", "nan"], "--phi0-s"),
    (["lifetime", "--route", "coupled", "--suction-table", "TABLE", "--phi0-s", "13"], "--phi0-s"),
    (["lifetime", "--route", "coupled", "--suction-table", "TABLE", "--relaxation", "none.csv"], "relaxation"),
    (["lifetime", "--route", "coupled", "--suction-table", "TABLE", "--relaxation", "default",
      "--rtol", "0.5"], "--rtol"),
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
    (["--u-mm", "-50", "1"], "u_mm"), (["--u-mm", "3", "1"], "u_mm"), (["--u-mm", "50"], "u_mm"),
    (["--nu", "0.499"], "nu"), (["--E-MPa", "-1"], "E"),
    (["--force", "5"], "--force: applies to --grid adaptive only"),
    (["--surface", "pmma-1.89"], "--surface: applies to --grid adaptive only"),
    (["--grid", "adaptive", "--force", "5", "-1"], "--force"),
    (["--grid", "adaptive", "--surface", "no-such-surface"], "surface"),
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


def test_relaxed_coupled_route_matches_the_library(capsys, table_path, tmp_path):
    """--relaxation default on the coupled route: phi0 defaults to cup A's measurement contact
    time (13 s), the lifetimes are the library's, the trajectory carries phi and kappa."""
    code, out, _ = _run(capsys, "lifetime", "--route", "coupled", "--suction-table", str(table_path),
                        "--cup", "A", "--force", "2", "--relaxation", "default", "--surface", "illustrative", "--json",
                        "--out", str(tmp_path / "run"))
    assert code == 0
    row = json.loads(out)[0]
    assert row["cup"]["phi0_s"] == pytest.approx(measurement_contact_time(CUP_A), rel=1e-12)
    model = LeakageModel(cup=CUP_A, suction=SuctionTable.from_json(table_path),
                         u_c=UcTable.from_csv(ILLUSTRATIVE_UC_CSV), gas=Gas(T_K=293.15), p_a_Pa=1e5,
                         relaxation=default_relaxation(), phi0_s=measurement_contact_time(CUP_A))
    expected = solve_lifetime(model, 2.0, route="coupled", u_start_m=CUP_A.h1_m - CUP_A.h_start_m)
    assert row["lifetime_s"] == pytest.approx(expected.lifetime_s, rel=1e-12)
    assert row["kappa_final"] == pytest.approx(expected.trajectory["kappa"][-1], rel=1e-12)
    header = (tmp_path / "run" / "trajectory_F1_2N.csv").read_text().splitlines()[0]
    assert header.endswith("phi_s,kappa")


def test_relaxed_node_conductance_is_the_unrelaxed_one_at_each_kappa(table_path):
    """The relaxed model's node conductances (Chebyshev in p_b, `reduced.coupled_relax`) at a
    frozen kappa against the unrelaxed model's, computed directly for the cup that is kappa times
    stiffer and meets the interface with E = kappa E_eff(phi0) (the FEM profiles: many rings;
    measured 5e-9 in ln on this table)."""
    table = SuctionTable.from_json(table_path)
    uc = UcTable.from_csv(ILLUSTRATIVE_UC_CSV)
    law = default_relaxation()
    relaxed = CoupledCavity(table, uc, Gas(T_K=293.15), 1e5, relaxation=law, phi0_s=13.0)
    rates = relaxed._relaxed.rates
    E_ref = float(law(13.0))
    for kappa in (0.6, 1.0, 1.2):
        direct = CoupledCavity(replace(table, E_Pa=kappa * E_ref), uc, Gas(T_K=293.15), 1e5, kappa=kappa)
        g = direct._node_conductance
        fitted = np.stack([rates.column(kappa, j) for j in range(table.dp_Pa.size)], axis=1)
        ok = np.isfinite(g) & (g > 0)
        assert ok.sum() > 0.5 * g.size
        assert np.max(np.abs(fitted[ok] - np.log(g[ok]))) < 1e-7


def test_adaptive_suction_table_holds_the_full_tables_states_around_the_paths(capsys, table_path, tmp_path):
    """--grid adaptive on the same lattice builds the table with holes around the lifetimes' paths
    (as `lifetime --route coupled` does): its states are the full table's to the solver's
    tolerance, and it says how many it solved."""
    out = tmp_path / "adaptive.json"
    code, stdout, _ = _run(capsys, "suction", "--cup", "A", "--fidelity", "coarse", "--u-mm", "0.05", "1", "3", "5",
                           "--dp-kPa", "0", "2", "5", "10", "20", "40", "--grid", "adaptive", "--force", "2",
                           "--surface", "illustrative", "--out", str(out))
    assert code == 0 and "states around the paths" in stdout and "states solved" in stdout
    full, around = SuctionTable.from_json(table_path), SuctionTable.from_json(out)
    assert np.array_equal(full.u_m, around.u_m) and np.array_equal(full.dp_Pa, around.dp_Pa)
    held = np.isfinite(around.F1_N)
    assert held.any()
    np.testing.assert_allclose(around.F1_N[held], full.F1_N[held], rtol=0,
                               atol=SolverOptions().rtol * np.abs(full.F1_N).max())
    assert around.provenance["states_solved"] <= full.u_m.size * full.dp_Pa.size
    assert around.provenance["forces_N"] == [2.0]
