"""FISH, the scripting language of 3DEC decks: parser (`syntax`), compiler to closures
(`compiler`), values and operators (`values`), run time (`runtime`), intrinsics.

The session owns one `FishRuntime`; `fish define` blocks are parsed when the deck is
read (syntax errors stop it before anything runs) and compiled when the define runs.
"""
from __future__ import annotations

from ..errors import SourceLocation
from .compiler import compile_function, compile_inline
from .runtime import FishError, FishFunction, FishRuntime, SystemErrorRaised, request_stop
from .syntax import FishDef, FishSource, parse_fish, parse_inline


def parse_block(block, filename: str, source_lines: list[str], stack=()) -> FishDef:
    """Parse a lifted `fish define` block (dec3d.lang.prepass.FishBlock) with its true line numbers."""
    first = block.line + 1
    lines = source_lines[block.line:block.end_line - 1]
    src = FishSource(filename, first, lines, stack)
    header = source_lines[block.line - 1]
    col = header.lower().find(block.name.lower()) + 1
    return parse_fish(block.name, block.params, src, (block.line, max(col, 1)))


def inline_source(filename: str, line: int, column: int, inner: str, display: str, stack=()) -> FishSource:
    """A `[ ... ]` fragment whose first character sits at `column` (1-based) of `line`."""
    src = FishSource(filename, line, [" " * (column - 1) + inner], stack)
    src.display = {line: display}
    return src


__all__ = ["FishRuntime", "FishFunction", "FishError", "SystemErrorRaised", "FishDef", "FishSource", "parse_block",
           "parse_fish", "parse_inline", "compile_function", "compile_inline", "request_stop", "inline_source",
           "SourceLocation"]
