"""Run the catalogue of bad inputs and write docs/reliability.md: inputs tried per category and
their outcomes (refused with exit 2 in one line naming the field, nothing written).

    python -m tests.catalogue.report [--out docs/reliability.md]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import tempfile
from collections import Counter
from pathlib import Path

from tests.catalogue.bad_inputs import CASES
from validation.cli import main as cupcheck


FAULTS = """
## Faults (tests/test_faults.py)

- A `stiffness` run killed (SIGKILL and SIGTERM, a real subprocess, at 0.5, 1.2, 2 and 3.5 s) leaves
  the curve and its sidecar complete or absent, never half-written (each file is written to a
  hidden temporary and renamed; a kill inside a write can leave only that hidden temporary).
- A file-size limit while writing (RLIMIT_FSIZE, as a full disk) is one line, `failed: cannot write
  the output: File too large`, exit status 1, and the output directory is not there.
- Two runs into the same output: the second is refused at once (an OS file lock on the output,
  `filelock`), so their files never interleave; the lock file is removed on release.
- A `lifetime` run SIGKILLed while it writes (a real process, killed as soon as its temporary
  directory appears and 0.05, 0.3, 1 s later): the output is the previous complete one or absent;
  the next run removes the killed run's temporaries and leaves only what its manifest lists.
- Two real runs, the second naming the output through a symlink while the first writes it: the
  second is refused at once (the lock is on the resolved path), the first completes.
- Every table cupcheck writes passes one guard (`validation.output.check_finite`): NaN is refused
  with the column and the stage that produced it; inf is written only where it means something
  (an infinite lifetime, an unbounded line-contact pressure).

## A partial FEM curve: exit status 3 (tests/test_partial_curve.py)

A `stiffness` path that fails after some converged steps (cup A, sticking, coarse, pressed to h1:
the wall folds into the plate at u = 8.921 mm) writes its converged part (the curve, the sidecar,
`--fields-out`), flagged `"partial": true` in the sidecar's provenance with `"failed_at_u_mm"`,
`"failure_reason"` and `"u_max_mm_that_runs"`; one line says where and why it stopped and which
`--u-max-mm` runs, the record goes to `<out>.failure.json`, and the exit status is 3 (1: nothing
converged, no curve; 2: refused input). `lifetime` uses such a curve within its range and refuses
(exit 2, one line) one that stops short of the state it needs.

## Outputs never destroy, and own their folder (tests/test_output_paths.py)

One function, `validation.output.check_outputs`, runs in every command before any work (and again
in the atomic writers): exit 2 and one line naming both paths for an empty path (`--out ""`), a
special file (`/dev/null`, a FIFO, a socket, also through a symlink; /dev/null is checked untouched),
an output that is an input of the run (by name, symlink or hard link: `uc --psd p.csv --out
p.csv`, `stiffness --geometry mycup.json --out mycup.csv` whose sidecar is the design), an input
or the cache inside an output directory, an existing directory cupcheck did not write, and a
file the user did not name (a curve's sidecar, a footprint's scale) over a file of another kind
(`stiffness --out mycup.csv` beside a design `mycup.json`).
`check_file_names` refuses two outputs of one run writing one file (a scene curve named
`manifest`, a curve and a footprint both writing `x.json`, forces 10 and 10.0000001 N sharing a
trajectory file). A run into an existing output directory replaces it as a whole: afterwards it
holds exactly the files its `manifest.json` lists; a later success removes a stale
`<out>.failure.json`; a refused or failed run leaves no directories it created.

## Readers that never crash (tests/test_readers.py)

Each wrong JSON type (text, null, bool, number, object, ragged and non-numeric lists) at every key
path of a suction table and of a stiffness sidecar: a one-line ValueError naming the file and the
key as the file spells it, or a valid read; meshes with an element naming a node out of range or
one node twice, or a repeated element: one line naming the file and the element.

## No silent clipping (tests/test_rough_clipping.py)

