"""The command line run in-process as a user types it, for tests: ``code, out, err = run(capsys, "fit", data, ...)``
(arguments converted with ``str``; stdout and stderr read from pytest's ``capsys``)."""
from rwadist.cli import main


def run(capsys, *argv) -> tuple:
    """(exit code, stdout, stderr) of ``rwadist ARGV``."""
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err
