"""Lines bound straight from the deck's text by the plan of their lexer key (``commands/bind_direct.py``,
``lang.parser.KeyLine``): the same command, values (floats by their bits), locations, range and text —
or the same error at the same file:line:column — as the ordinary binding, for every written form of a
number, values at and past their bounds, bad numbers in the middle of a run, continuations, comments,
tabs, form feeds, parentheses and `=` among the delimiters. Most such lines never make their tokens."""
import math
import random

import pytest

from dec3d.commands import bind_direct, load_all
from dec3d.commands.binder import BindContext, Binder
from dec3d.lang.parser import KeyLine, parse_deck
from test_bind_plans import _outcome, _same_outcomes

load_all()

#: number forms: `#` a random digit (lines of one template share their lexer key)
FORMS = ["#", "-#", "+#", "-0", "+0", "-00", "0#", "#.", ".#", "-.#", "#.#", "-#.#", "#e#", "#E-#", "-#e+#",
         "#.#e#", "#e99#", "-#e99#", "#" * 11, "-" + "#" * 11, "#" * 12, "#" * 13, "1000000000000", "-1000000000000",
         "#" * 16, "#" * 30, "##.#####################", "###########.#########", "0.0", "-0.0", "0e0", "-0e5"]

TEMPLATES = [
    "block create brick {n} {n} {n} {n} {n} {n}",
    "bl cr br {n} {n} {n} {n} {n} {n} group 'g{d}'",
    "block create brick {n} {n} {n} {n} {n} {n} ; a comment {d}",
    "block create brick {n}\t{n}  {n},{n} , {n} {n}",
    "block create brick ({n},{n}) ({n},{n}) ({n},{n})",
    "block create polyhedron face {p} face {p} face {p} face {p} face {p} face {p} group 'course_{d}'",
    "block create polyhedron face {p} face {p} face {p} face {p} group course slot s{d}",
    "block create polyhedron face {p} {n} face {p} face {p} face {p}",
    "block create polyhedron face {p} face {p} face {p} face {p} region {n}",
    "block create polyhedron face {p} face {p} face {p} face {p} group 'a,b c' face {p}",
    "block create polyhedron face {n},{n},{n} nan,{n},{n} {n},{n},{n} face {p} face {p} face {p}",
    "block create polyhedron face {n},{n},{n} {n},{n},{n} {n},inf,{n} face {p} face {p} face {p}",
    "block create polyhedron face {p} face [1 + {d}],{n},{n} {n},{n},{n} {n},{n},{n} face {p} face {p}",
    "block create polyhedron face {p} face @{w} {n} {n} {n} {n} {n} {n} {n} {n} face {p} face {p}",
    "block create tunnel dip {n} dip-direction {n} radius {n} length {n} {n} boundary {n} blocks-axial {n}",
    "block cut joint-set dip {n} dip-direction {n} origin {n},{n},{n} range position-z {n} {n} position-x {n} {n}",
    "block contact property stiffness-normal={n} stiffness-shear={n} friction={n}",
    "block contact property stiffness-normal {n} stiffness-shear {n} friction {n}",
    "block cut joint-set dip {n} dip-direction {n} spacing {n} number {n}",
    "model large-strain on",
    "block initialize velocity {n} {n} {n} range position-x {n} {n}",
    "model gravity {n} {n} {n}",
    "model gravity {n} {n} &\n  {n}",
    "block create brick {n} {n} ...\n  {n} {n} {n} {n} ; continued",
    "block create brick {n} {n} {n} {n} {n} {n}\f",
    "model title 'stage {d}'",
    "[x{d} = {n}]",
]


def _deck(seed: int, lines: int, templates=TEMPLATES, forms=FORMS) -> str:
    rng = random.Random(seed)
    # a few fixed fillings per template, so that lines of one key (the same forms) come back
    fillings = {}
    for t in templates:
        fillings[t] = []
        for _ in range(4):
            fs = iter([rng.choice(forms) for _ in range(200)])
            fillings[t].append(t.replace("{p}", "{n},{n},{n} {n},{n},{n} {n},{n},{n} {n},{n},{n}")
                               .replace("{n}", "\0").replace("{d}", "#").replace("{w}", "w")
                               .replace("\0", "%s") % tuple(next(fs) for _ in range(t.count("{n}") + 12 * t.count("{p}"))))

    def digits(s):
        return "".join(str(rng.randrange(10)) if c == "#" else c for c in s)

    out = [digits(rng.choice(fillings[rng.choice(templates)])) for _ in range(lines)]
    return "\n".join(out) + "\n"


