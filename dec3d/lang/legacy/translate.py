"""The 3DEC 4/5 -> 3DEC 7+ deck translator: `dec3d translate` and the in-memory path of `dec3d run`.

Line by line: a legacy command (its `&` continuation lines included) becomes one or more 3DEC 7+
commands on the same lines (extra commands follow on lines of their own); `def`/`define … end`
becomes `fish define … end` with its body's names translated (`fish.py`), and the command lines
of its `command … endcommand` sections are translated as commands. A line it cannot translate is
kept as a comment: `; dec3d translate: could not translate: <the line>  (<why>)`. The `LineMap`
takes every translated position back to the original file, line and column.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from .commands2 import is_legacy_word, translate_command
from .fish import translate_fish_line
from .lines import NOTE, LineMap, Out, OutLine, continues, split_comment, tokens

#: 3DEC 7+ top-level words: a line that starts with one is kept as it is (a deck that mixes both)
MODERN = {"model", "block", "program", "fish", "feblock", "structure", "table", "zone", "exit", "quit"}
_FISH_DEFINE = re.compile(r"^\s*fish\s+def\w*\s+", re.IGNORECASE)
_DEF = re.compile(r"^\s*(def|define)\s+([A-Za-z_]\w*)(.*)$", re.IGNORECASE)
_FISH_END = re.compile(r"^\s*end\s*$", re.IGNORECASE)
_CMD = re.compile(r"^\s*command\s*$", re.IGNORECASE)
_AT_CALL = re.compile(r"^\s*@([A-Za-z_]\w*)\s*\((.*)\)\s*$")
_VEC = re.compile(r"\(\s*([^(),]+,[^(),]+,[^(),]+)\)")      # (x, y, z): a vector in 3DEC 5 FISH
_ENDCMD = re.compile(r"^\s*(endcommand|end_command)\s*$", re.IGNORECASE)


@dataclass
class State:
    mats: dict = field(default_factory=dict)          # material number -> (density token, zone properties)
    jmats: dict = field(default_factory=dict)         # joint material number -> [(keyword, token)]
    created_mats: set = field(default_factory=set)
    ranges: set = field(default_factory=set)          # named ranges (now groups in slot 'range')
    fish: set = field(default_factory=set)            # the deck's FISH function names (lower case)
    zoned: bool | None = None
    hides: list = field(default_factory=list)         # the `hide` commands in force (3DEC 7+ text)
    shown: bool = False                               # they are shown for the mechanics (since a cycle)
    untranslated: int = 0


@dataclass
class Translation:
    text: str
    map: LineMap
    untranslated: int          # lines left as `could not translate` comments


def looks_legacy(text: str) -> bool:
    """Whether a deck is 3DEC 4/5 syntax: a top-level line starts with a 3DEC 5 command word that is not
    a 3DEC 7+ command (`new`, `poly`, `prop`, `def`, `cycle` …)."""
    modern = MODERN | {"list", "call", "title", "return", "plot", "history"}
    depth = 0
    cont = False
    for raw in text.splitlines():
        code, _ = split_comment(raw)
        words = code.split()
        after, cont = cont, continues(code)
        if not words or after:         # a continuation line (`… &` before it) starts no command
            continue
        w = words[0].lower()
        if depth == 0 and w in ("def", "define"):
            return True
        if w == "fish" and len(words) > 1 and words[1].lower().startswith("def"):
            depth = 1
            continue
        if depth:
            if w == "end":
                depth = 0
            continue
        if w.startswith(("@", "[")) or w in modern:
            continue
        if is_legacy_word(w):
            return True
    return False


def _fish_names(lines: list[str]) -> set[str]:
    names = set()
    for raw in lines:
        m = _DEF.match(split_comment(raw)[0])
        if m:
            names.add(m.group(2).lower())
    return names


def translate_text(text: str, filename: str = "<input>", state: State | None = None) -> Translation:
    """The 3DEC 7+ text of a legacy deck. ``state`` carries materials, named ranges, FISH names and hidden
    blocks from the decks translated before in the same run (a chain of decks run in one session)."""
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    src = text.split("\n")
    state = state if state is not None else State()
    state.untranslated = 0
    state.fish |= _fish_names(src)
    rows: list[OutLine] = []
    i, n = 0, len(src)
    in_fish = in_cmd = False
    while i < n:
        raw = src[i]
        code, comment = split_comment(raw)
        line = i + 1
        if in_fish and not in_cmd:
            if _FISH_END.match(code):
                in_fish = False
                rows.append(OutLine([Out(code.rstrip(), line, 1)], line, comment))
            elif _CMD.match(code):
                in_cmd = True
                rows.append(OutLine([Out(code.rstrip(), line, 1)], line, comment))
            else:
                new, notes = translate_fish_line(code.rstrip(), state.fish)
                if notes:
                    state.untranslated += 1
                    comment = (comment + " " if comment else "") + NOTE + "; ".join(notes)
                parts = new.split("\n")         # a line that became several (`x = c_cx(c)`)
                rows.append(OutLine([Out(parts[0], line, 1)] if parts[0].strip() else [], line, comment))
                rows += [OutLine([Out(p, line, 1)], line) for p in parts[1:]]
            i += 1
            continue
        if in_cmd and _ENDCMD.match(code):
            in_cmd = False
            rows.append(OutLine([Out(code.rstrip(), line, 1)], line, comment))
            i += 1
            continue
        if _FISH_DEFINE.match(code) and not in_cmd:      # a 3DEC 7+ function: kept as it is, to its `end`
            while i < n:
                rows.append(OutLine([Out(src[i], i + 1, 1)], i + 1))
                i += 1
                if _FISH_END.match(split_comment(src[i - 1])[0]):
                    break
            continue
        m = _DEF.match(code)
        if m and not in_cmd:
            in_fish = True
            rows.append(OutLine([Out("fish define", line, m.start(1) + 1), Out(m.group(2) + m.group(3).rstrip(),
                                                                              line, m.start(2) + 1)], line, comment))
            i += 1
            continue
        # one logical command: this line and its continuation lines
        group = [i]
        while continues(split_comment(src[group[-1]])[0]) and group[-1] + 1 < n and not in_cmd:
            group.append(group[-1] + 1)
        i = group[-1] + 1
        toks = [t for k in group for t in tokens(split_comment(src[k])[0], k + 1)]
        if not toks:
            rows += [OutLine([], k + 1, split_comment(src[k])[1]) for k in group]
            continue
        call = _AT_CALL.match(code)
        if call and len(group) == 1:           # `@f( (@x, @y, @z) )`: a FISH function called with arguments
            args = _VEC.sub(lambda mv: f"vector({mv.group(1)})", call.group(2).replace("@", ""))
            rows.append(OutLine([Out(f"[{call.group(1)}({args.strip()})]", line, code.index("@") + 1)], line, comment))
            continue
        if toks[0].text.startswith("@") or toks[0].text.startswith("[") or toks[0].low in MODERN:
            rows += [OutLine([Out(split_comment(src[k])[0].rstrip(), k + 1, 1)], k + 1, split_comment(src[k])[1])
                     for k in group]
            continue
        if len(toks) == 1 and toks[0].low in state.fish:       # a bare FISH function name runs it
            rows.append(OutLine([Out(f"[{toks[0].text}]", line, toks[0].col)], line, comment))
            rows += [OutLine([], k + 1, split_comment(src[k])[1]) for k in group[1:]]
            continue
        cmds, why = translate_command(toks, state)
        if cmds is None:
            state.untranslated += len(group)
            for k in group:
                rows.append(OutLine([], k + 1, f"{NOTE}{src[k].strip()}" + (f"  ({why})" if k == group[0] else "")))
            continue
        rows += _lay_out(cmds[0], group, src)
        for extra in cmds[1:]:
            rows.append(OutLine(extra, extra[0].line))
    lmap = LineMap(filename, src)
    out_text = []
    for row in rows:
        t, segs = row.render()
        out_text.append(t)
        lmap.rows.append((row.line, segs))
    return Translation("\n".join(out_text), lmap, state.untranslated)


def _lay_out(pieces: list[Out], group: list[int], src: list[str]) -> list[OutLine]:
    """The pieces of one command on the original lines of the command (`&` between them)."""
    by_line = {k + 1: [] for k in group}
    cur = group[0] + 1
    for p in pieces:
        if p.line in by_line and p.line >= cur:
            cur = p.line
        by_line[cur].append(p)
    rows = []
    filled = [k for k in group if by_line[k + 1]]
    last = filled[-1] + 1 if filled else group[-1] + 1
    for k in group:
        ps = by_line[k + 1]
        if k + 1 < last:
            ps = ps + [Out("&", k + 1, 10 ** 6)]
        code = split_comment(src[k])[0]
        indent = code[:len(code) - len(code.lstrip())]
        if ps and indent:
            ps = [Out(indent + ps[0].text, ps[0].line, ps[0].col)] + ps[1:]
        rows.append(OutLine(ps, k + 1, split_comment(src[k])[1]))
    return rows
