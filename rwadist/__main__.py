"""The ``rwadist`` command (the console script, and ``python -m rwadist``): Ctrl-C is one line from its first
instruction.

Python's own SIGINT handler raises ``KeyboardInterrupt`` wherever the program is, and the command's imports
(numpy, scipy, h5py: 0.3-0.7 s) ran before :func:`rwadist.cli.main` could catch it: a Ctrl-C then printed a
traceback.  :func:`main` installs, before any import, a handler that ends the process with one line and exit 130
(143 on SIGTERM); nothing is written yet.  :func:`rwadist.cli.main` then installs the one that knows the command
and its outputs (:func:`rwadist.outputs.exit_on_interrupt`).  A signal ignored at start (a background job's SIGINT)
stays ignored.

Until that handler is in place a Ctrl-C is Python's own traceback, so nothing may be imported before it: loading
this module (and ``import rwadist``) adds no module to what the interpreter's start-up loaded -- ``_signal``, the
C module under ``signal``, is one of them (the interpreter installs its SIGINT handler with it); ``signal`` itself
builds its enums (``enum``, ``functools``, ``collections``: ~5 ms at load 20, half the window).  What remains is
the interpreter's: its start (``site``, the environment's ``.pth`` files) and the console script pip writes (pip < 25
imports ``re`` there, ~8 ms more).  A Ctrl-C in it prints Python's traceback, before anything is written
(``benchmarks/kill_outputs.py --early`` counts them, ``--window`` times it; docs/cli.md says why rwadist ships no
launcher to close it).
"""
import os
import sys

try:
    import _signal as _sig  # the functions and constants of signal, without its enums
except ImportError:             # an interpreter without it (not CPython)
    import signal as _sig


def _interrupted(signum, frame):        # no command has started: nothing written
    os.write(2, b"rwadist: interrupted; nothing written\n" if signum == _sig.SIGINT else
             b"rwadist: terminated; nothing written\n")
    os._exit(130 if signum == _sig.SIGINT else 143)


def main() -> int:
    """Run the command line (:func:`rwadist.cli.main`) with Ctrl-C handled from the start."""
    for sig in (_sig.SIGINT, _sig.SIGTERM):
        if _sig.getsignal(sig) != _sig.SIG_IGN:
            _sig.signal(sig, _interrupted)
    from .cli import main as run

    return run()


if __name__ == "__main__":
    sys.exit(main())
