"""The ``rwadist`` command (the console script, and ``python -m rwadist``): Ctrl-C is one line from its first
instruction.

Python's own SIGINT handler raises ``KeyboardInterrupt`` wherever the program is, and the command's imports
(numpy, scipy, h5py: 0.3-0.7 s) ran before :func:`rwadist.cli.main` could catch it: a Ctrl-C then printed a
traceback.  ``import rwadist`` loads nothing heavy (its API is imported on first use), so :func:`main` installs,
before any import, a handler that ends the process with one line and exit 130 (143 on SIGTERM); nothing is written
yet.  :func:`rwadist.cli.main` then installs the one that knows the command and its outputs
(:func:`rwadist.outputs.exit_on_interrupt`).  A signal ignored at start (a background job's SIGINT) stays ignored.
Loading this module imports ``rwadist`` (nothing heavy) and ``signal`` only.  Before it runs, the interpreter
starts and the console script pip writes imports ``re`` (a few ms): a Ctrl-C there is still Python's own
traceback, which no program can take over; nothing has been written then.
"""
import os
import signal
import sys


def _interrupted(signum, frame):        # no command has started: nothing written
    os.write(2, b"rwadist: interrupted; nothing written\n" if signum == signal.SIGINT else
             b"rwadist: terminated; nothing written\n")
    os._exit(130 if signum == signal.SIGINT else 143)


def main() -> int:
    """Run the command line (:func:`rwadist.cli.main`) with Ctrl-C handled from the start."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(sig) != signal.SIG_IGN:
            signal.signal(sig, _interrupted)
    from .cli import main as run

    return run()


if __name__ == "__main__":
    sys.exit(main())
