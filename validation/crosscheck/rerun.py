"""Rerun one section of the validation report into an existing report, leaving the other sections'
files as they are:

    python -m validation.crosscheck.rerun friction --into validation/report

The section runs alone, as `cupcheck validate --only SECTION` runs it, through the validate cache (a
rerun computes only what changed); its tables and figures are copied in, its README section is
replaced (or added before the unnumbered tail) and the summary keys it writes are updated. Section 8
has its own command with parallel parts and a per-life CPU limit
(`python -m validation.crosscheck.fem_life_rerun`), which merges through `merge_into` below.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["merge_into", "replace_section", "report_problem"]


def merge_into(report_dir, section: str, quick: bool = False, cache_dir=None,
               cached_only: bool = False) -> list[str]:
    """Run `section` (a report section's NAME) alone and put its files, its README section and its
    summary keys into the report directory `report_dir`; returns the files written. `cached_only`
    (section 8 only): runs not in the cache are not run, their cells say so."""
    import json
    import shutil
    import tempfile

    from validation.bridge.cache import user_cache_dir
    from validation.crosscheck import SECTIONS
    from validation.crosscheck.context import Context
    from validation.crosscheck.report import Report, _finite, _plain
    from validation.crosscheck.runs import RunMemo
    from validation.output import terminal_progress

    module = {s.NAME: s for s in SECTIONS}[section]
    root = Path(report_dir)
    memo = RunMemo(cache_dir=user_cache_dir("validate") if cache_dir is None else cache_dir)
    with tempfile.TemporaryDirectory() as tmp:
        rep = Report(Path(tmp))
        ctx = Context(memo=memo, report=rep, quick=quick, progress=terminal_progress(section))
        module.run(ctx, **({"cached_only": True} if cached_only else {}))
        for name in rep.files:
            shutil.copyfile(Path(tmp) / name, root / name)
    readme = root / "README.md"
    readme.write_text(replace_section(readme.read_text(), f"## {module.TITLE}\n", "\n".join(rep.pages[section])))
    summary_path = root / "summary.json"
    summary = json.loads(summary_path.read_text())
    summary.update(_finite(json.loads(json.dumps(rep.summary, default=_plain))))
    summary_path.write_text(json.dumps(summary, indent=1, sort_keys=True) + "\n")
    return [*rep.files, readme.name, summary_path.name]


def replace_section(text: str, header: str, body: str) -> str:
    """`text` (a report's README) with the section under `header` replaced by `body`, or the section
    added before the next numbered-or-not section that follows the numbered ones ("## Deformed cup")."""
    lines = text.splitlines(keepends=True)
    new = [header, "\n", body, "\n"]
    if header in lines:
        i = lines.index(header)
        j = next((k for k in range(i + 1, len(lines)) if lines[k].startswith("## ")), len(lines))
        return "".join(lines[:i] + new + lines[j:])
    j = next((k for k, line in enumerate(lines) if line.startswith("## ") and not line[3:4].isdigit()),
             len(lines))
    return "".join(lines[:j] + new + lines[j:])


def report_problem(into: Path, written: str, quick: bool) -> str | None:
    """Why `into` cannot take a rerun section (None if it can): not a report directory, or a report
    of the other kind (a --quick section into a full report, or a full one into a quick report)."""
    import json

    if not (into / "README.md").is_file() or not (into / "summary.json").is_file():
        return f"--into {written}: not a report directory (README.md and summary.json)"
    try:
        kind = json.loads((into / "summary.json").read_text()).get("quick")
    except (ValueError, AttributeError):
        return f"--into {written}: its summary.json is not a report's summary"
    if kind is not None and bool(kind) != quick:
        return (f"--into {written}: a {'quick' if kind else 'full'} report; rerun its sections "
                + ("with" if kind else "without") + " --quick")
    return None


def main(argv=None) -> int:
    import argparse
    import sys

    from validation.crosscheck import section_names

    ap = argparse.ArgumentParser(description="Rerun one section into an existing report, e.g. "
                                             "python -m validation.crosscheck.rerun friction --into validation/report")
    ap.add_argument("section", help="the section's name: " + ", ".join(section_names()))
    ap.add_argument("--into", required=True, help="the report directory (README.md and summary.json there)")
    ap.add_argument("--quick", action="store_true", help="the CI subset")
    ap.add_argument("--cache-dir", default=None, help="the validate cache (default: the user's)")
    a = ap.parse_args(argv)
    into = Path(a.into)
    if a.section not in section_names():
        print(f"error: section {a.section!r}: not one of {', '.join(section_names())}", file=sys.stderr)
        return 2
    problem = report_problem(into, a.into, a.quick)
    if problem:
        print(f"error: {problem}", file=sys.stderr)
        return 2
    print("wrote " + ", ".join(merge_into(into, a.section, a.quick, a.cache_dir)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