The 1D -> isotropic inversion of a line scan's spectrum clips where no isotropic C(q) exists (below
a hump in C_1D); `spectrum.isotropic_misfit` measures it by the forward transform of the result
(share of <h^2> not reproduced; decades of q where C_1D is missed by > 2x): a power law < 1e-4 and
0, a 5 % Gaussian hump 6 % and 0.6 decades. A line scan carries it (`PowerSpectrum.misfit`, its
provenance), says it in one line where C_1D is missed anywhere, and is refused above 25 %.

## One guard for every entry, and interrupts (tests/test_guards.py, tests/test_defaults.py)

- The command line, scene files, sweep files and design files pass the same plausibility guards
  (`validation/guards.py`), named by the key path the user wrote, before any FEM work: the
  catalogue's scene, sweep and design-file rows above; real cups (Table 1, a design in mm, a curve
  used at its own modulus) pass.
- Two sweeps on one store: the second is refused at once (exit 2, one line; an OS file lock in the
  store, `validation.sweeps.spec.lock_store`) and computes nothing.
- Ctrl-C on a real `cupcheck run` at 0 .. 1.5 s from cupcheck's first line, and on a real sweep's
  process group (dask workers included): one line, exit status 130, no output left.
- Library warnings (numpy, scipy, joblib, dask) never reach the terminal; a scene runs from a
  read-only working directory (its cache is the user's).

## Properties (tests/test_properties.py, hypothesis, derandomized)

- Random bytes and valid-ish CSVs into the stiffness, u_c, relaxation, PSD and line-scan readers,
  and random sweep tables: each parses or raises a one-line ValueError, never another exception.
- Random cups, u_c tables and forces (beta >= 0.05): a finite positive lifetime (reached_r1, fold),
  0 (over_force) or inf (sealed, horizon) with a message, never NaN, the force balance to 1e-9 at
  every output. Found: with beta -> 0 the strip pressure vanishes at detachment and the u_c
  extrapolation overflows (left open).
"""


def outcome(argv, files, expected) -> str:
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        for name, content in files.items():
            (d / name).parent.mkdir(parents=True, exist_ok=True)
            (d / name).write_bytes(content if isinstance(content, bytes) else content.encode())
        before = set(d.rglob("*"))
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            try:
                code = cupcheck([a.format(d=d) for a in argv])
            except SystemExit as exc:
                code = exc.code
        lines = err.getvalue().splitlines()
        if code != 2:
            return f"exit {code}"
        if len(lines) != 1:
            return f"{len(lines)} lines"
        if expected.format(d=d) not in lines[0]:
            return "field not named"
        return "refused" if set(d.rglob("*")) == before else "wrote a file"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("docs/reliability.md"))
    args = ap.parse_args()
    rows: dict[str, Counter] = {}
    for category, argv, files, expected in CASES:
        rows.setdefault(category.split(":")[0], Counter())[outcome(argv, files, expected)] += 1
    outcomes = sorted({k for c in rows.values() for k in c})
    lines = ["# Reliability: the catalogue of bad inputs", "",
             "Generated by `python -m tests.catalogue.report` from `tests/catalogue/bad_inputs.py` (the same",
             "cases `tests/test_catalogue.py` runs). *refused*: exit status 2, one line on stderr naming the",
             "field and its allowed range or form, no file written.", "",
             "| category | inputs | " + " | ".join(outcomes) + " |", "|---|---|" + "---|" * len(outcomes)]
    for category, counts in rows.items():
        lines.append(f"| {category} | {sum(counts.values())} | " + " | ".join(str(counts[o]) for o in outcomes) + " |")
    total = Counter()
    for counts in rows.values():
        total.update(counts)
    lines.append(f"| **all** | {sum(total.values())} | " + " | ".join(str(total[o]) for o in outcomes) + " |")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("\n".join(lines) + "\n" + FAULTS)
    print(f"wrote {args.out}: {sum(total.values())} inputs, " + ", ".join(f"{total[o]} {o}" for o in outcomes))


if __name__ == "__main__":
    main()
