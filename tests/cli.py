"""The command line as the tests call it: `run_cli(capsys, *argv)` -> (exit status, stdout, stderr)."""

from validation.cli import main


def run_cli(capsys, *argv):
    """Run `cupcheck argv` in-process (arguments str()-ed), catching argparse's own exits."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:               # argparse's own errors
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err
