"""Bind plans (``commands/bind_plan.py``): a line bound by the plan of an earlier line of its shape
gives what the ordinary binding gives — the same command, values, locations and range, or the same
error at the same file:line:column — on every deck of the repository, every public deck, and lines
made to differ from their shape's first line only where a value fails. ``Nums`` converting its
numbers inline gives ``Num.convert``'s values and errors."""

import pytest

from dec3d.commands import load_all
from dec3d.commands.bind_plan import shape
from dec3d.commands.binder import BindContext, Binder
from dec3d.commands.values import Num, Nums
from dec3d.errors import Dec3dError
from dec3d.lang.parser import parse_deck
from bound_form import norm as _norm
from conftest import DECKS, NO_DECKS, ROOT


load_all()


def _outcome(fn, raw):
    try:
        call = fn(raw)
    except Dec3dError as exc:
        loc = exc.location
        return ("error", type(exc).__name__, exc.message, exc.hint, (loc.file, loc.line, loc.column, loc.length)
                if loc is not None else None)
    if not hasattr(call, "command"):
        return ("statement", _norm(call.node), call.location, call.source)
    rng = None
    if call.range is not None:
        rng = (call.range.union, tuple((e.element.name, _norm(e.args), e.negate, _norm(e.location))
                                       for e in call.range.elements))
    return ("call", call.command.path, _norm(call.args), call.given, rng, call.location, _norm(call.extra),
            _norm(call.locations), call.span[1:], call.text)


def _same_outcomes(text: str, name: str = "d.dat") -> int:
    """Every line bound with plans (one binder for the deck) and the ordinary way: the same."""
    try:
        deck = parse_deck(text, name)
    except Dec3dError:
        return 0
    planned = Binder(deck, BindContext(lenient_names=True))
    plain = Binder(deck, BindContext(lenient_names=True))
    for fish in deck.fish:
        planned.ctx.define_fish(fish)
        plain.ctx.define_fish(fish)

    def ordinary(raw):
        toks = raw.tokens
        if len(toks) == 1 and toks[0].type in ("EXPR", "ATNAME"):
            return plain.bind_line(raw)
        return plain._bind(toks)

    replayed = 0
    for raw in deck.lines:
        known = shape(raw.items) in planned.plans      # plans are keyed by the lexer items
        a = _outcome(planned.bind_line, raw)
        b = _outcome(ordinary, raw)
        assert a == b, f"{name}:{raw.line}"
        replayed += known and a[0] == "call"
    return replayed


def test_plans_bind_every_repository_deck_as_the_ordinary_binder():
    decks = sorted(p for d in ("examples", "verification") for p in (ROOT / d).rglob("*.dat"))
    assert len(decks) > 20
    replayed = sum(_same_outcomes(p.read_text(encoding="utf-8", errors="replace"), p.name) for p in decks)
    assert replayed > 500          # many lines were bound by a plan


def test_plans_bind_every_public_deck_as_the_ordinary_binder():
    if not DECKS.is_dir():
        pytest.skip(NO_DECKS)
    for p in sorted(DECKS.rglob("*.dat")):
        _same_outcomes(p.read_text(encoding="utf-8", errors="replace"), p.name)


LINES = [
    "block create brick 0 1 0 1 0 1",
    "block create brick 0 2 0 2.5 0 1e999",            # not finite: the plan's take fails
    "block create brick 0 1 0 1 0 [1 + ]",               # a bad expression
    "block create brick 0 1 0 1 0 [nothing_set]",        # an undefined name (lenient: deferred)
    "model gravity 0 0 -9.81",
    "model gravity 0 0 1" + "0" * 400,                   # an integer too large for a float
    "model gravity 0 0 -0",                              # an integer zero stays +0.0
    "model gravity 0 0 -0.0",
    "model title 'a'",
    "model title 'b'",
    "block contact jmodel assign elastic range id 1",
    "block contact jmodel assign elastic range id 2.5",  # not an integer
    "block contact jmodel assign elastic range id 3",
    "block contact property stiffness-normal 1e9 stiffness-shear 1e8 friction 30",
    "block contact property stiffness-normal 1e9 stiffness-shear 1e8 friction 1e999",
    "block contact property stiffness-normal -1 stiffness-shear 1e8 friction 30",
    "block contact property stiffness-normal 2e9 stiffness-shear 2e8 friction 20 range id 4 not",
    "block contact property stiffness-normal 2e9 stiffness-shear 2e8 friction 20 range id 5 not",
    "block fix velocity range position-z 0",
    "block fix velocity range position-z 1e999",
    "block fix velocity range position-z 2",
    "block fix velocity range group 'g' position-z 0 union",
    "block fix velocity range group 'h' position-z 1 union",
    "model cycle 10",
    "model cycle 2.5",
    "model cycle -1",
    "model cycle 20",
]


