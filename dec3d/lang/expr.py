"""Inline FISH expressions `[ ... ]` at bind time: parse to a small tree of tuples and check its
names (`check_names`), so an undefined variable stops the deck before anything runs.

Values are computed when the command runs, by dec3d.fish (one evaluator for inline expressions,
`@name` and FISH functions). Python's eval is never used: `[__import__('os').system('x')]` is a
syntax error and `[__import__('os')]` an unknown function.
"""
from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable

from lark import Lark, Transformer
from lark.exceptions import UnexpectedInput

from ..errors import DeckSyntaxError
from .fastexpr import parse_fast

Node = tuple


class _Tree(Transformer):
    __visit_tokens__ = False
    def assign(self, c):
        return ("assign", c[0].lower(), str(c[1]), c[2], c[0].column)

    def or_(self, c):
        return ("or", c[0], c[1])

    def and_(self, c):
        return ("and", c[0], c[1])

    def not_(self, c):
        return ("not", c[0])

    def compare(self, c):
        op = str(c[1])
        return ("cmp", "!=" if op == "#" else op, c[0], c[2])

    def binop(self, c):
        return ("bin", str(c[1]), c[0], c[2])

    def sign(self, c):
        return ("neg", c[1]) if str(c[0]) == "-" else c[1]

    def pow(self, c):
        return ("bin", "^", c[0], c[1])

    def number(self, c):
        s = str(c[0])
        if any(ch in s for ch in ".eE"):
            return ("const", float(s))
        return ("const", int(s))

    def string(self, c):
        return ("const", str(c[0])[1:-1])

    def true(self, c):
        return ("const", True)

    def false(self, c):
        return ("const", False)

    def name(self, c):
        return ("name", str(c[0]).lower(), c[0].column)

    def call(self, c):
        args = tuple(a for a in c[1:] if a is not None)
        return ("call", str(c[0]).lower(), args, c[0].column)


@lru_cache(maxsize=None)
def _parser() -> Lark:
    return Lark.open(str(Path(__file__).parent / "expr.lark"), parser="lalr", lexer="basic",
                     transformer=_Tree(), maybe_placeholders=True)


@lru_cache(maxsize=4096)
def parse_expression(text: str) -> Node:
    """Parse the inside of `[ ... ]`. Raises DeckSyntaxError with a 1-based column. The recursive
    descent of ``fastexpr`` first; lark's parser for what it does not take (and for the message)."""
    tree = parse_fast(text)
    if tree is not None:
        return tree
    try:
        return _parser().parse(text)
    except UnexpectedInput as exc:
        col = getattr(exc, "column", 1) or 1
        tok = getattr(exc, "token", None)
        if tok is not None and tok.type == "$END":
            msg = "inline expression ends too early"
        elif tok is not None:
            msg = f"unexpected {str(tok)!r} in inline expression"
        else:
            ch = text[col - 1] if 0 < col <= len(text) else ""
            msg = f"unexpected character {ch!r} in inline expression"
        err = DeckSyntaxError(msg, hint="FISH expressions use numbers, names, + - * / ^, comparisons, "
                              "and/or/not, function calls f(a, b) and assignment a = ...")
        err.column_in_expr = col
        raise err from None


# ---------------------------------------------------------------- names the binder accepts

#: intrinsics callable in `[ ]` without being a FISH function of the deck (the binder also accepts
#: every intrinsic dec3d.fish implements; values are computed by dec3d.fish when the command runs)
INTRINSICS: frozenset[str] = frozenset({
    "math.sqrt", "math.sin", "math.cos", "math.tan", "math.asin", "math.acos", "math.atan", "math.atan2",
    "math.abs", "math.exp", "math.log", "math.ln", "math.log10", "math.min", "math.max", "math.floor",
    "math.ceiling", "math.round", "math.sgn", "string", "string.build", "io.out", "float", "int",
})

#: constants: FISH names without parentheses
CONSTANTS: dict[str, Any] = {
    "math.pi": math.pi,
    "math.e": math.e,
    "math.degrad": math.pi / 180.0,
}

# dotted prefixes of FISH intrinsics dec3d knows exist in 3DEC but does not implement yet
_KNOWN_NAMESPACES = ("block.", "mech.", "dynamic.", "global.", "time.", "table.", "system.", "fish.",
                     "domain.", "model.", "history.", "string.", "math.", "io.", "file.", "list.",
                     "vector.", "matrix.", "geom.", "dfn.", "struct.", "thermal.", "fluid.", "type",
                     "array.", "memory.", "version.", "flowknot.", "flowplane.", "feblock.")


def check_names(node: Node, known: Callable[[str], str | None]) -> list[tuple[str, str, int]]:
    """Walk a tree and list (kind, name, column) of names `known` does not accept.

    `known(name)` returns None when the name is fine, else a kind: "undefined",
    "fish-function", "fish-variable", "intrinsic" (not supported), "unknown-function".
    The walk keeps its own stack (a 10 000-term sum is a tree that deep).
    """
    problems: list[tuple[str, str, int]] = []
    stack = [node]
    while stack:
        n = stack.pop()
        tag = n[0]
        if tag == "const":
            continue
        if tag == "name":
            if n[1] in CONSTANTS:
                continue
            if "." in n[1] and n[1].startswith(_KNOWN_NAMESPACES):
                problems.append(("intrinsic", n[1], n[2]))
                continue
            k = known(n[1])
            if k:
                problems.append((k, n[1], n[2]))
            continue
        if tag == "call":
            name = n[1]
            if name not in INTRINSICS:
                k = known(name)
                if k is None or k == "undefined":
                    k = "intrinsic" if name.startswith(_KNOWN_NAMESPACES) else "unknown-function"
                problems.append((k, name, n[3]))
            stack.extend(reversed(n[2]))
            continue
        if tag == "assign":
            stack.append(n[3])
            continue
        stack.extend(reversed([c for c in n[1:] if isinstance(c, tuple)]))
    return problems
