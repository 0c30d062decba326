"""The ``rwadist`` command (the console script ``rwadist-py`` that the launcher ``scripts/rwadist`` starts, and
``python -m rwadist``): Ctrl-C is one line from its first instruction.

Python's own SIGINT handler raises ``KeyboardInterrupt`` wherever the program is, and the command's imports
(numpy, scipy, h5py: 0.3-0.7 s) ran before :func:`rwadist.cli.main` could catch it: a Ctrl-C then printed a
traceback.  :func:`main` installs, before any import, a handler that ends the process with one line and exit 130
(143 on SIGTERM); nothing is written yet.  :func:`rwadist.cli.main` then installs the one that knows the command
and its outputs (:func:`rwadist.outputs.exit_on_interrupt`).  A signal ignored at start (a background job's SIGINT)
stays ignored.

Until that handler is in place a Ctrl-C is Python's traceback, so nothing may be imported before it: loading
this module (and ``import rwadist``) adds no module to what the interpreter's start-up loaded -- ``_signal``, the
C module under ``signal``, is one of them (the interpreter installs its SIGINT handler with it); ``signal`` itself
builds its enums (``enum``, ``functools``, ``collections``: ~5 ms at load 20, half the window).  Before this
module runs, the interpreter starts (``site``, the environment's ``.pth`` files, pip's console script): the
``rwadist`` launcher starts it with SIGINT blocked, so a Ctrl-C there waits, pending, and :func:`take_signals`
delivers it to the handler as it unblocks the signal.  ``python -m rwadist`` and ``rwadist-py`` run without the
launcher: a Ctrl-C in the interpreter's start is Python's traceback there, before anything is written
(``benchmarks/kill_outputs.py --early`` counts them, ``--aim`` aims at that instant, ``--window`` times it;
docs/cli.md, "Ctrl-C while Python starts").
"""
import os
import sys

try:
    import _signal as _sig  # the functions and constants of signal, without its enums
except ImportError:             # an interpreter without it (not CPython)
    import signal as _sig


def _interrupted(signum, frame):
    """Before the command's own handler (nothing written yet) and after it, while Python exits: then the command's
    outputs are complete, and :func:`rwadist.outputs.interrupt_message` names them."""
    outputs = sys.modules.get("rwadist.outputs")
    try:
        line = outputs.interrupt_message("", signum).encode(errors="replace") if outputs else b""
    except Exception:       # noqa: BLE001 - a handler that must end the process whatever happens
        line = b""
    os.write(2, (line or (b"rwadist: interrupted" if signum == _sig.SIGINT else b"rwadist: terminated") +
                 b"; nothing written") + b"\n")
    os._exit(130 if signum == _sig.SIGINT else 143)


def take_signals() -> None:
    """Ctrl-C and SIGTERM end the process with one line from now on (a signal ignored at start stays ignored), and
    SIGINT is unblocked: the ``rwadist`` launcher starts the interpreter with it blocked, so a Ctrl-C since then is
    pending and is delivered here, to :func:`_interrupted`.  Unblocked before anything else runs, so no thread,
    worker or subprocess inherits a blocked SIGINT."""
    for sig in (_sig.SIGINT, _sig.SIGTERM):
        if _sig.getsignal(sig) != _sig.SIG_IGN:
            _sig.signal(sig, _interrupted)
    if hasattr(_sig, "pthread_sigmask"):        # POSIX (Windows has no signal mask, and no launcher)
        _sig.pthread_sigmask(_sig.SIG_UNBLOCK, (_sig.SIGINT,))


def main() -> int:
    """Run the command line (:func:`rwadist.cli.main`) with Ctrl-C handled from the start."""
    take_signals()
    from .cli import main as run

    return run()


if __name__ == "__main__":
    sys.exit(main())