def test_lines_of_one_shape_with_bad_values_bind_as_the_ordinary_binder():
    text = "\n".join(LINES * 3) + "\n"
    deck = parse_deck(text, "d.dat")
    binder = Binder(deck, BindContext(lenient_names=True))
    kinds = [_outcome(binder.bind_line, raw)[0] for raw in deck.lines]
    assert kinds.count("call") > 40 and kinds.count("error") > 20      # both met
    assert _same_outcomes(text) > 40


ITEMS = [Num(), Num(lo=0, lo_open=True, hi=1e12), Num(lo=0, hi=90, hi_open=True), Num(angle=True),
         Num(lo=-1, hi=1, angle=True), Num(lo=0, lo_open=True, hi=1, hi_open=True)]
LITERALS = ["0", "-0", "+0", "-0.0", "1", "-1", "0.5", "1e3", "1E-3", ".5", "5.", "90", "89.99999", "1e12",
            "1.0000001e12", "1e999", "-1e999", "1" + "0" * 400, "-" + "9" * 320, "007", "1e-320"]


@pytest.mark.parametrize("item", ITEMS, ids=repr)
def test_nums_convert_inline_as_num_does(item):
    deck = parse_deck(" ".join(LITERALS) + "\n", "n.dat")
    toks = deck.lines[0].tokens
    binder = Binder(deck, BindContext())
    for k, tok in enumerate(toks):
        try:
            want = ("ok", _norm(item.take(toks, k, binder)[0]))
        except Dec3dError as exc:
            want = ("error", type(exc).__name__, exc.message, str(exc.location))
        try:
            got = Nums(1, 1, item=item).take(toks, k, binder)
            got = ("ok", _norm(got[0][0]))
        except Dec3dError as exc:
            got = ("error", type(exc).__name__, exc.message, str(exc.location))
        assert got == want, str(tok)


def test_what_is_made_while_reading_is_still_collected():
    """``gc_paused`` moves what was made meanwhile to the oldest generation unscanned; a cycle among
    it is still found by a full collection, and the collector is on again (if it was)."""
    import gc
    import weakref

    from dec3d.lang.parser import gc_paused

    class Node:
        pass

    assert gc.isenabled()
    with gc_paused():
        assert not gc.isenabled()
        a, b = Node(), Node()
        a.other, b.other = b, a
        gone = weakref.ref(a)
    assert gc.isenabled() and gc.get_freeze_count() == 0
    del a, b
    assert gone() is not None          # a cycle: only the collector frees it
    gc.collect()
    assert gone() is None


def test_calls_and_locations_made_field_by_field_equal_their_constructors():
    """``errors.frozen_instance`` (bound lines' commands and locations): every field set, equal to
    what the dataclass constructor makes."""
    from dataclasses import fields

    from dec3d.commands.binder import CommandCall
    from dec3d.errors import SourceLocation

    deck = parse_deck("model gravity 0 0 -9.81\nmodel gravity 0 0 -1\n", "g.dat")
    binder = Binder(deck, BindContext())
    for raw in deck.lines:
        call = binder.bind_line(raw)
        assert {f.name for f in fields(CommandCall)} == set(vars(call))
        assert call == CommandCall(call.command, call.args, call.given, call.range, call.location, call.extra,
                                   call.locations, call.span)
        loc = call.location
        assert {f.name for f in fields(SourceLocation)} == set(vars(loc))
        assert loc == SourceLocation("g.dat", raw.line, 1, deck.source_lines[raw.line - 1], 5, ())
        assert hash(loc) == hash(SourceLocation("g.dat", raw.line, 1, deck.source_lines[raw.line - 1], 5, ()))


def test_a_statement_line_made_field_by_field_equals_its_constructor():
    from dataclasses import fields

    from dec3d.commands.binder import ExprStatement

    deck = parse_deck("[x = 1 + 2] ; set x\n", "s.dat")
    st = Binder(deck, BindContext()).bind_line(deck.lines[0])
    assert {f.name for f in fields(ExprStatement)} == set(vars(st))
    assert st == ExprStatement(st.node, st.location, "[x = 1 + 2]")


