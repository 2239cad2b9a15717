"""Every --help says what the parser does: the default each option's help states is the default
the parser uses (or, for an option resolved after parsing, the value the code resolves it to);
a description that marks a choice "(default)" names the option's default; bare `cupcheck` lists
the commands; --version prints the installed version; no help cites an issue number."""

from __future__ import annotations

import argparse
import re
from importlib.metadata import version

import pytest

from validation.cli import COMMANDS, build_parser, main

#: options whose parser default is None and which the command resolves after parsing (so that it
#: can tell a given value from none): the value the stated default must name
RESOLVED = {
    ("example", "--fidelity"): "medium",       # fem.mesh.DEFAULT_FIDELITY
    ("stiffness", "--fidelity"): "medium", ("lifetime", "--fidelity"): "medium",      # validation.commands._fem_route.DEFAULT_FIDELITY
    ("lifetime", "--cup"): "A", ("example", "--cup"): "A", ("stiffness", "--cup"): "A", ("suction", "--cup"): "A",
    ("lifetime", "--uc-table"): None, ("example", "--surface"): "pmma-1.89",
    ("lifetime", "--cup-laws"): "cone", ("example", "--cup-laws"): "cone",     # "cone for the paper route, ..."
    ("stiffness", "--thickness-convention"): "normal",
}
_STATED = re.compile(r"\(default:? ([^,;:)\s]+)")


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def _help_of(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    text = parser._get_formatter()._expand_help(action)
    return " ".join(text.split())


def _same(stated: str, default, text: str = "") -> bool:
    if isinstance(default, (list, tuple)):
        if len(default) == 1:
            return _same(stated, default[0])
        # a long list is stated by its ends: "(default 0, 1, ..., 100)"
        listed = re.search(r"\(default:? ([^)]*)\)", text).group(1)
        return _same(stated, default[0]) and listed.split(", ")[-1] == f"{default[-1]:g}"
    if isinstance(default, bool):
        return stated.lower() == str(default).lower()
    if isinstance(default, (int, float)):
        try:
            return float(stated) == pytest.approx(float(default), rel=1e-12)
        except ValueError:
            return False
    return stated == str(default)


def _cases():
    from validation.bridge.pipeline import DEFAULT_SURFACE
    from fem.mesh import DEFAULT_FIDELITY

    assert RESOLVED[("example", "--fidelity")] == DEFAULT_FIDELITY
    assert RESOLVED[("example", "--surface")] == DEFAULT_SURFACE
    for name, parser in _subparsers().items():
        for action in parser._actions:
            if action.help in (None, argparse.SUPPRESS) or not action.option_strings:
                continue
            yield name, parser, action


@pytest.mark.parametrize("name,parser,action", list(_cases()),
                         ids=[f"{n}-{a.option_strings[-1]}" for n, _, a in _cases()])
def test_stated_default_is_the_parsers(name, parser, action):
    text = _help_of(parser, action)
    stated = _STATED.findall(text)
    option = action.option_strings[-1]
    if action.default is None or action.default is False:
        if (name, option) in RESOLVED:
            expected = RESOLVED[(name, option)]
            assert expected is None or (stated and stated[0] == expected), (option, text)
        elif action.default is None and stated:
            # a stated default of an option that defaults to None must be declared resolved
            assert stated[0] in ("none", "all", "the", "by", "l/rdot", "A") or not action.choices, (option, text)
        return
    if isinstance(action, argparse._StoreTrueAction) or isinstance(action, argparse._HelpAction):
        return
    assert stated, f"cupcheck {name} {option}: the help states no default; the parser's is {action.default!r}"
    assert _same(stated[0].rstrip("."), action.default, text), \
        f"cupcheck {name} {option}: the help says default {stated[0]!r}, the parser uses {action.default!r}"


@pytest.mark.parametrize("name", COMMANDS)
def test_description_marks_the_default_choice(name):
    parser = _subparsers()[name]
    description = parser.description or ""
    for choice in re.findall(r"- (\w+) \((?:the )?default", description):
        owners = [a for a in parser._actions if a.choices and choice in a.choices]
        assert owners and any(a.default == choice for a in owners), \
            f"cupcheck {name}: the description marks {choice!r} as the default; the parser's default differs"


@pytest.mark.parametrize("name", COMMANDS)
def test_no_issue_numbers_in_help(name):
    parser = _subparsers()[name]
    assert not re.search(r"issue \d+", parser.format_help(), re.I)


def test_bare_cupcheck_lists_the_commands(capsys):
    assert main([]) == 0
    out = capsys.readouterr().out
    for name in COMMANDS:
        assert re.search(rf"^\s+{name}\b", out, re.M), name


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"cupcheck {version('cupcheck')}"


def test_the_cache_options_default_to_the_users_cache(monkeypatch, tmp_path):
    """One cache per user: $CUPCHECK_CACHE_DIR (else the platform's cache directory), never the
    working directory; each command's --help states the directory its parser uses."""
    monkeypatch.setenv("CUPCHECK_CACHE_DIR", str(tmp_path / "c"))
    subs = _subparsers()
    for name, kind in (("run", "scenes"), ("example", "suction"), ("validate", "validate")):
        action = next(a for a in subs[name]._actions if "--cache-dir" in a.option_strings)
        assert action.default == tmp_path / "c" / kind
        assert str(tmp_path / "c" / kind) in _help_of(subs[name], action)