def _direct_count(text: str) -> int:
    """Lines bound by one binder whose tokens were never made (bound from their text)."""
    deck = parse_deck(text, "d.dat")
    binder = Binder(deck, BindContext(lenient_names=True))
    for raw in deck.lines:
        _outcome(binder.bind_line, raw)
    return sum(type(raw) is KeyLine and raw._items is None for raw in deck.lines)


def test_lines_bound_from_their_text_bind_as_the_ordinary_binder():
    text = _deck(11, 4000)
    deck = parse_deck(text, "d.dat")
    assert sum(type(raw) is KeyLine for raw in deck.lines) > 2500
    assert _direct_count(text) > 400            # most forms of numbers are out of bounds somewhere
    assert _same_outcomes(text, "d.dat") > 800


def test_every_number_form_in_a_polyhedron_run():
    """Each form alone in the middle of a polyhedron's otherwise plain faces (and in the brick's run):
    out-of-bounds and overflowing values, negative zeros and exponents bind or fail as the ordinary
    binding does, the error at the number's own column."""
    templates = ["block create polyhedron face 1,2,3 4,5,6 7,8,{n} 1,1,1 face 2,2,2 {n},3,3 4,4,4 "
                 "face 5,5,5 6,6,6 7,7,7 face 8,8,8 9,9,9 9,{n},9 group 'g'",
                 "block create brick 0 {n} 0 1 {n} 1"]
    for form in FORMS:
        text = _deck(3, 60, templates, [form, "#", "#.#"])
        assert _same_outcomes(text, "f.dat") >= 0
        assert _direct_count(text) > 0 or form in ("#" * 30, "#e99#", "-#e99#")


def _binder_after(text: str) -> Binder:
    deck = parse_deck(text, "t.dat")
    binder = Binder(deck, BindContext(lenient_names=True))
    for raw in deck.lines:
        _outcome(binder.bind_line, raw)
    return binder


def test_the_table_of_numbers_when_full(monkeypatch):
    """The table of number texts (``Binder.numbers``) emptied when full gives the same values."""
    monkeypatch.setattr(bind_direct, "MAX_NUMBERS", 7)
    monkeypatch.setattr(bind_direct, "MIN_LOOKS", 10**9)       # never given up
    text = _deck(17, 1500, forms=["#", "-#", "#.#", "-0", "-0.0", ".#", "#.", "##"])
    assert _binder_after(text).numbers is not None
    assert _direct_count(text) > 300
    assert _same_outcomes(text, "t.dat") > 600


def test_the_table_of_numbers_given_up():
    """Numbers that seldom come back: the table is given up (the values converted each time), and
    where it was kept, the same values."""
    text = _deck(19, 3000, forms=["#.######", "-##.#####", "#e-#", "##.####"])
    assert _binder_after(text).numbers is None
    assert _direct_count(text) > 1000
    assert _same_outcomes(text, "t.dat") > 1500
    kept = _deck(19, 3000, forms=["#", "-#"])
    assert _binder_after(kept).numbers is not None
    assert _same_outcomes(kept, "t.dat") > 1500


@pytest.mark.parametrize("key, inline, within", [
    ("00.0", (-1e12, True, 1e12, True, False), True),
    ("-00000000000", (-1e12, True, 1e12, True, False), True),       # 11 digits: below 1e11
    ("000000000000", (-1e12, True, 1e12, True, False), True),       # 12 digits: at most 1e12, closed
    ("000000000000", (-1e12, True, 1e12, False, False), False),     # ... open
    ("0000000000000", (-1e12, True, 1e12, True, False), False),
    ("0e0", (-1e12, True, 1e12, True, False), False),              # an exponent: looked at
    ("0.0", (0.0, False, 1e12, True, False), False),               # zero below an open bound
    ("0.0", (0.0, True, 1e12, True, False), True),
    ("-0.0", (0.0, True, 1e12, True, False), False),               # a negative value may be there
    ("." + "0" * 40, (-1.0, False, 1.0, False, False), False),     # at most 1.0, open at 1
    ("0" * 16, (-math.inf, False, math.inf, False, False), False),  # beyond 15 digits: looked at
])
def test_bounds_told_by_the_key(key, inline, within):
    assert bind_direct._within([key], inline) is within