def test_runs_of_numbers_replayed_on_items_bind_as_the_ordinary_binder():
    """Lines whose numbers are lexed as runs (``NumRun``) and replayed on them (``bind_plan.replay_compact``):
    random numbers of every written form, in and out of bounds, next to `[ ]`, continuations and other
    delimiters, give what the ordinary binding gives."""
    import random

    rng = random.Random(5)
    forms = ["0", "-0", "+0", "-0.0", "0.0", "1", "-1", "2.5", ".5", "5.", "007", "1e3", "-2E-4", "1e999", "-1e999",
             "1" + "0" * 30, "1e12", "1.0000001e12", "-1e12", "89.9", "90", "[1 + 1]"]

    def n():
        return rng.choice(forms)

    shapes = [
        lambda: f"block create brick {n()} {n()} {n()} {n()} {n()} {n()}",
        lambda: f"block create brick ({n()},{n()}) ({n()},{n()}) ({n()},{n()})",
        lambda: f"block create brick {n()} {n()} ...\n  {n()} {n()} {n()} {n()}",
        lambda: f"model gravity {n()} {n()} {n()}",
        lambda: f"model gravity {n()},{n()} &\n {n()}",
        lambda: f"block contact property stiffness-normal {n()} stiffness-shear {n()} friction {n()}",
        lambda: f"block fix velocity range position-z {n()} {n()} position-x {n()} {n()}",
        lambda: f"block initialize velocity {n()} {n()} {n()} range position-x {n()} {n()}",
        lambda: "block create polyhedron " + " ".join(f"face {n()},{n()},{n()} {n()},{n()},{n()} {n()},{n()},{n()}"
                                                     for _ in range(2)),
    ]
    text = "\n".join(rng.choice(shapes)() for _ in range(1500)) + "\n"
    deck = parse_deck(text, "r.dat")
    assert sum(it.type == "NUMRUN" for raw in deck.lines for it in raw.items) > 1000
    binder = Binder(deck, BindContext(lenient_names=True))
    kinds = [_outcome(binder.bind_line, raw)[0] for raw in deck.lines]
    assert kinds.count("call") > 300 and kinds.count("error") > 300      # both met
    assert any(p.compact is not None for p in binder.plans.values())
    assert _same_outcomes(text, "r.dat") > 300


def test_lines_of_one_lexer_key_bind_as_the_ordinary_binder():
    """Lines of one lexer key (the same text but their digits) are cut by the lexer's template and bound
    by the plan found through the key (``RawLine.key``, ``Binder.by_key``); a polyhedron's whole runs
    are converted in one pass (``Plan.batch``). Abbreviations, keyword values, signs, exponents, leading
    zeros, values out of bounds, words holding digits (no key), continuations and `[ ]`: the ordinary
    binding's results and errors."""
    import random

    rng = random.Random(9)

    def fill(t):
        return "".join(str(rng.randrange(10)) if c == "#" else c for c in t)

    templates = [
        "block create brick # #.# -# ## #e# #E-#",
        "bl cr br # # # # # #",
        "block create brick -# +# 0# .# #. -0",
        "block create brick #e99# # # # # #",
        "block create brick (#,#) (#,#) (#,#) ; a comment #",
        "block contact property stiffness-normal #e# stiffness-shear #e# friction ##",
        "block contact prop stiff-n #e# fric #",
        "block create polyhedron face #,#,# #,#,# #,#,# face -#,#,# #,#,# #,#,# group 'g#'",
        "block create polyhedron face #,#,# #,#,# #,#,# face #,#,# #,#,# ##,#,# group g#",
        "block create polyhedron face ## # # # # # # # # face # # # # # # # # #",
        "model gravity # # -#.##",
        "model gravity (#,#,#) ; g",
        "block fix velocity range position-z # # position-x -# #",
        "block initialize velocity # # # range position-x #.# #.#",
        "model title 'stage #'",
        "model large-strain on",
        "[x# = #.# * #]",
        "block create brick # # # # # # &\n  ; continued\n",
        "model gravity # # &\n -#",
        "block create brick # # # # # x#",
        "block create brick # # # # # # group g#",
        "block create brick # # # # # # group g0",
    ]
    text = "\n".join(fill(rng.choice(templates)) for _ in range(3000)) + "\n"
    deck = parse_deck(text, "k.dat")
    keyed = sum(raw.key is not None for raw in deck.lines)
    assert keyed > 2000
    binder = Binder(deck, BindContext(lenient_names=True))
    kinds = [_outcome(binder.bind_line, raw)[0] for raw in deck.lines]
    assert kinds.count("call") > 1000 and kinds.count("error") > 100      # both met
    assert len(binder.by_key) > 10 and any(p.batch is not None for p in binder.plans.values())
    assert _same_outcomes(text, "k.dat") > 1000


def test_words_holding_digits_are_not_found_by_their_key():
    """Lines whose words differ only in their digits (`g0`, `g5`) share a lexer key but not a shape:
    each binds its own word (the key finds no plan for them, ``RawLine.key`` is None)."""
    for word in ("g0", "g5", "x0y"):
        for later in ("g5", "g0", "x9y"):
            text = f"block create brick 0 1 0 1 0 1 group {word}\n" * 3 + f"block create brick 2 3 0 1 0 1 group {later}\n"
            deck = parse_deck(text, "g.dat")
            assert all(raw.key is None for raw in deck.lines)
            binder = Binder(deck, BindContext())
            assert [binder.bind_line(raw).args["group"] for raw in deck.lines] == [word] * 3 + [later]
    text = "block create brick 0 1 0 1 0 1 group g\n" * 3 + "block create brick 2 3 0 1 0 1 group g\n"
    assert parse_deck(text, "g.dat").lines[-1].key is not None      # no digit in its words: found by its key
