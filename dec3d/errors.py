"""Exceptions of dec3d.

Every error a user can cause is a `Dec3dError`. Errors tied to deck text carry a
`SourceLocation` (file, line, column, the source line, the include stack) and print
like a compiler: location, the line, a caret under the offending token, a hint.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

# C0 controls (tab kept), DEL, C1 controls, and the bidirectional overrides/isolates that
# reorder what a terminal shows: deck text echoed in a message must not drive the terminal
_CONTROL = re.compile("[\x00-\x08\x0a-\x1f\x7f-\x9f\u200e\u200f\u202a-\u202e\u2066-\u2069\ufeff]")


#: the same characters, as refused inside deck strings and expressions
CONTROL_CHARS = _CONTROL


def _escape(m) -> str:
    c = m.group()
    return f"\\x{ord(c):02x}" if ord(c) < 0x100 else f"\\u{ord(c):04x}"


def printable(text: str, newlines: bool = False) -> str:
    """`text` with control characters written as visible escapes (`\\x1b`, `\\u202e`).

    newlines=True keeps line breaks (console output of several lines)."""
    if not _CONTROL.search(text):
        return text
    if newlines:
        return "\n".join(_CONTROL.sub(_escape, part) for part in text.split("\n"))
    return _CONTROL.sub(_escape, text)


@dataclass(frozen=True)
class SourceLocation:
    """Where a token sits in a deck. `line` and `column` count from 1."""

    file: str
    line: int
    column: int
    text: str = ""          # the physical source line
    length: int = 1         # width of the caret
    stack: tuple["SourceLocation", ...] = field(default=())  # callers, outermost first

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


def frozen_instance(cls, fields: dict):
    """An instance of the frozen dataclass ``cls`` with ``fields`` (every field, by name): the same
    object its constructor makes, without a ``object.__setattr__`` call per field (binding makes a
    location and a command per deck line: the constructors were a third of binding a line)."""
    obj = object.__new__(cls)
    object.__setattr__(obj, "__dict__", fields)
    return obj


def _resolved(location):
    """Binding keeps token positions unresolved (see `LazyLocation`); errors resolve them."""
    return location.resolve() if hasattr(location, "resolve") else location


class LazyLocation:
    """A token position turned into a SourceLocation only if an error needs it (binding is hot)."""

    __slots__ = ("deck", "token", "stack")

    def __init__(self, deck, token, stack=()):
        self.deck, self.token, self.stack = deck, token, stack

    def resolve(self) -> SourceLocation:
        return self.deck.location(self.token, self.stack)


class Dec3dError(Exception):
    """Base of every error dec3d reports to a user."""

    def __init__(self, message: str, location: SourceLocation | None = None, hint: str | None = None):
        super().__init__(message)
        self.message = message
        self.location = _resolved(location)
        self.hint = hint

    def with_location(self, location: SourceLocation) -> "Dec3dError":
        if self.location is None:
            self.location = _resolved(location)
        return self

    def format(self) -> str:
        """Compiler-style report: location, message, source line, caret, hint, include stack."""
        out = []
        loc = self.location
        message = printable(self.message)
        if loc is None:
            out.append(f"error: {message}")
        else:
            out.append(f"{printable(str(loc))}: error: {message}")
            if loc.text:
                raw = loc.text.rstrip("\n")
                line = printable(raw.expandtabs(1))
                # the caret sits under the token as shown (escapes widen what precedes it)
                col = len(printable(raw[:max(0, loc.column - 1)].expandtabs(1)))
                out.append(f"    {line}")
                out.append("    " + " " * col + "^" * max(1, loc.length))
            for caller in reversed(loc.stack):
                out.append(f"  called from {printable(str(caller))}")
        if self.hint:
            out.append(f"  hint: {printable(self.hint)}")
        return "\n".join(out)

    def __str__(self) -> str:
        # the message alone: a caller that wraps this error in another one (`CommandError(str(exc))`)
        # must not repeat "error:" and the location; `format()` is the full report
        return self.message


class DeckSyntaxError(Dec3dError):
    """The text is not a well-formed command line."""


class BindError(Dec3dError):
    """A command or keyword is unknown, ambiguous, or its values are wrong."""


class NotSupportedError(Dec3dError):
    """A 3DEC command or feature dec3d knows by name but does not implement yet."""


class UnimplementedError(NotSupportedError):
    """A 3DEC command, keyword, range element or FISH intrinsic dec3d knows by name and does not
    implement: a deck still binds the lines after it and runs up to it (``dec3d.lang.unsupported``)."""


class ExpressionError(Dec3dError):
    """An inline [expression] failed to evaluate (unknown name, division by zero, ...)."""


class ResourceError(Dec3dError):
    """A command would need more blocks, memory or digits than the budget allows (`model budget`)."""


class CommandError(Dec3dError):
    """A command was bound correctly but could not be carried out."""


class StopDeck(Exception):
    """`program exit`: stop running, keep the model. (Control flow, not an error; it lives here so the
    command handlers can raise it without importing the session above them.)"""


class LegacySyntaxError(BindError):
    """A 3DEC 4/5 command in a 3DEC 7+ deck."""
