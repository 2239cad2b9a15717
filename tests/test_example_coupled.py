"""`cupcheck example --route coupled` on a small coarse suction table, and the table's build cache:
the example's lifetimes are the library's, a table of another design is refused, a cached table
is not recomputed."""

import math

import numpy as np
import pytest

from tests.cli import run_cli as _run
from validation.cli import main
from validation.bridge.coupled.build import SuctionGridSpec, suction_table_for

#: a small grid that still spans cup A's start (u_start = 4.8 mm on the coarse mesh) and 100 kPa
SMALL = SuctionGridSpec((0.005, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8),
                        (0.0, 2.0, 5.0, 10.0, 20.0, 40.0, 70.0, 100.0))



@pytest.fixture(scope="module")
def table_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("suction") / "cupA.json"
    suction_table_for("A", fidelity="coarse", grid=SMALL).to_json(path)
    return path


@pytest.fixture(scope="module")
def coupled_example(tmp_path_factory, table_file):
    out = tmp_path_factory.mktemp("ex") / "coupled"
    assert main(["example", "--route", "coupled", "--fidelity", "coarse", "--suction-table",
                 str(table_file), "--out", str(out)]) == 0
    return out


def test_coupled_example_lifetimes_are_the_librarys(coupled_example, table_file):
    import pandas as pd

    import reduced
    from reduced.cup import CUP_A
    from reduced.roughness import uc_table
    from reduced.roughness.surfaces import preset
    from reduced.suction_table import SuctionTable

    rows = pd.read_csv(coupled_example / "lifetime_vs_force.csv", keep_default_na=False)
    assert list(rows.columns) == ["cup", "route", "contact", "mesh", "surface", "force_N", "lifetime_s", "reason",
                                  "u_final_mm", "p_b_final_Pa"]
    assert {tuple(r) for r in rows[["route", "contact", "mesh", "surface"]].to_numpy()} == \
        {("coupled", "frictionless", "coarse", "pmma-1.89")}
    table = SuctionTable.from_json(table_file)
    model = reduced.LeakageModel(cup=CUP_A, suction=table, u_c=uc_table(preset("pmma-1.89").spectrum(), 0.5))
    u_start = table.h1_m - CUP_A.h_start_m
    for F, life, reason in zip(rows.force_N, rows.lifetime_s, rows.reason):
        expected = reduced.solve_lifetime(model, F, route="coupled", u_start_m=u_start)
        assert reason == expected.reason
        assert float(life) == pytest.approx(expected.lifetime_s, rel=1e-9)
    held = rows[rows.reason != "over_force"]
    assert len(held) >= 3 and np.all(np.diff(held.lifetime_s.astype(float)) < 0)
    # the forces the cup cannot hold have no final state: empty fields, not a number
    over = rows[rows.reason == "over_force"]
    assert len(over) and (over.u_final_mm == "").all()
    assert SuctionTable.from_json(coupled_example / "suction_table.json").F1_N.tolist() == table.F1_N.tolist()


@pytest.mark.parametrize("extra, message", [
    (["--route", "paper"], "--suction-table: applies to --route coupled only"),
    (["--route", "coupled", "--cup", "B"], "was built for another design"),
    (["--route", "coupled", "--cup-laws", "cone"], "--cup-laws: the coupled route"),
    (["--route", "coupled", "--contact", "sticking"], "was built with frictionless contact"),
])
def test_coupled_example_bad_input(capsys, tmp_path, table_file, extra, message):
    out = tmp_path / "never"
    code, _, err = _run(capsys, "example", "--fidelity", "coarse", "--suction-table", str(table_file),
                        "--out", str(out), *extra)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_cached_table_is_read_not_rebuilt(tmp_path):
    grid = SuctionGridSpec((0.1, 0.3), (0.0, 10.0))
    calls = []
    first = suction_table_for("A", fidelity="coarse", grid=grid, cache_dir=tmp_path,
                              progress=lambda f, m: calls.append(f))
    assert calls                              # the FEM ran and reported
    calls.clear()
    again = suction_table_for("A", fidelity="coarse", grid=grid, cache_dir=tmp_path,
                              progress=lambda f, m: calls.append(f))
    assert not calls                          # read from the cache: no FEM step
    assert again.F1_N.tolist() == first.F1_N.tolist() and math.isclose(again.E_Pa, first.E_Pa)
    other = suction_table_for("A", fidelity="coarse", grid=SuctionGridSpec((0.1, 0.3), (0.0, 20.0)),
                              cache_dir=tmp_path)
    assert other.dp_Pa[-1] == 2e4            # another grid is another entry


def test_suction_table_for_takes_the_contact_law_object():
    """The contact law travels as one `fem.interface.ContactLaw`; its name alone is refused before any FEM."""
    with pytest.raises(ValueError, match="contact: expected a fem.interface.ContactLaw"):
        suction_table_for("A", fidelity="coarse", grid=SMALL, contact="sticking")
