"""3DEC 4/5 range phrases -> 3DEC 7+ range elements (reference §10 and §13)."""
from __future__ import annotations

from .lines import Out, Tok


def q(name: str) -> str:
    """A quoted group name."""
    return "'" + name.strip("'\"") + "'"


def legacy_word(word: str, table: dict[str, tuple[int, object]]):
    """The entry of ``table`` (name -> (shortest abbreviation, value)) that ``word`` spells, or None."""
    w = word.lower()
    for name, (short, value) in table.items():
        if len(w) >= short and name.startswith(w):
            return name, value
    return None


def is_value(t: Tok) -> bool:
    s = t.text
    if s.startswith(("@", "[", "'", '"')):
        return True
    try:
        float(s)
        return True
    except ValueError:
        return False


def named(name: str) -> str:
    """A 3DEC 5 named range is a group of its own slot (named ranges may overlap; a slot holds one group)."""
    return f"group {q(name)} slot {q(name)}"


_AXIS = {"x": "position-x", "y": "position-y", "z": "position-z"}


def translate_range(toks: list[Tok], state) -> tuple[list[Out] | None, str]:
    """Range elements of a legacy command (after `range`, or the bare elements of `hide reg 1`).
    Returns (pieces, "") or (None, why)."""
    out: list[Out] = []
    i = 0
    while i < len(toks):
        t = toks[i]
        w = t.low
        vals = []
        j = i + 1
        while j < len(toks) and is_value(toks[j]):
            vals.append(toks[j])
            j += 1
        if w == "range":
            i += 1
            continue
        if w in _AXIS and len(vals) == 2:
            out += [Out(_AXIS[w], t.line, t.col)] + [Out(v.text, v.line, v.col) for v in vals]
        elif legacy_word(w, {"region": (3, 0)}) and len(vals) == 1:
            out += [Out("region", t.line, t.col), Out(vals[0].text, vals[0].line, vals[0].col)]
        elif legacy_word(w, {"material": (3, 0)}) and len(vals) == 1 and w != "matrix":
            out += [Out(f"group {q('mat' + vals[0].text)} slot 'material'", t.line, t.col)]
        elif legacy_word(w, {"jmaterial": (4, 0)}) and len(vals) == 1:
            out += [Out(f"group {q('jmat' + vals[0].text)} slot 'jmat'", t.line, t.col)]
        elif w in ("block", "id") and len(vals) == 1:
            out += [Out("id", t.line, t.col), Out(vals[0].text, vals[0].line, vals[0].col)]
        elif w == "group" and len(vals) == 1:
            out += [Out(f"group {q(vals[0].text)}", t.line, t.col)]
        elif w in ("name", "nrange") and i + 1 < len(toks):
            j = i + 1
            while j < len(toks) and (j == i + 1 or toks[j].low in state.ranges):
                out.append(Out(named(toks[j].text), toks[j].line, toks[j].col))
                j += 1
        elif w in ("not", "union"):
            out.append(Out(w, t.line, t.col))
        elif w in ("plane", "sphere", "cylinder", "cyl"):
            return None, f"the `{t.text}` range element (write it by hand: range {t.text} ...)"
        elif w in state.ranges and not vals:
            out.append(Out(named(t.text), t.line, t.col))
        else:
            return None, f"range element `{t.text}`"
        i = j
    return out, ""
