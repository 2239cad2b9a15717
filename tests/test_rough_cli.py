"""`cupcheck uc`: JSON and CSV outputs, presets listing, bad input (exit 2, no file left)."""

import json

import numpy as np
import pytest

from validation.cli import main


def test_json_output(capsys):
    assert main(["uc", "--surface", "pmma-1.89", "--E-MPa", "4", "--p-kPa", "10", "101.325",
                 "1000", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["p_Pa"] for r in rows] == [1e4, 101325.0, 1e6]
    for r in rows:
        assert set(r) >= {"p_Pa", "u_c_m", "u_mean_m", "contact_area_ratio", "sealed"}
    assert rows[1]["u_c_m"] == pytest.approx(0.68e-6, rel=0.05)
    assert rows[2]["sealed"] is True and rows[2]["u_c_m"] == 0.0


def test_out_table_is_sorted_and_readable(tmp_path, capsys):
    out = tmp_path / "uc.csv"
    assert main(["uc", "--surface", "table", "--E-MPa", "4", "--p-range-kPa", "1", "300", "20",
                 "--method", "critical-junction", "--out", str(out)]) == 0
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert out.read_text().splitlines()[0] == "p_over_E,u_c_m"
    assert np.all(np.diff(data[:, 0]) > 0) and np.all(data[:, 1] >= 0)


def test_psd_file_input(tmp_path, capsys):
    from reduced.roughness.surfaces import preset
    path = tmp_path / "c.csv"
    preset("pmma-1.08").spectrum().to_csv(path)
    assert main(["uc", "--psd", str(path), "--E-MPa", "4", "--p-kPa", "101.325", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)[0]["u_c_m"] == pytest.approx(0.40e-6, rel=1e-4)


def test_list_surfaces(capsys):
    assert main(["uc", "--list-surfaces"]) == 0
    assert "pmma-2.51" in capsys.readouterr().out


@pytest.mark.parametrize("argv,field", [
    (["--surface", "nope", "--E-MPa", "4", "--p-kPa", "100", "200"], "surface"),
    (["--surface", "table", "--E-MPa", "-4", "--p-kPa", "100", "200"], "E_Pa"),
    (["--surface", "table", "--E-MPa", "4", "--p-kPa", "0", "200"], "--p-kPa"),
    (["--surface", "table", "--E-MPa", "4", "--nu", "0.6", "--p-kPa", "100", "200"], "nu"),
    (["--surface", "table", "--E-MPa", "4", "--a-c", "1", "--p-kPa", "100", "200"], "a_c"),
    (["--surface", "table", "--E-MPa", "4", "--p-kPa", "100"], "--out"),
    (["--psd", "/nonexistent.csv", "--E-MPa", "4", "--p-kPa", "100", "200"], "--psd"),
    (["--E-MPa", "4", "--p-kPa", "100", "200"], "surface"),
])
def test_bad_input_exits_2_without_output(tmp_path, capsys, argv, field):
    out = tmp_path / "uc.csv"
    assert main(["uc", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_line_scan_input(tmp_path, capsys):
    from test_rough_line_scan import synthetic_scan
    x, z, *_ = synthetic_scan(h_rms=1.5e-6)
    path = tmp_path / "scan.csv"
    np.savetxt(path, np.c_[x * 1e6, z * 1e6], delimiter=",", header="x_um,z_um", comments="")
    assert main(["uc", "--line-scan", str(path), "--E-MPa", "4", "--p-kPa", "0.3", "3",
                 "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert rows[0]["u_c_m"] > rows[1]["u_c_m"] > 0
