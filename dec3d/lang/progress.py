"""A line now and then while a long deck is read and bound (nothing for decks read in under 2 s)."""
from __future__ import annotations

import time as _time

#: seconds before the first line, and between lines
EVERY = 2.0


class BindProgress:
    """``tick(line)`` once per deck line; writes ``reading <file>: line N (t s) …`` through ``write``
    every ``EVERY`` seconds (the clock is looked at every 1024 lines)."""

    __slots__ = ("write", "name", "t0", "next", "count")

    def __init__(self, write, name: str):
        self.write = write
        self.name = name
        self.t0 = _time.perf_counter()
        self.next = self.t0 + EVERY
        self.count = 0

    def tick(self, line: int) -> None:
        self.count += 1
        if self.count & 1023:
            return
        self.tick_at(line)

    def tick_at(self, line: int) -> None:
        """Look at the clock (a caller counting lines itself calls this every 1024 lines)."""
        now = _time.perf_counter()
        if now >= self.next:
            self.next = now + EVERY
            self.write(f"reading {self.name}: line {line} ({now - self.t0:.0f} s) …")
