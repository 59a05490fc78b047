"""A wall-clock limit on a run: `dec3d run --max-seconds S`, `dec3d batch --timeout S`.

When the time is up a timer thread does what Ctrl-C does (``_thread.interrupt_main``: the Python
handler of SIGINT runs in the main thread): while the engine cycles it stops at the end of its batch
of steps, the model consistent (``runcontrol``); a FISH loop stops at its next look at the stop flag
(``fish.runtime``, every 1024 iterations); anything else in Python stops at once. A kernel call is
not cut short: the stop comes when it returns (a batch of steps lasts well under a second). If the run
has not stopped ``GRACE`` seconds later, a second interrupt stops it at once (the engine then rolls
back to the state before the command, as after a second Ctrl-C).

Only the main thread can be interrupted this way; in another thread (a Dask worker's task) the limit
sets the engine's and FISH's stop flags instead, which stop cycling and FISH loops but not other
Python work.
"""
from __future__ import annotations

import _thread
import threading
from contextlib import contextmanager

#: seconds between the first interrupt and the second
GRACE = 10.0


class TimeLimit:
    """``expired`` says whether the limit stopped the run (what the caller reports)."""

    def __init__(self, seconds: float | None):
        self.seconds = seconds
        self.expired = False


@contextmanager
def time_limit(seconds: float | None):
    """Stop what runs inside after ``seconds`` of wall time (None: no limit); yields a ``TimeLimit``."""
    lim = TimeLimit(seconds)
    if seconds is None:
        yield lim
        return
    main = threading.current_thread() is threading.main_thread()
    done = threading.Event()
    lock = threading.Lock()              # no interrupt once the block has ended

    def fire():
        if done.wait(seconds):
            return
        with lock:
            if done.is_set():
                return
            lim.expired = True
            if main:
                _thread.interrupt_main()
        if not main:
            from .fish.runtime import request_stop as stop_fish
            from .physics.runcontrol import request_stop as stop_cycling

            stop_cycling()
            stop_fish()
            return
        if not done.wait(GRACE):
            with lock:
                if not done.is_set():
                    _thread.interrupt_main()

    timer = threading.Thread(target=fire, name="dec3d-time-limit", daemon=True)
    timer.start()
    try:
        yield lim
    finally:
        with lock:
            done.set()
