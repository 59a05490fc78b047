"""Pre-pass over deck text: lift `fish define ... end` blocks out of the command stream.

FISH bodies have a syntax of their own (if/loop/local/command...endcommand) that the
line grammar does not describe. They are kept as raw text for dec3d.fish, which
parses and compiles them; their lines are blanked (not removed) so every other line keeps its
true line number. 3DEC accepts `def` as an abbreviation of `define` and, in data
files, a bare `define`/`def` opening a function (3DEC 7 manual, "FISH in data files").
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import DeckSyntaxError, SourceLocation

_DEFINE = re.compile(
    r"^[ \t]*(?:fish[ \t]+)?(?:def|defi|defin|define)(?![A-Za-z0-9_\-])[ \t]*"
    r"(?P<name>[A-Za-z_][A-Za-z0-9_.]*)?(?P<args>[ \t]*\([^)]*\))?",
    re.IGNORECASE,
)
_END = re.compile(r"^[ \t]*end[ \t]*(?:;.*)?$", re.IGNORECASE)
# assignments and global declarations inside a body: the variables a function sets
_ASSIGN = re.compile(r"^[ \t]*(?:local[ \t]+|global[ \t]+)?([A-Za-z_][A-Za-z0-9_]*)[ \t]*(?:=(?!=)|\+=|-=|\*=|/=)", re.I)
_GLOBAL = re.compile(r"^[ \t]*global[ \t]+(.*)$", re.I)


@dataclass(frozen=True)
class FishBlock:
    """A `fish define name(args) ... end` block, kept verbatim."""

    name: str
    params: tuple[str, ...]
    body: str
    line: int          # line of the `define`, from 1
    end_line: int
    variables: frozenset[str]   # names the body assigns or declares global (lower case)


def lift_fish(text: str, filename: str) -> tuple[str, list[FishBlock]]:
    """Return `text` with FISH blocks blanked, and the blocks in order."""
    lines = text.split("\n")
    blocks: list[FishBlock] = []
    i = 0
    n = len(lines)
    while i < n:
        raw = lines[i]
        stripped = raw.lstrip()
        # cheap filter: only lines starting with f/d can open a FISH block
        if stripped[:1] not in ("f", "F", "d", "D"):
            i += 1
            continue
        m = _DEFINE.match(raw)
        if m is None or (m.group("name") is None):
            i += 1
            continue
        name = m.group("name")
        params = ()
        if m.group("args"):
            params = tuple(p.strip().lower() for p in m.group("args").strip()[1:-1].split(",") if p.strip())
        start = i
        j = i + 1
        while j < n and not _END.match(lines[j].rstrip("\r")):
            j += 1
        if j >= n:
            raise DeckSyntaxError(
                f"`fish define {name}` has no matching `end`",
                SourceLocation(filename, start + 1, m.start("name") + 1, raw, len(name)),
                hint="close the function with a line holding only `end`",
            )
        body_lines = lines[start + 1 : j]
        variables = {name.lower()}
        for b in body_lines:
            g = _GLOBAL.match(b)
            if g:
                variables.update(v.split("=")[0].strip().lower() for v in g.group(1).split(";")[0].split(",")
                                 if v.split("=")[0].strip())
                continue
            a = _ASSIGN.match(b)
            if a:
                variables.add(a.group(1).lower())
        blocks.append(FishBlock(name, params, "\n".join(body_lines), start + 1, j + 1, frozenset(variables)))
        for k in range(start, j + 1):
            lines[k] = ""
        i = j + 1
    return "\n".join(lines), blocks
