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


# the same tokens, the blanks before each matched with it (half the matches; nothing but `ws` can
# start with a blank, so this is the same cut)
_TOKEN_AFTER_BLANKS = re.compile(r"[ \t\f]*(?:" + _TOKEN.pattern.split("|", 1)[1] + ")", re.X)


def _tokens(text: str):
    """(kind, text, column) tokens; kind is num, str, name, a keyword, or the operator itself."""
    out = []
    pos, n = 0, len(text)
    for m in _TOKEN_AFTER_BLANKS.finditer(text):
        if m.start() != pos:
            raise _Fail
        kind = m.lastgroup
        value = m.group(kind)
        pos = m.end()
        if kind == "name":
            kind = _KEYWORDS.get(value.lower(), "name")
        elif kind == "op":
            kind = value
        out.append((kind, value, pos - len(value) + 1))
    if pos != n and text[pos:].strip(" \t\f"):
        raise _Fail
    out.append(("end", "", n + 1))
    return out


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


def parse_fast(text: str):
    """The expression tree of ``text``, or None when it is not one (or nests too deep for this parser)."""
    try:
        p = _Parser(_tokens(text))
        tree = p.statement()
        if p.kind() != "end":
            return None
        return tree
    except (_Fail, IndexError, RecursionError):
        return None
