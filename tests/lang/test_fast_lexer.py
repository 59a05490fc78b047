"""The deck lexer (``parser._lex_fast``, one regular expression) against its reference, lark's lexer
on the same grammar (``parser._lex_lark``): the same tokens, with the same positions, on every deck
of the repository, every public deck, and random text; text it cannot lex is reported by lark."""
from pathlib import Path

import numpy as np
import pytest

from dec3d.errors import DeckSyntaxError
from dec3d.lang.parser import _lex_fast, _lex_lark, normalise, parse_deck
from dec3d.lang.prepass import lift_fish
from conftest import DECKS, NO_DECKS, ROOT

FIELDS = ("type", "value", "line", "column", "end_line", "end_column", "start_pos", "end_pos")


def _tokens(lines):
    return [[tuple(getattr(t, f) for f in FIELDS) for t in raw.tokens] for raw in lines]


def _both(text: str):
    lifted, _ = lift_fish(normalise(text), "x.dat")
    fast = _lex_fast(lifted)
    try:
        ref = _lex_lark(lifted)
    except Exception as exc:               # lark refuses: the fast lexer must give up too
        assert fast is None, f"fast lexer accepted text lark refuses ({exc})"
        return None
    assert fast is not None, "fast lexer gave up on text lark accepts"
    assert _tokens(fast) == _tokens(ref)
    for raw in fast:                       # a run of numbers: its texts are its tokens' (binding reads them)
        for it in raw.items:
            if it.type == "NUMRUN":
                assert it.nums == [t.value for t in it.tokens()] and len(it.nums) >= 2
                assert (it.line, it.start, it.text) == (it.tokens()[0].line, it.tokens()[0].start_pos,
                                                        lifted[it.start:it.tokens()[-1].end_pos])
    return len(ref)


def _repo_decks():
    return sorted(p for d in ("examples", "verification") for p in (ROOT / d).rglob("*.dat"))


def test_same_tokens_on_the_repository_decks():
    decks = _repo_decks()
    assert len(decks) > 20
    lines = sum(_both(p.read_text(encoding="utf-8", errors="replace")) or 0 for p in decks)
    assert lines > 1000


def test_same_tokens_on_the_public_decks():
    if not DECKS.is_dir():
        pytest.skip(NO_DECKS)
    decks = sorted(DECKS.rglob("*.dat"))
    assert decks
    for p in decks:
        _both(p.read_text(encoding="utf-8", errors="replace"))


ALPHABET = list("abcXYZ_019.+-eE ,()=\t;&'\"[]@\n:/\\\x0c") + ["...", "1e5", "-.5", "block ", "& ; c\n"]


def test_same_tokens_or_the_same_refusal_on_random_text():
    rng = np.random.default_rng(11)
    accepted = refused = 0
    for _ in range(3000):
        text = "".join(rng.choice(ALPHABET, size=int(rng.integers(1, 40))))
        if _both(text) is None:
            refused += 1
        else:
            accepted += 1
    assert accepted > 300 and refused > 300          # both branches met


def _other_digits(line: str, rng) -> str:
    return "".join(str(rng.integers(10)) if c in "0123456789" else c for c in line)


def test_lines_of_one_key_are_cut_alike():
    """From the third line of a key (its ASCII digits as 0) on, lines are cut by the template the second
    left (``_lex_fast``): random lines, each followed by lines of its key (other digits), continued or
    not, give lark's tokens, or lark's refusal."""
    rng = np.random.default_rng(12)
    alphabet = [c for c in ALPHABET if "\n" not in c] + ["0", "7", "12", "3.5", "-4e-2", "9,9", " 1 2 3"]
    used = 0
    for _ in range(2000):
        line = "".join(rng.choice(alphabet, size=int(rng.integers(1, 16))))
        lines = [line] + [_other_digits(line, rng) for _ in range(int(rng.integers(2, 6)))]
        if rng.random() < 0.2:             # a line of the key continued, or continuing one
            lines.insert(int(rng.integers(len(lines) + 1)), "model &" if rng.random() < 0.5 else line + " &")
        if _both("\n".join(lines) + "\n") is not None:
            used += 1
    assert used > 300


def test_a_line_of_a_known_key_and_a_bad_character():
    """A later line of a key lexed before still reports its own bad text (a key holds every character
    but the digits)."""
    text = "block create brick 0 1 0 1 0 1\n" * 3 + "block create brick 2 3 0 1 0 1`\n"
    assert _both(text) is None
    with pytest.raises(DeckSyntaxError) as info:
        parse_deck(text, "d.dat")
    assert (info.value.location.line, info.value.location.column) == (4, 31)


def test_bad_text_is_reported_with_its_line_and_column():
    with pytest.raises(DeckSyntaxError) as info:
        parse_deck("model new\nblock create brick 0 1 ` 2\n", "d.dat")
    assert (info.value.location.line, info.value.location.column) == (2, 24)
    assert "unexpected character" in str(info.value)
