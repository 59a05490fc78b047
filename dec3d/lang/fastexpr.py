"""Inline expressions `[ ... ]` by recursive descent: the tree lark's LALR parser of expr.lark makes
(``expr._Tree``), in about a tenth of the time (a generated deck with an expression on every fifth
line spent a third of its reading time in lark's parser).

``parse_fast(text)`` returns the tree, or None for anything it does not take: a syntax error, or
nesting deeper than Python's recursion allows. ``expr.parse_expression`` then asks lark, which
reports the error with its column, so messages do not change. tests/lang/test_fast_expressions.py
compares the two parsers on generated expressions and on token soup.

The grammar, lowest precedence first (expr.lark): statement = NAME ASSIGN_OP or_test | or_test;
or_test = and_test ("or" and_test)*; and_test = not_test ("and" not_test)*; not_test = "not" not_test
| comparison; comparison = sum [COMPOP sum]; sum = product (ADDOP product)*; product = unary (MULOP
unary)*; unary = ADDOP unary | power; power = atom ["^" unary]; atom = NUMBER | STRING | true | false
| NAME | NAME "(" [or_test ("," or_test)*] ")" | "(" or_test ")". Keywords are case-insensitive and
only whole names (`order` is a name).
"""
from __future__ import annotations

import re

_TOKEN = re.compile(r"""
    (?P<ws>[ \t\f]+)
  | (?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
  | (?P<str>'[^']*'|"[^"]*")
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)
  | (?P<op>\+=|-=|\*=|/=|==|!=|<=|>=|[=#<>+\-*/^(),])
""", re.X)
_KEYWORDS = {"or": "or", "and": "and", "not": "not", "true": "true", "false": "false"}
_ASSIGN = frozenset(("=", "+=", "-=", "*=", "/="))
_COMPARE = frozenset(("==", "!=", "#", "<=", ">=", "<", ">"))


class _Fail(Exception):
    pass


# the same tokens, each a tuple of groups (the blanks before it, then one of num, str, name, op) made by
# ``findall`` (nothing but `ws` can start with a blank, so this is the same cut)
_TOKEN_GROUPS = re.compile(r"([ \t\f]*)(?:" + re.sub(r"\(\?P<\w+>", "(", _TOKEN.pattern.split("|", 1)[1]) + ")", re.X)
assert _TOKEN_GROUPS.groups == 5


class _Parser:
    __slots__ = ("toks", "i")

    def __init__(self, toks):
        self.toks = toks
        self.i = 0

    def kind(self) -> str:
        return self.toks[self.i][0]

    def take(self):
        t = self.toks[self.i]
        self.i += 1
        return t

    def statement(self):
        if self.kind() == "name" and self.toks[self.i + 1][0] in _ASSIGN:
            name = self.take()
            op = self.take()
            return ("assign", name[1].lower(), op[1], self.or_test(), name[2])
        return self.or_test()

    def or_test(self):
        left = self.and_test()
        while self.kind() == "or":
            self.i += 1
            left = ("or", left, self.and_test())
        return left

    def and_test(self):
        left = self.not_test()
        while self.kind() == "and":
            self.i += 1
            left = ("and", left, self.not_test())
        return left

    def not_test(self):
        if self.kind() == "not":
            self.i += 1
            return ("not", self.not_test())
        left = self.sum()
        if self.kind() in _COMPARE:
            op = self.take()[1]
            left = ("cmp", "!=" if op == "#" else op, left, self.sum())
        return left

    def sum(self):
        left = self.product()
        while self.kind() in ("+", "-"):
            op = self.take()[1]
            left = ("bin", op, left, self.product())
        return left

    def product(self):
        left = self.unary()
        while self.kind() in ("*", "/"):
            op = self.take()[1]
            left = ("bin", op, left, self.unary())
        return left

    def unary(self):
        k = self.kind()
        if k == "+" or k == "-":
            self.i += 1
            operand = self.unary()
            return ("neg", operand) if k == "-" else operand
        base = self.atom()
        if self.kind() == "^":
            self.i += 1
            return ("bin", "^", base, self.unary())
        return base

    def atom(self):
        kind, value, col = self.take()
        if kind == "num":
            return ("const", float(value)) if any(ch in value for ch in ".eE") else ("const", int(value))
        if kind == "str":
            return ("const", value[1:-1])
        if kind == "true":
            return ("const", True)
        if kind == "false":
            return ("const", False)
        if kind == "name":
            if self.kind() != "(":
                return ("name", value.lower(), col)
            self.i += 1
            args = []
            if self.kind() != ")":
                args.append(self.or_test())
                while self.kind() == ",":
                    self.i += 1
                    args.append(self.or_test())
            if self.take()[0] != ")":
                raise _Fail
            return ("call", value.lower(), tuple(args), col)
        if kind == "(":
            inner = self.or_test()
            if self.take()[0] != ")":
                raise _Fail
            return inner
        raise _Fail


