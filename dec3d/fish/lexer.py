"""FISH source text -> tokens and logical lines (`...` continuations joined, `;` comments dropped,
`command … endcommand` lines kept raw), with the deck positions every error points at.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import DeckSyntaxError, SourceLocation

_TOKEN = re.compile(r"""
 (?P<ws>[ \t\f\r]+)
|(?P<comment>;.*)
|(?P<cont>\.\.\.)
|(?P<num>(?:\d+\.\d*|\.\d+|\d+)(?:[eE][+-]?\d+)?)
|(?P<str>'[^']*'|"[^"]*")
|(?P<name>[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)
|(?P<op>->|::|==|!=|<=|>=|<>|\+=|-=|\*=|/=|\^=|[-+*/^=#<>()&|!,])
""", re.VERBOSE)


@dataclass(frozen=True)
class Tok:
    kind: str          # num, str, name, op
    value: object      # number, string (quotes removed), lower-case name, operator text
    line: int
    col: int
    text: str          # as written

    def is_op(self, *ops) -> bool:
        return self.kind == "op" and self.value in ops

    def is_word(self, *words) -> bool:
        return self.kind == "name" and self.value in words


class FishSource:
    """The body of one `fish define` with the deck's line numbers (for carets and locations)."""

    def __init__(self, filename: str, first_line: int, lines: list[str], stack=()):
        self.filename = filename
        self.first_line = first_line      # deck line number of lines[0]
        self.lines = lines
        self.stack = tuple(stack)
        self.display: dict[int, str] = {}   # line -> text shown under an error (inline fragments)

    def text(self, line: int) -> str:
        k = line - self.first_line
        return self.lines[k] if 0 <= k < len(self.lines) else ""

    def location(self, pos, length: int = 1, stack=None) -> SourceLocation:
        line, col = pos
        return SourceLocation(self.filename, line, col, self.display.get(line) or self.text(line), max(1, length),
                              self.stack if stack is None else tuple(stack))

    def error(self, msg: str, pos, length: int = 1, hint: str | None = None) -> DeckSyntaxError:
        return FishSyntaxError(msg, self.location(pos, length), hint)


class FishSyntaxError(DeckSyntaxError):
    """A FISH line that does not parse."""


def tokenize_line(src: FishSource, line: int, text: str) -> tuple[list[Tok], bool]:
    """Tokens of one physical line, and whether it ends with the `...` continuation."""
    toks: list[Tok] = []
    pos = 0
    cont = False
    n = len(text)
    while pos < n:
        m = _TOKEN.match(text, pos)
        if m is None:
            ch = text[pos]
            if ch in "'\"":
                raise src.error("unterminated string", (line, pos + 1), hint=f"close the string with {ch} on this line")
            raise src.error(f"unexpected character {ch!r} in FISH", (line, pos + 1))
        kind = m.lastgroup
        s = m.group()
        if kind == "comment":
            break
        if kind == "cont":
            rest = text[m.end():].strip()
            if rest and not rest.startswith(";"):
                raise src.error("`...` continues a line only at its end", (line, pos + 1), 3)
            cont = True
            break
        if kind == "num":
            value = float(s) if any(c in s for c in ".eE") else int(s)
            toks.append(Tok("num", value, line, pos + 1, s))
        elif kind == "str":
            toks.append(Tok("str", s[1:-1], line, pos + 1, s))
        elif kind == "name":
            toks.append(Tok("name", s.lower(), line, pos + 1, s))
        elif kind == "op":
            toks.append(Tok("op", s, line, pos + 1, s))
        pos = m.end()
    return toks, cont


_CMD_COMMENT = re.compile(r""";(?=(?:[^'"]|'[^']*'|"[^"]*")*$).*""")
_CMD_CONT = re.compile(r"(?:&|\.\.\.)\s*$")


def logical_lines(src: FishSource) -> list[list[Tok]]:
    """Token lines; lines of a `command ... endcommand` section are kept raw (one `raw` token
    per physical line), to be read later by the deck reader."""
    out: list[list[Tok]] = []
    current: list[Tok] = []
    in_command = False
    for k, text in enumerate(src.lines):
        line = src.first_line + k
        if in_command and not current:
            bare = _CMD_COMMENT.sub("", text).strip()
            word = bare.split()[0].lower() if bare.split() else ""
            if word in ("endcommand", "end_command"):
                in_command = False
            elif not bare:
                continue
            else:
                raw = [Tok("raw", text, line, 1, text)]
                if _CMD_CONT.search(bare):
                    current = raw
                else:
                    out.append(raw)
                continue
        elif in_command and current:
            current.append(Tok("raw", text, line, 1, text))
            if not _CMD_CONT.search(_CMD_COMMENT.sub("", text).strip()):
                out.append(current)
                current = []
            continue
        toks, cont = tokenize_line(src, line, text)
        current.extend(toks)
        if cont:
            continue
        if current:
            out.append(current)
            if len(current) == 1 and current[0].is_word("command"):
                in_command = True
        current = []
    if current:
        out.append(current)
    return out
