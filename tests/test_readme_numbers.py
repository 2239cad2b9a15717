"""scripts/check_readme.py: the README's numbers against fresh runs of the commands that print
them. The README's annotations parse and each value stands in the text beside its comment; on a
small README of its own the script finds a wrong number and a malformed annotation (a real
`cupcheck lifetime` run, ~1 s); the slow test checks every annotated number of the README."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "check_readme.py"


def _module():
    spec = importlib.util.spec_from_file_location("check_readme", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module              # its dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=600)


def test_the_readme_annotations_parse_and_name_numbers_its_text_shows():
    commands, checks = _module().parse((ROOT / "README.md").read_text(encoding="utf-8"))
    assert {"main", "paper-inputs", "design", "ex02", "ex03", "ex04", "ex05"} <= set(commands)
    assert {c.name for c in checks} == set(commands)          # every command is checked for something
    assert {"131.1", "23.24", "1189.25", "120.7", "53.04", "107.7"} <= {c.value for c in checks}


def test_a_wrong_number_fails_and_a_right_one_passes(tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text("Cup A on the paper's inputs lasts 120.7 s at 10 N and 157.9 s at 5 N.\n"
                      "<!-- check-command ref: cupcheck lifetime --reference-mode --force 5 10 -->\n"
                      "<!-- check ref: 120.7 from stdout /^\\s*10\\s+(\\S+)\\s/ -->\n"
                      "<!-- check ref: 157.9 from stdout /^\\s*5\\s+(\\S+)\\s/ -->\n")
    done = _run("--readme", str(readme))
    assert done.returncode == 1, done.stderr
    rows = [line.split() for line in done.stdout.splitlines()[1:-1]]
    assert rows == [["README.md:3", "ref", "120.7", "120.7", "(120.739)", "ok"],
                    ["README.md:4", "ref", "157.9", "157.8", "(157.798)", "MISMATCH"]]
    assert done.stdout.splitlines()[-1] == "1 of 2 numbers match; 1 do not"


@pytest.mark.parametrize("text, message", [
    ("lasts 99 s\n<!-- check ref: 98 from stdout /(x)/ -->\n<!-- check-command ref: true -->\n",
     "README line 2: the value 98 is not in the text above its comment"),
    ("lasts 99 s\n<!-- check ref: 99 from stdout /(x)/ -->\n",
     "README line 2: no check-command 'ref'"),
    ("lasts 99 s\n<!-- check-command ref: true -->\n<!-- check ref: 99 from the log -->\n",
     "README line 3: cannot read 'from the log'"),
])
def test_a_malformed_annotation_exits_2_before_running_anything(tmp_path, text, message):
    readme = tmp_path / "README.md"
    readme.write_text(text)
    done = _run("--readme", str(readme))
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.startswith(f"check_readme: error: {message}")


@pytest.mark.slow
def test_every_number_the_readme_quotes_matches_a_fresh_run():
    done = _run()
    assert done.returncode == 0, done.stdout + done.stderr
