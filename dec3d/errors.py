"""Exceptions of dec3d.

Every error a user can cause is a `Dec3dError`. Errors tied to deck text carry a
`SourceLocation` (file, line, column, the source line, the include stack) and print
like a compiler: location, the line, a caret under the offending token, a hint.
"""
from __future__ import annotations

from dataclasses import dataclass, field


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
        if loc is None:
            out.append(f"error: {self.message}")
        else:
            out.append(f"{loc}: error: {self.message}")
            if loc.text:
                line = loc.text.rstrip("\n").expandtabs(1)
                out.append(f"    {line}")
                out.append("    " + " " * (loc.column - 1) + "^" * max(1, loc.length))
            for caller in reversed(loc.stack):
                out.append(f"  called from {caller}")
        if self.hint:
            out.append(f"  hint: {self.hint}")
        return "\n".join(out)

    def __str__(self) -> str:
        return self.format()


class DeckSyntaxError(Dec3dError):
    """The text is not a well-formed command line."""


class BindError(Dec3dError):
    """A command or keyword is unknown, ambiguous, or its values are wrong."""


class NotSupportedError(Dec3dError):
    """A 3DEC command or feature dec3d knows by name but does not implement yet."""


class ExpressionError(Dec3dError):
    """An inline [expression] failed to evaluate (unknown name, division by zero, ...)."""


class CommandError(Dec3dError):
    """A command was bound correctly but could not be carried out."""


class StopDeck(Exception):
    """`program exit`: stop running, keep the model. (Control flow, not an error; it lives here so the
    command handlers can raise it without importing the session above them.)"""


class LegacySyntaxError(BindError):
    """A 3DEC 4/5 command in a 3DEC 7+ deck."""
