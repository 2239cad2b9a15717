"""Section 8 of the validation report (the cup's whole life in the FEM): the runs it plans, a run
that ends without a lifetime kept as a cell with its reason, the README splice, and the quick
section end to end (~25 s on one core)."""

import json
import math

import pytest

from validation.crosscheck import fem_life
from validation.crosscheck.fem_life import LifeRun, live, plan
from validation.crosscheck.fem_life_rerun import replace_section


def test_the_full_section_plans_every_law_and_force_once():
    runs = plan(False)
    assert len(set(runs)) == len(runs)
    laws = {("frictionless", None), ("coulomb", 0.3), ("coulomb", 0.5), ("coulomb", 1.0), ("coulomb", 2.0),
            ("sticking", None)}
    for cup, forces in (("A", {5.0, 10.0, 20.0, 40.0, 60.0, 80.0}), ("B", {5.0, 10.0, 20.0, 40.0})):
        for law in laws:
            mine = [r.force_N for r in runs if r.cup == cup and (r.law, r.friction) == law]
            assert mine[0] is None                      # the largest holdable force first
            assert set(mine[1:]) == forces and len(mine) == len(forces) + 1
    assert {r.cup for r in runs} == {"A", "B"}
    assert all(r.fidelity == "coarse" for r in runs)


def test_the_quick_subset_is_cup_a_frictionless_and_mu_half_at_10_N():
    assert set(plan(True)) == {LifeRun("A", law, mu, F) for law, mu in (("frictionless", None), ("coulomb", 0.5))
                               for F in (None, 10.0)}
    assert fem_life.requests(True) == fem_life.requests(False) == ()


def test_an_invalid_law_is_a_failed_cell_naming_it():
    out = live(LifeRun("A", "coulomb", -1.0, 10.0))
    assert out.failed and math.isnan(out.lifetime_s)
    assert out.cell().startswith("failed: ValueError:") and "friction" in out.cell()


def test_a_force_above_the_largest_holdable_is_an_over_force_cell_not_a_lifetime():
    """Cup A (frictionless, coarse) holds about 52 N once sealed: at 80 N it lets go at once, by the
    route's branch (run) and by the section's rule (F1 above the largest holdable force: not run)."""
    runs = (LifeRun("A", "frictionless", None, None), LifeRun("A", "frictionless", None, 80.0))
    calls = []
    section = fem_life.lives(runs, lambda r: calls.append(r) or live(r))
    assert calls == [runs[0]]
    largest = section[("A", "frictionless", None, None)]
    assert 20.0 < largest.largest_force_N < 80.0
    skipped = section[("A", "frictionless", None, 80.0)]
    out = live(runs[1])
    for o in (out, skipped):
        assert o.reason == "over_force" and o.lifetime_s == 0.0 and o.cell() == "0 (over_force)"
    assert out.largest_force_N == pytest.approx(largest.largest_force_N, rel=1e-9)
    # the sealed state's seal lies inside the contact, inside the cup's rim (19 mm + the wall)
    s = out.sealed
    assert 0 < s["r_c_mm"] <= s["r_k_mm"] <= s["r_out_mm"] < 25.0


README = "# r\n\n## 7. Friction\n\nseven\n\n## Deformed cup\n\npic\n"


def test_the_section_goes_before_the_unnumbered_tail_and_replaces_itself():
    header = f"## {fem_life.TITLE}\n"
    once = replace_section(README, header, "first\n")
    assert once.index("seven") < once.index(header) < once.index("first") < once.index("## Deformed cup")
    twice = replace_section(once, header, "second\n")
    assert "first" not in twice and twice.count(header) == 1
    assert twice.replace("second", "first") == once


def test_quick_section_end_to_end(tmp_path):
    from validation.cli import main

    out = tmp_path / "report"
    assert main(["validate", "--quick", "--only", "fem_life", "--no-scene", "--out", str(out),
                 "--cache-dir", str(tmp_path / "cache")]) == 0
    names = {p.name for p in out.iterdir()}
    assert {"fem_life_lifetimes.csv", "fem_life_largest_force.csv", "fem_life_seal.csv",
            "fem_life_seal.png"} <= names
    s = json.loads((out / "summary.json").read_text())["fem_life"]
    assert s["failed_runs"] == []
    for law in ("frictionless", "mu 0.5"):
        assert s["lifetime_s"][f"A {law} 10N"] > 0
        assert s["largest_force_N"]["A"][f"fem {law}"] > 10.0
    assert "88 N" in (out / "README.md").read_text()


def test_the_plan_splits_into_independent_parts_per_cup_and_law():
    parts = fem_life.groups(False)
    flat = [r for p in parts for r in p]
    assert len(flat) == len(plan(False)) and set(flat) == set(plan(False))
    assert len(parts) == 2 * len(fem_life.LAWS)
    for p in parts:
        assert p[0].force_N is None                     # the largest holdable force first in each part
        assert len({(r.cup, r.law, r.friction) for r in p}) == 1
    some = fem_life.groups(False, cups={"B"}, laws={("sticking", None)})
    assert [(r.cup, r.law) for r in some[0]] == [("B", "sticking")] * 5 and len(some) == 1


@pytest.mark.parametrize("text, law", [("frictionless", ("frictionless", None)), ("coulomb 0.3", ("coulomb", 0.3)),
                                       ("sticking", ("sticking", None)), ("coulomb  2", ("coulomb", 2.0))])
