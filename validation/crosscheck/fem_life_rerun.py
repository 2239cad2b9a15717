"""The one command that reruns section 8 (`validation.crosscheck.fem_life`) into an existing
report, leaving the other sections' files as they are:

    python -m validation.crosscheck.fem_life_rerun --into validation/report

It runs the section alone as `cupcheck validate --only fem_life` does (the validate cache: a rerun
computes only what changed), copies its tables and figure, replaces its README section (or adds it
before the unnumbered tail) and its entry of summary.json. The section's lives are independent per
cup and contact law: `--jobs 2` runs them two at a time into the cache first, and `--cup`/`--law`
run only some of them (the others come from the cache, or their cells say "not run"):

    python -m validation.crosscheck.fem_life_rerun --into validation/report --jobs 2
    python -m validation.crosscheck.fem_life_rerun --into validation/report --cup A --law sticking "coulomb 1"
"""

from __future__ import annotations

from pathlib import Path

from validation.crosscheck.rerun import replace_section, report_problem

__all__ = ["merge_into", "replace_section", "parse_law"]


def merge_into(report_dir, quick: bool = False, cache_dir=None, cached_only: bool = False) -> list[str]:
    """Run section 8 alone (as `cupcheck validate --only fem_life`, through the validate cache) and
    put its files, its README section and its summary entry into an existing report directory,
    leaving the other sections' files as they are; returns the files written. `cached_only`: runs
    not in the cache are not run, their cells say so (a report cut at a time budget)."""
    from validation.crosscheck import rerun
    from validation.crosscheck.fem_life import NAME
    return rerun.merge_into(report_dir, NAME, quick, cache_dir, cached_only)


def parse_law(text: str) -> tuple[str, float | None]:
    """A section law as written on the command line: "frictionless", "sticking" or "coulomb MU"."""
    from validation.crosscheck.fem_life import LAWS

    words = text.split()
    try:
        law = (words[0], float(words[1]) if len(words) == 2 and words[0] == "coulomb" else None)
    except (IndexError, ValueError):
        law = None
    if law not in LAWS:
        raise ValueError(f"--law {text!r}: not one of the section's laws "
                         + ", ".join(f"{n} {m:g}" if m else n for n, m in LAWS))
    return law


def main(argv=None) -> int:
    import argparse
    import sys

    from validation.crosscheck import fem_life

    ap = argparse.ArgumentParser(description="Rerun section 8 into an existing report, e.g. "
                                             "python -m validation.crosscheck.fem_life_rerun --into validation/report")
    ap.add_argument("--into", required=True, help="the report directory (README.md and summary.json there)")
    ap.add_argument("--quick", action="store_true", help="the CI subset")
    ap.add_argument("--cache-dir", default=None, help="the validate cache (default: the user's)")
    ap.add_argument("--cached-only", action="store_true",
                    help="run nothing: runs not in the cache become cells saying so")
    ap.add_argument("--jobs", type=int, default=1, help="processes that run the (cup, law) parts (default 1)")
    ap.add_argument("--cup", nargs="+", choices=sorted(fem_life.FORCES_N), help="run only these cups' lives")
    ap.add_argument("--law", nargs="+", help='run only these laws\' lives: frictionless, sticking, "coulomb MU"')
    a = ap.parse_args(argv)
    into = Path(a.into)
    try:
        laws = None if a.law is None else {parse_law(t) for t in a.law}
        if a.jobs < 1:
            raise ValueError(f"--jobs {a.jobs}: must be at least 1")
        problem = report_problem(into, a.into, a.quick)
        if problem:
            raise ValueError(problem)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    cached_only = a.cached_only
    if not cached_only and (a.jobs > 1 or a.cup or laws):
        from validation.bridge.cache import user_cache_dir

        root = Path(user_cache_dir("validate") if a.cache_dir is None else a.cache_dir)
        cups = None if a.cup is None else set(a.cup)
        tables = () if a.quick or laws is not None or cups else tuple(fem_life.FORCES_N)
        fem_life.fill(fem_life.groups(a.quick, cups, laws), root, a.jobs, tables)
        cached_only = True
    print("wrote " + ", ".join(merge_into(into, a.quick, a.cache_dir, cached_only)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
