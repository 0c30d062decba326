"""Progress on stderr over the whole of a long command: bars for steps that can be counted and an
elapsed-time line for a stage whose length is not known in advance (a search, a compiler run), so
the terminal never sits silent for seconds (issue 17 item 5). Into a log file or a pipe the same progress
is written as plain lines, at most one per :data:`LOG_INTERVAL_S` and the final state, never carriage
returns or cursor moves (a captured console was full of ``\\r`` bars)."""
from __future__ import annotations

import math
import sys
import threading
import time
from contextlib import contextmanager

from tqdm.std import tqdm as _std_tqdm

_NOTEBOOK = "ipykernel" in sys.modules or "IPython.utils._process_emscripten" in sys.modules
if _NOTEBOOK:
    # a notebook's widget bars (tqdm.auto's own test)
    from tqdm.auto import tqdm as _terminal_tqdm
else:
    # a terminal: tqdm.std, the class tqdm.auto picks there, without its asyncio mix-in (importing asyncio, ssl
    # and the rest cost every command ~20 ms of CPU for ``async for``, which the kit never uses)
    _terminal_tqdm = _std_tqdm

#: Seconds between two progress lines written to a log (stderr not a terminal).
LOG_INTERVAL_S = 10.0


class _LogLines(_std_tqdm):
    """A progress bar for a stream that is not a terminal: each shown state on a line of its own, at most one
    per :data:`LOG_INTERVAL_S` (the first state at once), and the final state when the bar ends."""

    def __init__(self, *args, **kwargs):
        self._logged_at = -math.inf
        self._logged: tuple = ()
        self._final = False
        kwargs.setdefault("ascii", True)              # a log stays plain ASCII
        kwargs["leave"] = False                        # every line stays in a log; the final one is written by close
        super().__init__(*args, **kwargs)

    def display(self, msg=None, pos=None):
        if msg == "":                                  # tqdm clearing the line: nothing to clear in a log
            return False
        now = time.monotonic()
        state = (self.n, self.total)
        if msg is None and not self._final and (now - self._logged_at < LOG_INTERVAL_S or
                                                 (state == self._logged and self.total is not None)):
            return False
        self._logged_at, self._logged = now, state
        self.fp.write((str(self) if msg is None else msg).rstrip() + "\n")
        self.fp.flush()
        return True

    def clear(self, nolock=False):
        pass

    def moveto(self, n):
        pass

    def close(self):
        if not self.disable and ((self.n, self.total) != self._logged or self.total is None):
            self._final = True
            self.display()
        super().close()


def _is_terminal(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


def tqdm(*args, **kwargs):
    """``tqdm.tqdm`` on a terminal (or a notebook); :class:`_LogLines` when the stream (``file``, by default
    stderr) is a log file or a pipe."""
    stream = kwargs.get("file") or sys.stderr
    return (_terminal_tqdm if _NOTEBOOK or _is_terminal(stream) else _LogLines)(*args, **kwargs)


def steps(total: int, desc: str, enabled: bool = True, unit: str = "step"):
    """A bar over ``total`` counted steps (``.update()`` after each); a no-op bar when not ``enabled``."""
    return tqdm(total=total, desc=desc, unit=unit, disable=not enabled, leave=False, file=sys.stderr)


@contextmanager
def working(desc: str, enabled: bool = True, interval_s: float = 0.5):
    """While the block runs, a line ``desc: 12s elapsed`` on stderr refreshed every ``interval_s``
    (for stages whose length is unknown); removed when the block ends."""
    if not enabled:
        yield
        return
    bar = tqdm(total=None, desc=desc, bar_format="{desc}: {elapsed} elapsed", leave=False, file=sys.stderr)
    stop = threading.Event()

    def tick():
        while not stop.wait(interval_s):
            bar.refresh()

    thread = threading.Thread(target=tick, name="rwadist-progress", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()
        bar.close()
