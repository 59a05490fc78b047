"""FISH source -> syntax tree (hand-written lexer and Pratt parser; nothing executes here).

FISH is line-oriented (Itasca, "FISH scripting > Lines"): every line is one statement;
`...` at the end of a line continues it on the next; `;` starts a comment; names are
case-insensitive and never abbreviated (dotted intrinsic names may be, see
`intrinsics.resolve`). A line is a statement (`if`, `loop`, `local`, ...), an
assignment, an expression (usually a call), or one or more function names separated
by spaces.

Trees are tuples whose first item is a tag and whose last item is the position
`(line, column)` in the deck file (both from 1), so errors can point inside the body.

Expression precedence, lowest first (as in dec3d's inline expressions, lang/expr.lark):
`|`/`or`, `&`/`and`, `not`/`!`, comparisons (`=` `==` `#` `!=` `<` `>` `<=` `>=`),
`+ -`, `* /`, unary minus, `^` (right-associative: `-2^2` is -4, `2^3^2` is 512),
then postfix `f(args)` and `v->x`. `::expr` as a call argument maps the call over a list.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import DeckSyntaxError
from .lexer import FishSource, Tok, logical_lines


ASSIGN_OPS = ("=", "+=", "-=", "*=", "/=", "^=")
COMPARE = {"=": "==", "==": "==", "#": "!=", "!=": "!=", "<>": "!=", "<": "<", ">": ">", "<=": "<=", ">=": ">="}
_BINARY_BP = {"|": 10, "or": 10, "&": 20, "and": 20,
              "=": 40, "==": 40, "#": 40, "!=": 40, "<>": 40, "<": 40, ">": 40, "<=": 40, ">=": 40,
              "+": 50, "-": 50, "*": 60, "/": 60, "^": 80}
_UNARY_MINUS_BP = 70
_NOT_BP = 30
_POSTFIX_BP = 90

#: words that end a block; a line starting with one is never an assignment or call
END_WORDS = {"endif": "endif", "end_if": "endif", "endloop": "endloop", "end_loop": "endloop",
             "endcase": "endcase", "end_case": "endcase", "endsection": "endsection",
             "end_section": "endsection", "endcommand": "endcommand", "end_command": "endcommand"}
KEYWORDS = {"if", "then", "else", "loop", "while", "foreach", "for", "exit", "continue", "case_of", "caseof",
            "case", "section", "command", "local", "global", "and", "or", "not"} | set(END_WORDS)


# ---------------------------------------------------------------- expressions

class _Expr:
    """Pratt parser over the tokens of one logical line (or a slice of it)."""

    def __init__(self, src: FishSource, toks: list[Tok], end_pos):
        self.src = src
        self.toks = toks
        self.i = 0
        self.end_pos = end_pos

    def peek(self) -> Tok | None:
        return self.toks[self.i] if self.i < len(self.toks) else None

    def next(self) -> Tok:
        t = self.peek()
        if t is None:
            raise self.src.error("the line ends too early", self.end_pos)
        self.i += 1
        return t

    def expect_op(self, op: str) -> Tok:
        t = self.peek()
        if t is None or not t.is_op(op):
            where = (t.line, t.col) if t else self.end_pos
            got = f"`{t.text}`" if t else "the end of the line"
            raise self.src.error(f"expected `{op}`, got {got}", where)
        self.i += 1
        return t

    def expr(self, min_bp: int = 0):
        t = self.next()
        pos = (t.line, t.col)
        if t.kind == "num" or t.kind == "str":
            left = ("const", t.value, pos)
        elif t.kind == "name":
            if t.value in ("true", "false"):
                left = ("const", t.value == "true", pos)
            elif t.value == "not":
                left = ("not", self.expr(_NOT_BP), pos)
            elif t.value in KEYWORDS:
                raise self.src.error(f"`{t.text}` cannot start an expression", pos, len(t.text))
            else:
                left = ("name", t.value, pos)
        elif t.is_op("("):
            left = self.expr(0)
            self.expect_op(")")
        elif t.is_op("-"):
            left = ("neg", self.expr(_UNARY_MINUS_BP), pos)
        elif t.is_op("+"):
            left = self.expr(_UNARY_MINUS_BP)
        elif t.is_op("!"):
            left = ("not", self.expr(_NOT_BP), pos)
        elif t.is_op("::"):
            raise self.src.error("`::` maps a call over a list; it is written before a call argument", pos, 2)
        else:
            raise self.src.error(f"unexpected `{t.text}` in FISH expression", pos, len(t.text))
        while True:
            t = self.peek()
            if t is None:
                return left
            if t.is_op("(") and _POSTFIX_BP >= min_bp:
                if left[0] != "name":
                    raise self.src.error("only a name can be called or indexed", (t.line, t.col))
                self.i += 1
                args = self.arguments()
                left = ("call", left[1], tuple(args), left[2])
                continue
            if t.is_op("->") and _POSTFIX_BP >= min_bp:
                self.i += 1
                m = self.next()
                if m.kind != "name":
                    raise self.src.error("`->` is followed by a component name (x, y, z)", (m.line, m.col))
                left = ("member", left, m.value, (m.line, m.col))
                continue
            op = t.value if t.kind == "op" else (t.value if t.is_word("and", "or") else None)
            bp = _BINARY_BP.get(op) if op is not None else None
            if bp is None or bp <= min_bp:
                return left
            self.i += 1
            pos = (t.line, t.col)
            if op == "^":
                right = self.expr(bp - 1)          # right-associative
                left = ("bin", "^", left, right, pos)
            elif op in ("|", "or"):
                left = ("or", left, self.expr(bp), pos)
            elif op in ("&", "and"):
                left = ("and", left, self.expr(bp), pos)
            elif op in COMPARE:
                left = ("cmp", COMPARE[op], left, self.expr(bp), pos)
            else:
                left = ("bin", op, left, self.expr(bp), pos)

    def arguments(self) -> list:
        args = []
        t = self.peek()
        if t is not None and t.is_op(")"):
            self.i += 1
            return args
        while True:
            t = self.peek()
            if t is not None and t.is_op("::"):
                self.i += 1
                args.append(("map", self.expr(0), (t.line, t.col)))
            else:
                args.append(self.expr(0))
            t = self.next()
            if t.is_op(")"):
                return args
            if not t.is_op(","):
                raise self.src.error(f"expected `,` or `)` in the argument list, got `{t.text}`", (t.line, t.col))


def _end_pos(toks: list[Tok]):
    last = toks[-1]
    return (last.line, last.col + len(last.text))


def parse_expression_tokens(src: FishSource, toks: list[Tok]):
    p = _Expr(src, toks, _end_pos(toks))
    node = p.expr(0)
    if p.i < len(toks):
        t = toks[p.i]
        raise src.error(f"unexpected `{t.text}` after the expression", (t.line, t.col), len(t.text))
    return node


def _split_commas(src, toks: list[Tok]) -> list[list[Tok]]:
    parts, cur, depth = [], [], 0
    for t in toks:
        if t.is_op("("):
            depth += 1
        elif t.is_op(")"):
            depth -= 1
        if depth == 0 and t.is_op(","):
            parts.append(cur)
            cur = []
            continue
        cur.append(t)
    parts.append(cur)
    return parts


# ---------------------------------------------------------------- statements

@dataclass
class FishDef:
    """A parsed `fish define`: name, parameters, statement tree, where it came from."""

    name: str
    params: tuple[str, ...]
    body: list
    source: FishSource
    pos: tuple[int, int]
    locals: set            # names declared local anywhere (plus loop `local` variables)
    globals: set           # names declared global
    assigned: set          # names assigned (targets), lower case
    commands: list         # ("command", lines, pos) nodes, in order


class _Statements:
    def __init__(self, src: FishSource, lines: list[list[Tok]], fname: str):
        self.src = src
        self.lines = lines
        self.k = 0
        self.fname = fname
        self.locals: set = set()
        self.globals: set = set()
        self.assigned: set = set()
        self.commands: list = []

    def block(self, enders: tuple[str, ...], opener=None):
        """Statements up to a line starting with one of `enders` (normalised words); returns (body, ender line)."""
        body = []
        while self.k < len(self.lines):
            toks = self.lines[self.k]
            head = toks[0]
            word = head.value if head.kind == "name" else None
            norm = END_WORDS.get(word, word)
            if word == "else" and "else" in enders:
                return body, toks
            if word == "case" and "case" in enders:
                return body, toks
            if norm in enders and norm != "else" and norm != "case":
                self.k += 1
                return body, toks
            if norm in END_WORDS.values():
                raise self.src.error(f"`{head.text}` without a matching opening statement", (head.line, head.col),
                                     len(head.text))
            if word in ("else", "case"):
                raise self.src.error(f"`{head.text}` outside {'an if' if word == 'else' else 'a case_of'}",
                                     (head.line, head.col), len(head.text))
            self.k += 1
            body.append(self.statement(toks))
        if opener is not None:
            t, what, close = opener
            raise self.src.error(f"`{what}` is not closed", (t.line, t.col), len(t.text),
                                 hint=f"close it with `{close}` before `end`")
        return body, None

    def statement(self, toks: list[Tok]):
        head = toks[0]
        pos = (head.line, head.col)
        w = head.value if head.kind == "name" else None
        if w == "if":
            return self.if_(toks, pos)
        if w == "loop":
            return self.loop(toks, pos)
        if w in ("local", "global") and len(toks) > 1 and toks[1].kind == "name":
            return self.declare(w, toks[1:], pos)
        if w == "exit":
            if len(toks) == 1:
                return ("return", pos)
            if toks[1].is_word("loop") and len(toks) == 2:
                return ("break", pos)
            if toks[1].is_word("section") and len(toks) == 2:
                return ("exit_section", pos)
            raise self.src.error("`exit` is written alone, or as `exit loop` / `exit section`", pos, 4)
        if w == "continue" and len(toks) == 1:
            return ("continue", pos)
        if w in ("case_of", "caseof"):
            return self.case_of(toks, pos)
        if w == "section" and len(toks) == 1:
            body, _ = self.block(("endsection",), (head, "section", "end_section"))
            return ("section", body, pos)
        if w == "command" and len(toks) == 1:
            return self.command(pos, head)
        if w == "array" and len(toks) > 1 and toks[1].kind == "name":
            from ..errors import LegacySyntaxError
            raise LegacySyntaxError("`array` declarations are 3DEC 5 (legacy) FISH, not 3DEC 7+",
                                    self.src.location(pos, 5), "in 3DEC 7+ write `name = array.create(n)` "
                                    "or use a list: `name = list.sequence(...)`")
        # assignment?
        p = _Expr(self.src, toks, _end_pos(toks))
        target = None
        try:
            target = p.expr(_POSTFIX_BP - 1)
        except DeckSyntaxError:
            target = None
        nxt = p.peek()
        if target is not None and nxt is not None and nxt.kind == "op" and nxt.value in ASSIGN_OPS:
            if target[0] not in ("name", "call", "member"):
                raise self.src.error("only a name, an element `a(i)` or a component `v->x` can be assigned",
                                     pos, len(head.text))
            if target[0] == "name" and target[1] in KEYWORDS:
                raise self.src.error(f"`{head.text}` is a FISH keyword and cannot be assigned", pos, len(head.text))
            p.i += 1
            rest = toks[p.i:]
            if not rest:
                raise self.src.error(f"`{nxt.value}` needs a value on its right", (nxt.line, nxt.col))
            value = parse_expression_tokens(self.src, rest)
            if target[0] == "name":
                self.assigned.add(target[1])
            return ("assign", target, nxt.value, value, (nxt.line, nxt.col))
        if all(t.kind == "name" for t in toks):
            for t in toks:
                if t.value in KEYWORDS:
                    raise self.src.error(f"`{t.text}` is out of place here", (t.line, t.col), len(t.text))
            if len(toks) > 1:
                return ("calls", tuple(("name", t.value, (t.line, t.col)) for t in toks), pos)
        return ("expr", parse_expression_tokens(self.src, toks), pos)

    def declare(self, kind, toks, pos):
        items = []
        for part in _split_commas(self.src, toks):
            if not part or part[0].kind != "name":
                where = (part[0].line, part[0].col) if part else pos
                raise self.src.error(f"`{kind}` is followed by names, optionally `= value`", where)
            name = part[0].value
            if name in KEYWORDS or "." in name:
                raise self.src.error(f"`{part[0].text}` cannot be a variable name", (part[0].line, part[0].col),
                                     len(part[0].text))
            (self.locals if kind == "local" else self.globals).add(name)
            value = None
            if len(part) > 1:
                if not part[1].is_op("="):
                    raise self.src.error(f"expected `=` or `,` after `{part[0].text}`", (part[1].line, part[1].col))
                if len(part) == 2:
                    raise self.src.error("`=` needs a value on its right", (part[1].line, part[1].col))
                value = parse_expression_tokens(self.src, part[2:])
                self.assigned.add(name)
            items.append((name, value, (part[0].line, part[0].col)))
        return (kind, tuple(items), pos)

    def _cond(self, toks, start: int, what: str):
        rest = toks[start:]
        if rest and rest[-1].is_word("then"):
            rest = rest[:-1]
        if not rest:
            raise self.src.error(f"`{what}` needs a condition", (toks[0].line, toks[0].col))
        return parse_expression_tokens(self.src, rest)

    def if_(self, toks, pos):
        head = toks[0]
        branches = [(self._cond(toks, 1, "if"), None)]
        else_body = None
        while True:
            body, ender = self.block(("endif", "else"), (head, "if", "endif"))
            branches[-1] = (branches[-1][0], body)
            if ender is None:
                break
            e = ender[0]
            if e.value in ("endif", "end_if"):
                break
            # else / else if
            self.k += 1
            if len(ender) > 1 and ender[1].is_word("if"):
                if else_body is not None:
                    raise self.src.error("`else if` after `else`", (e.line, e.col), 4)
                branches.append((self._cond(ender, 2, "else if"), None))
                continue
            if len(ender) > 1:
                t = ender[1]
                raise self.src.error(f"unexpected `{t.text}` after `else`", (t.line, t.col), len(t.text))
            if else_body is not None:
                raise self.src.error("a second `else` in the same `if`", (e.line, e.col), 4)
            body, ender = self.block(("endif", "else"), (head, "if", "endif"))
            else_body = body
            if ender is not None and ender[0].value == "else":
                raise self.src.error("`else` after `else` in the same `if`", (ender[0].line, ender[0].col), 4)
            break
        return ("if", tuple(branches), else_body, pos)

    def loop(self, toks, pos):
        head = toks[0]
        if len(toks) < 2:
            raise self.src.error("`loop` needs a form: `loop i (a, b)`, `loop while c`, `loop foreach x list` "
                                 "or `loop for (init, cond, step)`", pos, 4)
        kw = toks[1]
        opener = (head, "loop", "endloop")
        if kw.is_word("while"):
            cond = self._cond(toks, 2, "loop while")
            body, _ = self.block(("endloop",), opener)
            return ("loop_while", cond, body, pos)
        if kw.is_word("foreach"):
            i = 2
            is_local = False
            if i < len(toks) and toks[i].is_word("local"):
                is_local = True
                i += 1
            if i >= len(toks) or toks[i].kind != "name":
                raise self.src.error("`loop foreach` needs a variable name and a list", pos, 4)
            var = toks[i].value
            if is_local:
                self.locals.add(var)
            self.assigned.add(var)
            if i + 1 >= len(toks):
                raise self.src.error("`loop foreach` needs a list after the variable", (toks[i].line, toks[i].col))
            seq = parse_expression_tokens(self.src, toks[i + 1:])
            body, _ = self.block(("endloop",), opener)
            return ("loop_foreach", var, seq, body, pos)
        if kw.is_word("for"):
            inner = toks[2:]
            if len(inner) < 2 or not inner[0].is_op("(") or not inner[-1].is_op(")"):
                raise self.src.error("`loop for` is written `loop for (init, condition, step)`", pos, 4)
            parts = _split_commas(self.src, inner[1:-1])
            if len(parts) != 3 or not all(parts):
                raise self.src.error("`loop for` needs three parts: (init, condition, step)", pos, 4)
            init = self.statement(parts[0])
            cond = parse_expression_tokens(self.src, parts[1])
            step = self.statement(parts[2])
            body, _ = self.block(("endloop",), opener)
            return ("loop_for", init, cond, step, body, pos)
        i = 1
        is_local = False
        if toks[i].is_word("local"):
            is_local = True
            i += 1
        if i >= len(toks) or toks[i].kind != "name" or toks[i].value in KEYWORDS:
            raise self.src.error("expected a loop variable after `loop`", pos, 4)
        var = toks[i].value
        rest = toks[i + 1:]
        if len(rest) < 2 or not rest[0].is_op("(") or not rest[-1].is_op(")"):
            raise self.src.error(f"`loop {toks[i].text}` needs its range in parentheses: (first, last[, step])",
                                 (toks[i].line, toks[i].col), len(toks[i].text))
        parts = _split_commas(self.src, rest[1:-1])
        if len(parts) not in (2, 3) or not all(parts):
            raise self.src.error("a counted loop takes (first, last) or (first, last, step)",
                                 (rest[0].line, rest[0].col))
        exprs = [parse_expression_tokens(self.src, p) for p in parts]
        if is_local:
            self.locals.add(var)
        self.assigned.add(var)
        body, _ = self.block(("endloop",), opener)
        return ("loop_range", var, exprs[0], exprs[1], exprs[2] if len(exprs) == 3 else None, body, pos)

    def case_of(self, toks, pos):
        head = toks[0]
        if len(toks) < 2:
            raise self.src.error("`case_of` needs an expression", pos, len(head.text))
        sel = parse_expression_tokens(self.src, toks[1:])
        opener = (head, "case_of", "end_case")
        pre, ender = self.block(("endcase", "case"), opener)
        if pre:
            raise self.src.error("statements between `case_of` and the first `case` never run", pos, len(head.text))
        cases = []
        while ender is not None and ender[0].value == "case":
            self.k += 1
            if len(ender) < 2:
                raise self.src.error("`case` needs a value", (ender[0].line, ender[0].col), 4)
            values = tuple(parse_expression_tokens(self.src, p) for p in _split_commas(self.src, ender[1:]))
            body, ender = self.block(("endcase", "case"), opener)
            cases.append((values, body, (ender[0].line, ender[0].col) if ender else pos))
        return ("case_of", sel, tuple(cases), pos)

    def command(self, pos, head):
        """Raw command lines up to `endcommand` (taken from the source text, continuation kept)."""
        lines = []
        while self.k < len(self.lines):
            toks = self.lines[self.k]
            self.k += 1
            if toks[0].kind == "name" and END_WORDS.get(toks[0].value) == "endcommand":
                node = ("command", tuple(lines), pos)
                self.commands.append(node)
                return node
            first, last = toks[0].line, toks[-1].line
            lines.append((first, last))
        raise self.src.error("`command` is not closed", pos, 7, hint="close it with `endcommand` before `end`")


def parse_fish(name: str, params: tuple[str, ...], src: FishSource, pos) -> FishDef:
    """Parse a whole function body."""
    lines = logical_lines(src)
    st = _Statements(src, lines, name.lower())
    body, ender = st.block(())
    for p in params:
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", p) or p in KEYWORDS:
            raise src.error(f"`{p}` cannot be a parameter name", pos)
    return FishDef(name.lower(), tuple(p.lower() for p in params), body, src, pos,
                   st.locals, st.globals, st.assigned, st.commands)


def parse_inline(text: str, src: FishSource):
    """A `[ ... ]` fragment: one statement (assignment or expression)."""
    lines = logical_lines(src)
    if not lines:
        raise src.error("empty inline expression", (src.first_line, 1))
    if len(lines) > 1:
        t = lines[1][0]
        raise src.error("an inline expression holds one statement", (t.line, t.col))
    st = _Statements(src, lines, "")
    node = st.statement(lines[0])
    if node[0] not in ("assign", "expr", "calls"):
        raise src.error("only an assignment or an expression can stand in `[ ]`", node[-1])
    return node, st