#: token shape (kinds, words, operators, numbers by int or float; no columns) -> a tree parsed from
#: it: the parse depends on nothing else, so a later expression of the shape takes its numbers and
#: columns into the tree (``_refill``) instead of being parsed (a deck's `[x = 0.53 * 2.5 + ...]`
#: lines differ in their numbers only)
_SHAPES: dict = {}
_NUMERIC = (int, float)


def _const(value: str):
    return float(value) if "." in value or "e" in value or "E" in value else int(value)


def _refill(node, nums, cols):
    """``node`` with its numbers (constants that are int or float, in the text's order) and its
    columns (of names, calls, assignments) taken from the iterators ``nums`` and ``cols``."""
    tag = node[0]
    if tag == "const":
        return ("const", next(nums)) if type(node[1]) in _NUMERIC else node
    if tag == "name":
        return ("name", node[1], next(cols))
    if tag == "bin" or tag == "cmp":
        return (tag, node[1], _refill(node[2], nums, cols), _refill(node[3], nums, cols))
    if tag == "neg" or tag == "not":
        return (tag, _refill(node[1], nums, cols))
    if tag == "and" or tag == "or":
        return (tag, _refill(node[1], nums, cols), _refill(node[2], nums, cols))
    if tag == "call":
        col = next(cols)
        return ("call", node[1], tuple(_refill(a, nums, cols) for a in node[2]), col)
    if tag == "assign":
        col = next(cols)
        return ("assign", node[1], node[2], _refill(node[3], nums, cols), col)
    raise AssertionError(tag)


def _shaped_tokens(text: str):
    """(kind, text, column) tokens — kind is num, str, name, a keyword, or the operator itself — and,
    made in the same pass, the token shape (``_SHAPES``' key: each token's text, a number as whether it
    is written as a float), the numbers' texts and the names' columns."""
    toks, key, nums, cols = [], [], [], []
    add, shape = toks.append, key.append
    pos = 0
    keywords = _KEYWORDS
    for ws, num, st, name, op in _TOKEN_GROUPS.findall(text):
        if ws:
            pos += len(ws)
        if num:
            add(("num", num, pos + 1))
            shape("\0f" if "." in num or "e" in num or "E" in num else "\0i")   # no token's text starts so
            nums.append(num)
            pos += len(num)
        elif name:
            kind = keywords.get(name.lower(), "name")
            add((kind, name, pos + 1))
            shape(name)
            if kind == "name":
                cols.append(pos + 1)
            pos += len(name)
        elif op:
            add((op, op, pos + 1))
            shape(op)
            pos += len(op)
        else:
            add(("str", st, pos + 1))
            shape(st)
            pos += len(st)
    # findall skips text no token takes: then the tokens' lengths do not add up to the text's (the
    # rest from ``pos`` holds the text of a later token, or the text skipped at the end)
    if pos != len(text) and text[pos:].strip(" \t\f"):
        raise _Fail
    add(("end", "", len(text) + 1))
    return toks, tuple(key), nums, cols


def parse_fast(text: str):
    """The expression tree of ``text``, or None when it is not one (or nests too deep for this parser)."""
    try:
        toks, key, nums, cols = _shaped_tokens(text)
    except _Fail:
        return None
    tree = _SHAPES.get(key)
    if tree is not None:
        return _refill(tree, iter([_const(v) for v in nums]), iter(cols))
    try:
        p = _Parser(toks)
        tree = p.statement()
        if p.kind() != "end":
            return None
    except (_Fail, IndexError, RecursionError):
        return None
    if len(_SHAPES) >= 4096:
        _SHAPES.clear()
    _SHAPES[key] = tree
    return tree
