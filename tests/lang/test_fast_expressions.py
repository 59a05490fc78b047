"""The recursive-descent expression parser (lang/fastexpr.py) against its reference, lark's parser of
expr.lark (``expr._parser``): the same tree for every expression it takes, and None for every text lark
refuses, on expressions generated from the grammar and on token soup."""
import numpy as np
import pytest
from lark.exceptions import UnexpectedInput

from dec3d.errors import DeckSyntaxError
from dec3d.lang.expr import _parser, parse_expression
from dec3d.lang.fastexpr import parse_fast

NAMES = ["x", "Abc", "math.pi", "block.pos.z", "order", "ORx", "nota", "android", "true_1", "falsey", "_a9"]
NUMBERS = ["0", "12", "3.5", ".25", "1e3", "2.E-4", "1.", "007"]


def _gen(rng, depth=0):
    """A random expression from the grammar (a few keywords in odd cases)."""
    r = rng.random()
    if depth > 4 or r < 0.3:
        leaf = rng.integers(0, 5)
        return (str(rng.choice(NAMES)) if leaf == 0 else str(rng.choice(NUMBERS)) if leaf == 1
                else "'s t'" if leaf == 2 else str(rng.choice(["true", "FALSE", "True"])) if leaf == 3
                else f"{rng.choice(NAMES)}({', '.join(_gen(rng, depth + 1) for _ in range(rng.integers(0, 3)))})")
    a, b = _gen(rng, depth + 1), _gen(rng, depth + 1)
    form = rng.integers(0, 9)
    return [f"{a} {rng.choice(['or', 'OR', 'And', 'and'])} {b}", f"not {a}", f"{a} {rng.choice(['==', '#', '!=', '<=', '>', '<', '>='])} {b}",
            f"{a}{rng.choice(['+', '-'])}{b}", f"{a} {rng.choice(['*', '/'])} {b}", f"-{a}", f"+ {a}",
            f"{a}^{b}", f"({a})"][form]


def _lark(text):
    try:
        return _parser().parse(text)
    except UnexpectedInput:
        return None


def test_same_tree_as_lark_on_generated_expressions():
    """Generated without regard to precedence, so some (chained comparisons, `not` inside a sum) are
    refused: by both parsers."""
    rng = np.random.default_rng(4)
    took = 0
    for _ in range(3000):
        text = _gen(rng)
        if rng.random() < 0.2:
            text = f"{rng.choice(NAMES)} {rng.choice(['=', '+=', '-=', '*=', '/='])} {text}"
        want = _lark(text)
        assert parse_fast(text) == want, text
        took += want is not None
    assert took > 1500


SOUP = ["a", "b1", "or", "and", "not", "true", "(", ")", ",", "+", "-", "*", "/", "^", "=", "==", "#", "<", ">=",
        "1", "2.5", "'q'", "f(", "!", "@", "..", " ", "+=", "x.y"]


def test_none_exactly_where_lark_refuses_on_token_soup():
    rng = np.random.default_rng(9)
    took = refused = 0
    for _ in range(6000):
        text = "".join(rng.choice(SOUP, size=int(rng.integers(1, 9))))
        want, got = _lark(text), parse_fast(text)
        assert got == want, text
        took += want is not None
        refused += want is None
    assert took > 200 and refused > 3000         # both branches met


def test_deep_nesting_is_left_to_lark_and_errors_keep_their_columns():
    deep = "(" * 5000 + "1" + ")" * 5000
    assert parse_fast(deep) is None and parse_expression(deep) == ("const", 1)
    with pytest.raises(DeckSyntaxError) as e:
        parse_expression("1 + * 2")
    assert e.value.column_in_expr == 5 and "unexpected '*'" in e.value.message


def test_expressions_of_one_shape_with_other_numbers_give_lark_s_tree():
    """``parse_fast`` parses a token shape once and fills later expressions of that shape with their own
    numbers and columns (``fastexpr._refill``): the trees are lark's, numbers of every width and kind."""
    from dec3d.lang import fastexpr

    rng = np.random.default_rng(11)
    hits = 0
    for _ in range(600):
        form = _gen(rng)
        for n in NUMBERS:                       # every number a slot (longest first: `12` holds `1`... no)
            form = form.replace(n, "{}") if n in ("3.5", "2.E-4", "1e3") else form
        slots = form.count("{}")
        for k in range(3):
            nums = [str(rng.choice(["7", "1234567", "0.5", "12.25e-3", ".5", "3.", "9" * 30, "2E5", "0"]))
                    for _ in range(slots)]
            text = form.format(*nums)
            before = len(fastexpr._SHAPES)
            got = parse_fast(text)
            assert got == _lark(text), text
            hits += k > 0 and got is not None and len(fastexpr._SHAPES) == before
    assert hits > 100, hits
