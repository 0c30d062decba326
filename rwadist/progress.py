"""Progress on stderr over the whole of a long command: bars for steps that can be counted and an
elapsed-time line for a stage whose length is not known in advance (a search, a compiler run), so
the terminal never sits silent for seconds (issue 17 item 5)."""
from __future__ import annotations

import sys
import threading
from contextlib import contextmanager

if "ipykernel" in sys.modules or "IPython.utils._process_emscripten" in sys.modules:
    # a notebook's widget bars (tqdm.auto's own test)
    from tqdm.auto import tqdm
else:
    # a terminal: tqdm.std, the class tqdm.auto picks there, without its asyncio mix-in (importing asyncio, ssl
    # and the rest cost every command ~20 ms of CPU for ``async for``, which the kit never uses)
    from tqdm.std import tqdm


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
