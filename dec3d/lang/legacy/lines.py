"""Legacy (3DEC 4/5) deck text: physical lines split into tokens that remember their columns, and
the translated text with its map back to the original file (line and column of every token).

A translated line is built from `Out` pieces; each piece knows the original line and column it came
from, so an error found in the translation points at the original text (`LineMap.remap`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field, replace

NOTE = "; dec3d translate: could not translate: "

_TOKEN = re.compile(r"""'[^']*'|"[^"]*"|\[[^\]]*\]|[^\s,()=&\[\]'"]+""")


@dataclass
class Tok:
    text: str
    line: int           # 1-based original line
    col: int            # 1-based original column

    @property
    def low(self) -> str:
        return self.text.lower()


def split_comment(text: str) -> tuple[str, str]:
    """(code, comment) of one physical line: the comment starts at the first `;` outside quotes."""
    quote = None
    for i, ch in enumerate(text):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == ";":
            return text[:i], text[i:]
    return text, ""


def continues(code: str) -> bool:
    """A legacy line goes on on the next one when it ends with `&` (or `...`)."""
    s = code.rstrip()
    return s.endswith("&") or s.endswith("...")


def tokens(code: str, line: int) -> list[Tok]:
    """The words, numbers, strings, `@names` and `[...]` of one line (`,` `(` `)` `=` `&` separate)."""
    s = code.rstrip()
    if s.endswith("..."):
        s = s[:-3]
    return [Tok(m.group(0), line, m.start() + 1) for m in _TOKEN.finditer(s)]


@dataclass
class Out:
    """A piece of translated text and where it came from."""
    text: str
    line: int
    col: int


@dataclass
class OutLine:
    pieces: list[Out]
    line: int                 # original line
    comment: str = ""         # original comment, kept at the end

    def render(self) -> tuple[str, list[tuple[int, int, int]]]:
        text, segs = "", []
        for p in self.pieces:
            if text and not text.endswith(" ") and not p.text.startswith(" "):
                text += " "
            segs.append((len(text) + 1, p.line, p.col))
            text += p.text
        if self.comment:
            segs.append((len(text) + 2 if text else 1, self.line, -1))
            text = f"{text} {self.comment}" if text else self.comment
        return text, segs


@dataclass
class LineMap:
    """Translated line number -> (original line, [(translated column, original line, original column)],
    original text)."""
    filename: str
    original: list[str]
    rows: list[tuple[int, list[tuple[int, int, int]]]] = field(default_factory=list)

    def where(self, line: int, column: int) -> tuple[int, int]:
        if not 1 <= line <= len(self.rows):
            return line, column
        orig, segs = self.rows[line - 1]
        best = (orig, 1)
        for out_col, oline, ocol in segs:
            if out_col <= column:
                # within a piece the columns run on from the piece's original column (exact for text the
                # translation kept, such as most of a FISH line), never past the original line's end
                width = len(self.original[oline - 1]) if 1 <= oline <= len(self.original) else column
                col = ocol + (column - out_col) if ocol > 0 else column
                best = (oline, max(1, min(col, width)))
            else:
                break
        return best

    def remap_location(self, loc):
        if loc is None:
            return loc
        stack = tuple(self.remap_location(s) for s in getattr(loc, "stack", ()))
        if getattr(loc, "file", None) != self.filename:
            return replace(loc, stack=stack) if stack != loc.stack else loc
        line, col = self.where(loc.line, loc.column)
        text = self.original[line - 1] if 1 <= line <= len(self.original) else loc.text
        return replace(loc, line=line, column=col, text=text, length=1, stack=stack)


def remap_error(exc, maps: list[LineMap]):
    """The error with its location (and the include stack) moved to the original legacy text."""
    loc = getattr(exc, "location", None)
    for m in maps:
        loc = m.remap_location(loc)
    if loc is not None:
        exc.location = loc
    return exc
