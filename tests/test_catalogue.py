"""Every bad input of the catalogue (tests/catalogue/bad_inputs.py) is refused: exit status 2, one
line on stderr that names the field, and no file written."""

from pathlib import Path

import pytest

from tests.catalogue.bad_inputs import CASES
from validation.cli import main


def _files(directory: Path) -> set[str]:
    return {p.relative_to(directory).as_posix() for p in directory.rglob("*")}


@pytest.mark.parametrize("category,argv,files,expected", CASES,
                         ids=[f"{i:03d}-{c[0]}" for i, c in enumerate(CASES)])
def test_bad_input_is_refused(tmp_path, capsys, category, argv, files, expected):
    for name, content in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_bytes(content if isinstance(content, bytes) else content.encode())
    before = _files(tmp_path)
    try:
        code = main([a.format(d=tmp_path) for a in argv])
    except SystemExit as exc:              # argparse's own errors
        code = exc.code
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert code == 2, err
    assert len(lines) == 1, err
    assert expected.format(d=tmp_path) in lines[0]
    assert "Traceback" not in err
    assert _files(tmp_path) == before
