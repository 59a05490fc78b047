"""How a run is watched and stopped: Ctrl-C (the first one stops cycling at the end of the current
kernel call, the model consistent; a second one at once, the engine then rolls back) and progress
(a rich bar on a terminal, a line every ``PROGRESS_SECONDS`` otherwise)."""
from __future__ import annotations

import signal
import sys
import threading
import time as _time
from contextlib import contextmanager

#: a line of progress every this many seconds when the output is not a terminal
PROGRESS_SECONDS = 10.0

#: a step count at least this large means "no step limit" (a solve limited by time or ratio only)
_OPEN_END = 2**60


class CycleInterrupted(KeyboardInterrupt):
    """Cycling stopped at the end of a batch because the user pressed Ctrl-C (or
    ``request_stop()`` was called). The model is consistent at ``step`` and can cycle again."""

    def __init__(self, step: int):
        super().__init__(f"interrupted at step {step}")
        self.step = step


class _StopFlag:
    """Set by SIGINT while the engine cycles (or by ``request_stop``); read between batches."""
    requested = False


def request_stop() -> None:
    """Ask the running ``cycle`` to stop at the end of its current batch of steps
    (what Ctrl-C does; usable from a step hook, a FISH callback or another thread)."""
    _StopFlag.requested = True


@contextmanager
def _sigint_stops_cycling():
    """While cycling, the first Ctrl-C only sets the stop flag (the engine stops at the end of
    the batch, the model consistent); a second one raises KeyboardInterrupt at once (the
    engine then rolls back to the state before the command). Only in the main thread and
    when Python's default handler is in place (an embedding program keeps its own)."""
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        yield
        return

    def handler(signum, frame):
        if _StopFlag.requested:
            raise KeyboardInterrupt
        _StopFlag.requested = True

    old = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


class _Progress:
    """On a terminal, a rich progress bar for runs longer than about a second; otherwise
    (output to a file or a pipe) a line every ``PROGRESS_SECONDS`` of wall time."""

    def __init__(self, total: int, eng=None):
        self.total = total
        self.eng = eng
        self.step0 = eng.model.step if eng is not None else 0      # the model's step when the command began
        self.t0 = _time.perf_counter()
        self.last = self.t0
        self.bar = None
        self.task = None
        self.enabled = sys.stdout.isatty()

    def update(self, done: int) -> None:
        now = _time.perf_counter()
        if not self.enabled:
            if now - self.last >= PROGRESS_SECONDS:
                self.last = now
                e = self.eng
                if e is not None:
                    # one step count: the model's step, and the step this command ends at
                    end = f" of {self.step0 + self.total}" if self.total < _OPEN_END else ""
                    text = f"cycling: step {self.step0 + done}{end}, ratio {e.ratio:.3g}"
                else:
                    of = f" of {self.total}" if self.total < _OPEN_END else ""
                    text = f"cycling: {done}{of} steps"
                print(f"{text} ({now - self.t0:.0f} s)", flush=True)
            return
        if self.bar is None:
            if now - self.t0 < 1.0:
                return
            from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

            self.bar = Progress(TextColumn("cycling"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                                TimeRemainingColumn(), transient=True)
            self.bar.start()
            self.task = self.bar.add_task("cycle", total=self.total if self.total < _OPEN_END else None)
        self.bar.update(self.task, completed=done)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()
