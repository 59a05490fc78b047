"""Hostile decks for the lexer's template path (``parser._lex_fast``: a physical line whose key — its
ASCII digits as 0 — repeats is cut where an earlier line of the key was): lines of one key that differ
in what must not lex alike (digits in strings, `[ ]`, `@names`, comments; `01` against `10`; numbers too
large for a float; tabs, form feeds, trailing blanks; continuations; non-ASCII digits and letters; CRLF
and CR line ends; very long lines). Each deck gives the tokens of lark's lexer and of the fast lexer with
no template, and binds line by line as the ordinary binder does."""
import sys
from pathlib import Path

import numpy as np
import pytest

from dec3d.commands import load_all
from dec3d.commands.binder import BindContext, Binder
from dec3d.errors import Dec3dError
from dec3d.lang import parser
from dec3d.lang.parser import _lex_fast, _lex_lark, normalise, parse_deck
from dec3d.lang.prepass import lift_fish

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "lang"))
from bound_form import norm  # noqa: E402  (the comparable form tests/lang compares bindings in)

load_all()

FIELDS = ("type", "value", "line", "column", "end_line", "end_column", "start_pos", "end_pos")

GROUPS = {
    "strings": ["model title 'g1'", "model title 'g9'", "model title 'g5'", "model title \"7\""],
    "range-strings": ["block group 'g1' range id 1", "block group 'g9' range id 2", "block group 'g5' range id 3"],
    "expressions": ["[x1 = 1]", "[x9 = 2]", "model gravity 0 0 [x1]", "model gravity 0 0 [x9]",
                    "model gravity 0 0 [x7]", "model gravity 0 0 [1+]", "model gravity 0 0 [9/0]"],
    "at-names": ["[a1 = 1]", "model gravity 0 0 @a1", "model gravity 0 0 @a1", "model gravity 0 0 @a2"],
    "leading-zeros": ["model cycle 01", "model cycle 10", "model cycle 00", "model cycle 99"],
    "exponents": ["model gravity 1e5 0 0", "model gravity 1e9 0 0", "model gravity 1e99999 0 0",
                  "model gravity 1e0 0 0"],
    "integers-beyond-64-bits": ["model cycle 10000000000000000000", "model cycle 90000000000000000000",
                                "model cycle 00000000000000000001"],
    "comments": ["model gravity 0 0 -10 ; 1 2 3", "model gravity 0 0 -20 ; 4 5 6", "model gravity 0 0 -30 ; 7 & 9"],
    "trailing-blanks": ["model gravity 0 0 -10\t", "model gravity 0 0 -20 ", "model gravity 0 0 -30\t",
                        "model gravity 0 0 -40 ", "model gravity 0 0 -50\x0c"],
    "tabs-for-spaces": ["model gravity\t0 0 -10", "model gravity 0\t0 -20", "model gravity\t0 0 -30",
                        "model gravity 0\t0 -40"],
    "continuations": ["model gravity 0 0 -10 &", "0", "model gravity 0 0 -10", "model gravity 0 0 -10",
                      "model gravity 0 0 -10 &", " 1", "model gravity 0 0 -1 ...", " 2", "model &", "gravity 0 0 1"],
    "non-ascii-digits": ["model gravity 0 0 \u0661", "model gravity 0 0 \u0662", "model gravity 0 0 1",
                         "model gravity 0 0 \u0663", "model gravity 0 0 2"],
    "non-ascii-letters": ["model title '\u00e91'", "model title '\u00e92'", "model title '\u20ac9'"],
    "delimiters": ["model gravity 0,0,-1", "model gravity 0,0,-2", "model gravity (0,0,-3)", "model gravity (0,0,-4)"],
    "numbers-or-words": ["model gravity 0 0 1a", "model gravity 0 0 2a", "model gravity 0 0 3_b",
                         "model gravity 0 0 1e", "model gravity 0 0 2e", "model gravity 0 0 5."],
    "bad-values": ["block create brick 0 1 0 1 0 1", "block create brick 1 0 0 1 0 1", "block create brick 0 0 0 0 0 0",
                   "block contact jmodel assign elastic range id 1", "block contact jmodel assign elastic range id 0"],
    "long-lines": ["block create brick 0 1 0 1 0 1 ; " + "x1" * 5000, "block create brick 0 2 0 2 0 2 ; " + "x9" * 5000,
                   "block create brick 1 2 1 2 1 2 ; " + "x5" * 5000],
    "liner-sizes": ["structure liner create by-quadrilateral 0 0 0 1 0 0 1 1 0 0 1 0 size 1 1",
                    "structure liner create by-quadrilateral 0 0 0 1 0 0 1 1 0 0 1 0 size 9 9",
                    "structure liner create by-quadrilateral 0 0 0 0 0 0 0 0 0 0 0 0 size 0 0"],
}


