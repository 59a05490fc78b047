"""Inline FISH expressions `[ ... ]`: parse to a small tree, evaluate with dec3d's own walker.

The tree is made of tuples; evaluation looks names up in a variables mapping and
calls only the intrinsics listed in `INTRINSICS`. Python's eval is never used, so
`[__import__('os').system('x')]` is a syntax error and `[__import__('os')]` an
unknown function.

FISH semantics kept (Itasca FISH reference): names are case-insensitive; integer
literals stay integers and integer division truncates toward zero (`[7/2]` is 3);
`#` and `!=` mean "not equal"; `^` is power.
"""
from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Mapping

from lark import Lark, Token, Transformer
from lark.exceptions import UnexpectedInput

from ..errors import DeckSyntaxError, ExpressionError, NotSupportedError

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
    """Parse the inside of `[ ... ]`. Raises DeckSyntaxError with a 1-based column."""
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


# ---------------------------------------------------------------- intrinsics

def _io_out(ctx, *args):
    ctx.write(" ".join(_to_string(a) for a in args))
    return 0


def _to_string(v) -> str:
    """FISH string(): integers without a decimal point, floats in %g-like form."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if v != int(v) or abs(v) >= 1e16 else f"{v:.1f}"
    return str(v)


def _string_build(ctx, fmt, *args):
    """string.build("a %1 b %2", x, y): %n replaced by the n-th argument as a string."""
    if not isinstance(fmt, str):
        raise ExpressionError("string.build: the first argument must be a string")
    out = fmt
    for k in range(len(args), 0, -1):  # %10 before %1
        out = out.replace(f"%{k}", _to_string(args[k - 1]))
    return out


def _num(f: Callable) -> Callable:
    def wrapped(ctx, *args):
        for a in args:
            if isinstance(a, (str, bool)):
                raise ExpressionError(f"expected a number, got {a!r}")
        return f(*args)
    return wrapped


#: name -> (function(ctx, *args), min args, max args); max None = any
INTRINSICS: dict[str, tuple[Callable, int, int | None]] = {
    "math.sqrt": (_num(math.sqrt), 1, 1),
    "math.sin": (_num(math.sin), 1, 1),
    "math.cos": (_num(math.cos), 1, 1),
    "math.tan": (_num(math.tan), 1, 1),
    "math.asin": (_num(math.asin), 1, 1),
    "math.acos": (_num(math.acos), 1, 1),
    "math.atan": (_num(math.atan), 1, 1),
    "math.atan2": (_num(math.atan2), 2, 2),
    "math.abs": (_num(abs), 1, 1),
    "math.exp": (_num(math.exp), 1, 1),
    "math.log": (_num(math.log), 1, 1),
    "math.ln": (_num(math.log), 1, 1),
    "math.log10": (_num(math.log10), 1, 1),
    "math.min": (_num(min), 1, None),
    "math.max": (_num(max), 1, None),
    "math.floor": (_num(math.floor), 1, 1),
    "math.ceiling": (_num(math.ceil), 1, 1),
    "math.round": (_num(round), 1, 1),
    "math.sgn": (_num(lambda x: (x > 0) - (x < 0)), 1, 1),
    "string": (lambda ctx, v: _to_string(v), 1, 1),
    "string.build": (_string_build, 1, None),
    "io.out": (_io_out, 1, None),
    "float": (_num(float), 1, 1),
    "int": (_num(int), 1, 1),
}

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


class EvalContext:
    """What an expression may touch: a variables mapping and an output function."""

    def __init__(self, variables: dict[str, Any], write: Callable[[str], None] = print):
        self.variables = variables
        self.write = write


#: FISH integers are 64-bit signed (Itasca FISH reference, "Data Types")
INT_MIN, INT_MAX = -(2**63), 2**63 - 1
#: longest string an expression may make (characters)
MAX_STRING = 1_000_000


def _checked(v):
    """A value an expression made, refused when it is not finite, wider than 64 bits or too long."""
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ExpressionError(f"numeric overflow: the result is {v!r}, not a finite number")
    elif isinstance(v, int) and not isinstance(v, bool):
        if not INT_MIN <= v <= INT_MAX:
            raise ExpressionError("integer overflow: the result is beyond the 64-bit range of FISH integers "
                                  "(±9.2e18)", hint="write a real number (e.g. 2.0 instead of 2) to compute in reals")
    elif isinstance(v, str) and len(v) > MAX_STRING:
        raise ExpressionError(f"string too long: {len(v):,} characters (at most {MAX_STRING:,})")
    return v


def evaluate(node: Node, ctx: EvalContext) -> Any:
    """Evaluate a parsed statement or expression. Assignment stores and returns the value.

    The walk keeps its own stack of pending nodes and values, so a tree of any depth (a
    generated 10 000-term sum) evaluates without Python recursion. Every intermediate result
    is checked (`_checked`): finite reals, 64-bit integers, strings of at most MAX_STRING.
    """
    vals: list[Any] = []
    todo: list[tuple[Node, int]] = [(node, 0)]
    while todo:
        n, step = todo.pop()
        tag = n[0]
        if tag == "const":
            vals.append(_checked(n[1]))
        elif tag == "name":
            name = n[1]
            if name in ctx.variables:
                vals.append(ctx.variables[name])
            elif name in CONSTANTS:
                vals.append(CONSTANTS[name])
            else:
                raise ExpressionError(f"undefined FISH variable `{name}`")
        elif tag in ("bin", "cmp"):
            if step == 0:
                todo += [(n, 1), (n[3], 0), (n[2], 0)]     # left, then right, then the operator
            else:
                b = vals.pop()
                a = vals.pop()
                vals.append(_checked(_binary(n[1], a, b)) if tag == "bin" else _compare(n[1], a, b))
        elif tag in ("neg", "not"):
            if step == 0:
                todo += [(n, 1), (n[1], 0)]
            else:
                v = vals.pop()
                if tag == "not":
                    vals.append(not bool(v))
                elif isinstance(v, (str, bool)):
                    raise ExpressionError(f"cannot negate {v!r}")
                else:
                    vals.append(_checked(-v))
        elif tag in ("and", "or"):
            if step == 0:
                todo += [(n, 1), (n[1], 0)]
            elif step == 1:
                a = bool(vals.pop())
                if a == (tag == "or"):         # decided by the left side: the right is not evaluated
                    vals.append(a)
                else:
                    todo += [(n, 2), (n[2], 0)]
            else:
                vals.append(bool(vals.pop()))
        elif tag == "call":
            name = n[1]
            if step == 0:
                if name not in INTRINSICS:
                    raise NotSupportedError(f"FISH function `{name}` is not supported yet")
                todo.append((n, 1))
                todo += [(a, 0) for a in reversed(n[2])]
            else:
                fn, lo, hi = INTRINSICS[name]
                k = len(n[2])
                args = vals[len(vals) - k:] if k else []
                del vals[len(vals) - k:]
                if len(args) < lo or (hi is not None and len(args) > hi):
                    want = str(lo) if lo == hi else f"{lo}..{hi if hi is not None else 'n'}"
                    raise ExpressionError(f"`{name}` takes {want} argument(s), got {len(args)}")
                try:
                    vals.append(_checked(fn(ctx, *args)))
                except (ValueError, OverflowError, TypeError) as exc:
                    raise ExpressionError(f"`{name}`: {exc}") from None
        elif tag == "assign":
            _, name, op, rhs, _col = n
            if step == 0:
                todo += [(n, 1), (rhs, 0)]
            else:
                value = vals.pop()
                if op != "=":
                    if name not in ctx.variables:
                        raise ExpressionError(f"undefined FISH variable `{name}`")
                    value = _checked(_binary(op[0], ctx.variables[name], value))
                ctx.variables[name] = value
                vals.append(value)
        else:  # pragma: no cover - the grammar makes no other tags
            raise ExpressionError(f"cannot evaluate {tag}")
    return vals[0]


def _binary(op: str, a, b):
    if op == "+" and isinstance(a, str) and isinstance(b, str):
        return a + b
    for v in (a, b):
        if isinstance(v, (str, bool)):
            raise ExpressionError(f"operator {op} needs numbers, got {v!r}")
    try:
        if op == "+":
            return a + b
        if op == "-":
            return a - b
        if op == "*":
            return a * b
        if op == "/":
            if isinstance(a, int) and isinstance(b, int):
                q = abs(a) // abs(b)          # FISH integer division truncates toward zero
                return q if (a >= 0) == (b >= 0) else -q
            return a / b
        if op == "^":
            if isinstance(a, int) and isinstance(b, int) and b >= 0:
                if abs(a) > 1 and b * math.log2(abs(a)) > 64:     # refused before the digits are made
                    raise ExpressionError(f"integer overflow: {a}^{b} is beyond the 64-bit range of FISH "
                                          "integers (±9.2e18)",
                                          hint="write a real number (e.g. 2.0 instead of 2) to compute in reals")
                return a ** b
            r = float(a) ** float(b)
            if isinstance(r, complex):
                raise ExpressionError(f"{a}^{b} is not a real number")
            return r
    except ZeroDivisionError:
        raise ExpressionError("division by zero") from None
    except OverflowError:
        raise ExpressionError(f"numeric overflow: {_to_string(a)} {op} {_to_string(b)} is too large") from None
    raise ExpressionError(f"unknown operator {op}")  # pragma: no cover


def _compare(op: str, a, b) -> bool:
    if isinstance(a, str) != isinstance(b, str):
        if op in ("==", "!="):
            return op == "!="
        raise ExpressionError(f"cannot compare {a!r} and {b!r}")
    if op == "==":
        return a == b
    if op == "!=":
        return a != b
    if op == "<":
        return a < b
    if op == ">":
        return a > b
    if op == "<=":
        return a <= b
    return a >= b