def test_a_law_as_written_on_the_command_line(text, law):
    from validation.crosscheck.fem_life_rerun import parse_law
    assert parse_law(text) == law


@pytest.mark.parametrize("argv, field", [(["--law", "coulomb 7"], "--law 'coulomb 7'"),
                                         (["--law", "coulomb"], "--law 'coulomb'"),
                                         (["--jobs", "0"], "--jobs 0")])
def test_bad_rerun_options_are_one_line_exit_2_nothing_written(tmp_path, capsys, argv, field):
    from validation.crosscheck.fem_life_rerun import main
    (tmp_path / "README.md").write_text(README)
    (tmp_path / "summary.json").write_text("{}\n")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert main(["--into", str(tmp_path), "--cache-dir", str(tmp_path / "c"), *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


@pytest.mark.slow
def test_parts_filled_by_two_workers_are_what_one_process_computes(tmp_path):
    """The quick parts run by two loky workers into a cache, then read back without running: the
    same lifetimes and largest forces as `live` in this process (~60 s on one core)."""
    fem_life.fill(fem_life.groups(True), tmp_path, jobs=2)
    back = fem_life.lives(plan(True), fem_life.cached_runner(tmp_path, cached_only=True))
    assert not any(o.reason == "not run" for o in back.values())
    here = live(LifeRun("A", "coulomb", 0.5, 10.0))
    there = back[("A", "coulomb", 0.5, 10.0)]
    assert there.lifetime_s == here.lifetime_s and there.reason == here.reason


def test_a_life_over_its_cpu_limit_is_an_unfinished_cell_and_the_timer_is_restored():
    """A real life (cup A medium, 10 N: ~7 s of CPU) given 1 s of CPU stops there and says so;
    afterwards the profiling signal is the process's own again and no timer is left running."""
    import signal
    import time

    before = signal.getsignal(signal.SIGPROF)
    t0 = time.process_time()
    out = live(LifeRun("A", "frictionless", None, 10.0, "medium", cpu_limit_s=1.0))
    spent = time.process_time() - t0
    assert out.reason == "unfinished" and out.failed and math.isnan(out.lifetime_s)
    assert out.cell() == "unfinished: not finished within 1 s of CPU"
    assert 1.0 <= spent < 3.0
    assert signal.getsignal(signal.SIGPROF) is before and signal.getitimer(signal.ITIMER_PROF) == (0.0, 0.0)


def test_cpu_limits_nest_the_sooner_one_fires_and_the_outer_one_is_re_armed():
    """An inner limit leaves the outer one running (less the CPU spent inside); an inner limit
    longer than what is left of the outer one does not push the outer deadline back."""
    import signal
    import time

    from validation.crosscheck.fem_life import CpuLimitReached, cpu_limit

    def spin(seconds):
        t = time.process_time()
        while time.process_time() - t < seconds:
            sum(range(1000))

    t0 = time.process_time()
    with pytest.raises(CpuLimitReached):
        with cpu_limit(0.6):
            with cpu_limit(0.2):
                spin(0.05)                       # the inner block ends well inside both limits
            spin(5.0)                            # the outer limit still fires
    assert 0.5 <= time.process_time() - t0 < 1.2
    t0 = time.process_time()
    with pytest.raises(CpuLimitReached):
        with cpu_limit(0.3):
            with cpu_limit(100.0):               # longer than the outer: the outer's deadline holds
                spin(5.0)
    assert 0.25 <= time.process_time() - t0 < 0.9
    assert signal.getitimer(signal.ITIMER_PROF) == (0.0, 0.0)


def test_one_section_rerun_into_a_report_keeps_the_others(tmp_path, capsys):
    """`python -m validation.crosscheck.rerun speed --quick`: section 4's files, README section and
    summary keys go in; the other sections' text and summary keys stay; a bad section name is one
    line, exit 2, nothing written."""
    from validation.crosscheck.rerun import main

    (tmp_path / "README.md").write_text(README)
    (tmp_path / "summary.json").write_text('{"keep": 1}\n')
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert main(["spead", "--into", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'spead'" in err[0]
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    assert main(["speed", "--quick", "--into", str(tmp_path), "--cache-dir", str(tmp_path / "c")]) == 0
    text = (tmp_path / "README.md").read_text()
    assert text.index("seven") < text.index("## 4. Speed") < text.index("## Deformed cup")
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["keep"] == 1 and len(summary) > 1
    assert (tmp_path / "pareto.png").stat().st_size > 10_000


@pytest.mark.parametrize("module", ["rerun", "fem_life_rerun"])
def test_a_quick_rerun_into_a_full_report_is_refused(tmp_path, capsys, module):
    """A --quick section would put the CI subset's numbers into a full report: one line naming
    --into, exit 2, nothing written (and a full section into a quick report likewise)."""
    import importlib

    main = importlib.import_module(f"validation.crosscheck.{module}").main
    args = ["speed"] if module == "rerun" else []
    for kind, flag in (("false", ["--quick"]), ("true", [])):
        (tmp_path / "README.md").write_text(README)
        (tmp_path / "summary.json").write_text(f'{{"quick": {kind}}}\n')
        before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
        assert main([*args, "--into", str(tmp_path), "--cache-dir", str(tmp_path / "c"), *flag]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"--into {tmp_path}" in err[0] and "report" in err[0]
        assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