def _tokens(lines):
    return [[tuple(getattr(t, f) for f in FIELDS) for t in raw.tokens] for raw in lines]


def _outcome(fn, raw):
    try:
        call = fn(raw)
    except Dec3dError as exc:
        loc = exc.location
        return ("error", type(exc).__name__, exc.message, None if loc is None else (loc.line, loc.column))
    if not hasattr(call, "command"):
        return ("statement", norm(call.node))
    rng = None if call.range is None else (call.range.union, tuple(
        (e.element.name, norm(e.args), e.negate, norm(e.location)) for e in call.range.elements))
    return ("call", call.command.path, norm(call.args), call.given, rng, call.location, norm(call.extra),
            norm(call.locations), call.text)


def _check(text: str) -> None:
    lifted, _ = lift_fish(normalise(text), "x.dat")
    fast = _lex_fast(lifted)
    ref = _lex_lark(lifted)
    assert fast is not None and _tokens(fast) == _tokens(ref)
    keep = parser.MAX_TEMPLATES
    try:
        parser.MAX_TEMPLATES = 0                       # the template path off
        plain = _lex_fast(lifted)
    finally:
        parser.MAX_TEMPLATES = keep
    assert _tokens(plain) == _tokens(fast)
    deck = parse_deck(text, "d.dat")
    planned = Binder(deck, BindContext(lenient_names=True))
    ordinary = Binder(deck, BindContext(lenient_names=True))

    def bind(raw):
        toks = raw.tokens
        if len(toks) == 1 and toks[0].type in ("EXPR", "ATNAME"):
            return ordinary.bind_line(raw)
        return ordinary._bind(toks)

    for raw in deck.lines:
        assert _outcome(planned.bind_line, raw) == _outcome(bind, raw), raw.line


@pytest.mark.parametrize("name", list(GROUPS))
@pytest.mark.parametrize("end", ["\n", "\r\n", "\r"])
def test_lines_of_one_key_lex_and_bind_as_without_templates(name, end):
    lines = GROUPS[name]
    text = end.join(lines * 3) + end
    _check(text)
    assert _tokens(parse_deck(text, "d.dat").lines) == _tokens(parse_deck(text.replace(end, "\n"), "d.dat").lines)


def test_random_hostile_lines_of_one_key():
    """Random lines of a hostile alphabet, each followed by lines of its key (other ASCII digits)."""
    rng = np.random.default_rng(2026)
    alpha = ["model", "gravity", "cycle", " ", "\t", "\x0c", ",", "(", ")", "=", "&", "...", ";", "'", '"', "[", "]",
             "@a1", "x1", "1", "0", "9", "1e5", "1e99999", "-", "+", ".", "\u0661", "\u00e9", "\u00a0", "\u2028",
             "\x85", "block", "range", "id", "'g1'", "[a1]", "[a1+1]", "1a", "01", " 1 2 3", "\\", "/", ":", "_", "e"]
    used = 0
    for _ in range(600):
        line = "".join(rng.choice(alpha, size=int(rng.integers(1, 14))))
        more = ["".join(str(rng.integers(10)) if c in "0123456789" else c for c in line)
                for _ in range(int(rng.integers(2, 5)))]
        text = "\n".join(["[a1 = 1]", line] + more) + "\n"
        lifted, _ = lift_fish(normalise(text), "x.dat")
        try:
            _lex_lark(lifted)
        except Exception:
            assert _lex_fast(lifted) is None
            continue
        _check(text)
        used += 1
    assert used > 100
