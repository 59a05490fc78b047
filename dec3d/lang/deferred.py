"""A command value known only when its command runs (`[expr]` or `@name`), shared by the
binder and FISH's `command … endcommand` sections."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True, slots=True)
class Deferred:
    """A value known only when the command runs: `[expr]` (node) or `@name`."""

    kind: str            # "expr" or "at"
    node: Any            # parsed expression tree (for "at": ("name", name, col))
    token: Any           # the lark token, for error locations
    where: Any = None    # its LazyLocation (errors of the evaluated value point at the value itself)

    def __repr__(self) -> str:
        return str(self.token)
