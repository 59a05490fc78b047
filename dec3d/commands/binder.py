"""Binding: a raw token line + the registry -> a `CommandCall` (pure; nothing runs).

Command words are resolved level by level by unique prefix; then positional values,
keywords and an optional range clause are bound against the command's declaration.
`range` may be omitted before the first range element (`block hide group 'x'`).
Inline `[expr]` and `@name` values are parsed and their names checked now, and
evaluated when the command runs.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from ..errors import (BindError, DeckSyntaxError, LazyLocation, LegacySyntaxError, NotSupportedError,  # noqa: F401
                      SourceLocation, UnimplementedError, frozen_instance)
from ..lang.abbrev import matches, suggest
from ..lang.expr import check_names, parse_expression
from ..lang.parser import KeyLine, ParsedDeck, RawLine
from .bind_direct import make_direct, replay_direct
from .bind_plan import MAX_PLANS, Plan, Slot, fill, replay, shape
from .legacy import legacy_hint
from .registry import REGISTRY, Command, Node, RangeElement, Registry
from .values import FLOAT, MISSING, Deferred, Flag, Param, ValueRangeError, ValueType


# a `;` comment that is not inside a quoted string
_COMMENT = re.compile(r""";(?=(?:[^'"]|'[^']*'|"[^"]*")*$).*""")


def _shown(tok, limit: int = 60) -> str:
    """A token as quoted in a message: a very long one is cut (the caret still marks all of it)."""
    t = str(tok)
    return t if len(t) <= limit else t[:limit - 1] + "…"


def source_text(lines, first: int, last: int) -> str:
    """Physical lines of a command, comments stripped, joined with newlines."""
    return "\n".join(_COMMENT.sub("", ln).rstrip() for ln in lines[first - 1:last]).strip()


@dataclass(frozen=True)
class RangeCall:
    element: RangeElement
    args: dict
    negate: bool
    location: SourceLocation


@dataclass(frozen=True)
class RangeClause:
    elements: tuple[RangeCall, ...]
    union: bool = False


@dataclass(frozen=True)
class CommandCall:
    """A bound command: what to run, with which values, from where."""

    command: Command
    args: dict                      # keyword key -> value (defaults filled); Deferred until run
    given: tuple[str, ...]          # keys given on the line, in order
    range: RangeClause | None
    location: SourceLocation
    extra: dict = field(default_factory=dict)   # undeclared keywords (open_keywords commands)
    locations: dict = field(default_factory=dict)  # key -> SourceLocation of its value
    span: tuple = ()          # (source lines, first line, last line): the text, made on demand

    @property
    def name(self) -> str:
        return self.command.name

    @property
    def text(self) -> str:
        """The command as written (continuation lines included, comments removed)."""
        if self.span:
            return source_text(*self.span)
        return self.location.text.strip()


@dataclass(frozen=True)
class ExprStatement:
    """A line made only of `[ ... ]` (assignment or expression, e.g. io.out) or of `@name`."""

    node: tuple
    location: SourceLocation
    source: str


class BindContext:
    """What the binder knows about FISH names while reading a deck, in order."""

    def __init__(self, variables=None, lenient_names: bool = False):
        self.session_variables = variables if variables is not None else {}
        # checking a file on its own: names it never assigns may come from a calling deck
        self.lenient_names = lenient_names
        self.assigned: set[str] = set()
        self.fish_functions: dict[str, Any] = {}
        self.fish_variables: dict[str, str] = {}   # variable -> function that sets it

    def define_fish(self, block) -> None:
        self.fish_functions[block.name.lower()] = block
        for v in block.variables:
            self.fish_variables.setdefault(v, block.name)

    def classify(self, name: str) -> str | None:
        # FISH functions and the variables their bodies set are run by dec3d.fish
        if name in self.fish_functions or name in self.assigned or name in self.session_variables:
            return None
        if name in self.fish_variables:
            return None
        return None if self.lenient_names else "undefined"


class Binder:
    def __init__(self, deck: ParsedDeck, context: BindContext, stack=(), registry: Registry = REGISTRY):
        self.deck = deck
        self.ctx = context
        self.stack = tuple(stack)
        self.reg = registry
        self.plans: dict[tuple, Plan | None] = {}   # line shape -> plan (lang: bind_plan)
        # a line's lexer key -> a plan of its shape (``RawLine.key``: lines of one key have one shape;
        # a string's hash is kept, a shape's is not)
        self.by_key: dict[str, Plan] = {}
        # number text -> its float, for lines bound from their text (bind_direct): a polyhedron's
        # line writes each corner three times, and neighbouring blocks share corners
        self.numbers: dict[str, float] | None = {}
        self.looked = self.missed = 0             # takes of numbers looked up there, and missed
        self._steps: list | None = None             # the takes of the line being planned

    # ------------------------------------------------------------ helpers
    def where(self, tok) -> LazyLocation:
        return LazyLocation(self.deck, tok, self.stack)

    def deferred(self, tok) -> Deferred:
        if tok.type == "ATNAME":
            name = str(tok)[1:].lower()
            self._check_name_use([("name", name, 1)], tok, at=True)
            return Deferred("at", ("name", name, 1), tok, self.where(tok))
        node = self.expression(tok)
        return Deferred("expr", node, tok, self.where(tok))

    def expression(self, tok):
        """Parse `[...]` and check its names; errors point into the bracket."""
        text = str(tok)[1:-1]
        try:
            node = parse_expression(text)
        except DeckSyntaxError as exc:
            fish = _fish_inline(text)        # FISH syntax beyond expr.lark (v->x, ::list); run by dec3d.fish
            if fish is not None:
                return fish
            col = tok.column + getattr(exc, "column_in_expr", 1)
            loc = self.deck.location(tok, self.stack)
            raise DeckSyntaxError(exc.message, SourceLocation(loc.file, loc.line, col, loc.text, 1, loc.stack),
                                  exc.hint) from None
        problems = check_names(node, self.ctx.classify)
        for kind, name, col in problems:
            if node[0] == "assign" and kind == "undefined" and name == node[1]:
                continue
            if kind in ("intrinsic", "unknown-function") and _fish_knows(name, self.ctx):
                continue
            self._raise_name_problem(kind, name, tok, tok.column + col)
        return node

    def _check_name_use(self, names, tok, at=False):
        for _, name, _col in names:
            kind = self.ctx.classify(name)
            if kind:
                self._raise_name_problem(kind, name, tok, tok.column + (1 if at else 0), at=at)

    def _raise_name_problem(self, kind, name, tok, col, at=False):
        loc = self.deck.location(tok, self.stack)
        loc = SourceLocation(loc.file, loc.line, col, loc.text, len(name), loc.stack)
        if kind == "fish-function":
            raise NotSupportedError(f"FISH functions are not supported yet (call of `{name}`)", loc)
        if kind == "fish-variable":
            fn = self.ctx.fish_variables[name]
            raise NotSupportedError(f"`{name}` is set by FISH function `{fn}`; FISH functions are not supported yet", loc)
        if kind == "intrinsic":
            raise UnimplementedError(f"FISH intrinsic `{name}` is not supported yet", loc)
        if kind == "unknown-function":
            raise NotSupportedError(f"`{name}` is neither a FISH function of the deck nor a FISH intrinsic dec3d "
                                    "knows", loc, hint="define the function with `fish define` before this line")
        if at:
            raise NotSupportedError(f"`@{name}` is neither a variable set earlier nor a FISH function", loc)
        raise BindError(f"undefined FISH variable `{name}`", loc, hint="assign it first, e.g. [name = 1.0]")

    # ------------------------------------------------------------ commands
    def bind_line(self, raw: RawLine) -> "CommandCall | ExprStatement":
        """Any line: a `[ ... ]` statement, an `@name` call, or a command."""
        lkey = raw.key
        if lkey is not None and type(raw) is KeyLine:     # by its key's plan, from the text (bind_direct)
            plan = self.by_key.get(lkey)
            if plan is not None:
                d = plan.direct.get(lkey)
                if d is None:
                    d = plan.direct[lkey] = make_direct(plan, raw) or False
                if d and d.tpl is raw.tpl:
                    call = replay_direct(d, raw, self)
                    if call is not None:
                        return call
        toks = raw.items
        first = toks[0]
        if len(toks) == 1 and first.type == "EXPR":
            node = self.expression(first)
            if node[0] == "assign":
                self.ctx.assigned.add(node[1])   # later lines may use the variable
            return frozen_instance(ExprStatement, {"node": node, "location": self.deck.location(first, self.stack),
                                                   "source": self.source(raw)})
        if len(toks) == 1 and first.type == "ATNAME":
            self.deferred(first)                 # checks the name; a FISH function is called when it runs
            return ExprStatement(("name", str(first)[1:].lower(), 1), self.deck.location(first, self.stack),
                                 str(first))
        tried = None                             # a command: by its lexer key's plan, if any
        if lkey is not None:
            tried = self.by_key.get(lkey)
            if tried is not None:
                call = replay(tried, raw, toks, self)
                if call is not None:
                    return call
        key = shape(toks)                        # by its shape's plan, if any
        plan = self.plans.get(key)
        if plan is not None and plan is not tried:
            call = replay(plan, raw, toks, self)
            if call is not None:
                if lkey is not None:
                    self.by_key[lkey] = plan
                return call
        call = self._plan(raw, key)
        if lkey is not None and key in self.plans:
            self.by_key[lkey] = self.plans[key]
        return call

    def bind(self, raw: RawLine) -> CommandCall:
        """A command line (``bind_line`` for any line)."""
        key = shape(raw.items)
        plan = self.plans.get(key)
        call = replay(plan, raw, raw.items, self) if plan is not None else None
        return call if call is not None else self._plan(raw, key)

    def _plan(self, raw: RawLine, key) -> CommandCall:
        """The line bound the ordinary way, and the plan of its shape ``key`` made from it."""
        items = raw.items
        toks = raw.tokens
        self._steps = steps = []
        try:
            call = self._bind(toks)
        finally:
            self._steps = None
        if call.command.accepts_anything:
            return call
        values = [s[3] for s in steps]
        if len(self.plans) >= MAX_PLANS:
            self.plans.clear()
            self.by_key.clear()
        plan = self.plans[key] = Plan(call, [s[:3] for s in steps], toks, items, values)
        call = fill(plan, values, toks, self.deck, self.stack)
        cmd = call.command
        if cmd.check is not None:
            cmd.check(call)
        return call

    def _bind(self, toks) -> CommandCall:
        """The ordinary binding of a command line; with ``_steps`` set, each value is a ``Slot``
        (the command's check is left to the caller, which fills them)."""
        first = toks[0]
        if first.type == "ATNAME":
            self.deferred(first)
            raise NotSupportedError(f"`{first}` followed by more words is not supported yet: write `[f(args)]` "
                                    "to call a FISH function with arguments", self.where(first))
        if first.type != "WORD":
            raise BindError(f"a command starts with a command word, not `{_shown(first)}`", self.where(first),
                            hint="`[ ... ]` and `@name` stand alone on a line or as values")
        node, i, path, pre, prekw = self._resolve(toks)
        cmd = node.command
        loc = self.deck.location(first, self.stack)
        if cmd is None:
            self._no_command(node, path, toks, i)
        span = (self.deck.source_lines, first.line, toks[-1].line)
        if cmd.accepts_anything:
            return CommandCall(cmd, {}, (), None, loc, span=span)
        call = self._bind_args(cmd, toks, i, pre, loc, prekw)
        object.__setattr__(call, "span", span)
        if cmd.check is not None and self._steps is None:
            cmd.check(call)
        return call

    def source(self, raw: RawLine) -> str:
        items = raw.items
        return source_text(self.deck.source_lines, items[0].line, items[-1].line)

    def _resolve(self, toks):
        node = self.reg.root
        path: list[str] = []
        pre: dict = {}
        prekw: tuple[Param, ...] = ()
        i = 0
        while i < len(toks):
            tok = toks[i]
            if tok.type != "WORD" or not node.children:
                break
            word = str(tok).lower()
            hits = node.match(word)
            if len(hits) == 1:
                child = node.children[hits[0]]
                if child.alias_of:                      # bare `call` = `program call`
                    child = self.reg.node(child.alias_of)
                    path = list(self.reg.aliases[hits[0]])
                else:
                    path.append(hits[0])
                node = child
                prekw = prekw + node.keywords
                i += 1
                continue
            if len(hits) > 1:
                # a command whose keywords could also take this word binds it as a keyword
                if node.command and any(matches(word, [p.name for p in node.command.keywords])):
                    break
                raise BindError(f"`{_shown(tok)}` is ambiguous after `{' '.join(path) or 'the start of a line'}`: "
                                f"could be {', '.join(hits)}", self.where(tok),
                                hint="type more letters of the word")
            kw = matches(word, [p.name for p in prekw]) if prekw else []
            if len(kw) == 1 and node.command is None:
                param = next(p for p in prekw if p.name == kw[0])
                value, i = self._take_value(param, toks, i + 1, tok)
                pre[param.key] = value
                continue
            break
        return node, i, tuple(path), pre, prekw

    def _no_command(self, node: Node, path, toks, i):
        name = " ".join(path)
        if i < len(toks) and toks[i].type == "WORD" and (node.children or not path):
            tok = toks[i]
            if node.known and not node.children:
                raise UnimplementedError(f"`{name}` is not supported yet", self.where(toks[0]))
            cands = sorted(node.children)
            if len(path) <= 1:
                # `hist time` (3DEC 5) resolves its first word to the modern `history` group
                head = str(toks[0]).lower() if path else str(tok).lower()
                hint = legacy_hint(head)
                if hint and path:
                    raise LegacySyntaxError(f"`{_shown(toks[0])} {_shown(tok)}` is 3DEC 5 (legacy) syntax, not 3DEC 7+",
                                            self.where(toks[0]), hint)
                if hint:
                    raise LegacySyntaxError(f"`{_shown(tok)}` is 3DEC 5 (legacy) syntax, not 3DEC 7+", self.where(tok), hint)
            close = suggest(str(tok), cands)
            where = f"`{name} {_shown(tok)}`" if name else f"`{_shown(tok)}`"
            if close:
                hint = "did you mean " + " or ".join(f"`{(name + ' ' + c).strip()}`" for c in close) + "?"
            else:
                hint = "expected one of: " + ", ".join(cands[:12]) + (" …" if len(cands) > 12 else "")
            raise BindError(f"unknown command {where}", self.where(tok), hint=hint)
        if node.known and not any(c.command for _, c in self.reg.walk(node)):
            raise UnimplementedError(f"`{name}` is not supported yet", self.where(toks[0]))
        cands = sorted(node.children)
        hint = legacy_hint(str(toks[0]).lower()) if len(path) == 1 and i < len(toks) else None
        if hint:                                 # `hist @var` (3DEC 5): a value where 3DEC 7 wants a word
            raise LegacySyntaxError(f"`{_shown(toks[0])} {_shown(toks[i])}` is 3DEC 5 (legacy) syntax, not 3DEC 7+",
                                    self.where(toks[0]), hint)
        raise BindError(f"`{name}` needs a subcommand", self.where(toks[min(i, len(toks)) - 1]),
                        hint=f"one of: {', '.join(cands)}")

    def _take(self, param: Param, toks, i):
        """The value of `param` at toks[i]; an out-of-range value names its keyword. While a plan is
        made, the take is recorded and its value stands as a Slot."""
        try:
            value, j = param.value.take(toks, i, self)
        except ValueRangeError as exc:
            raise exc.named(param.name) from None
        steps = self._steps
        if steps is None:
            return value, j
        steps.append((param, i, j, value))
        return Slot(len(steps) - 1), j

    def _take_value(self, param: Param, toks, i, kwtok):
        if not param.supported:
            raise UnimplementedError(f"keyword `{param.name}` is not supported yet", self.where(kwtok))
        vt = param.value
        if isinstance(vt, Flag):          # present means True; it takes no value
            return True, i
        if i < len(toks) and vt.fits(toks[i]):
            return self._take(param, toks, i)
        if param.bare is not MISSING:
            return param.bare, i
        got = f"`{_shown(toks[i])}`" if i < len(toks) else "the end of the line"
        raise BindError(f"`{param.name}` needs a value {vt.describe()}, got {got}",
                        self.where(toks[i] if i < len(toks) else kwtok))

    def _bind_params(self, what: str, positional, names, by_name, toks, i, args, given, locs, on_other) -> int:
        """Bind positional values, then keywords, from toks[i:] into `args`.

        A token that is neither goes to `on_other(i)`, which returns where to go on from,
        or None to stop there (a range clause, the next range element). Returns the index
        where binding stopped. Shared by commands and range elements.
        """
        pos = list(positional)
        n = len(toks)
        while i < n:
            tok = toks[i]
            if pos:
                p = pos[0]
                if p.value.fits(tok) and not (tok.type == "WORD" and matches(str(tok), names)):
                    pos.pop(0)
                    locs[p.key] = self.where(tok)
                    args[p.key], i = self._take(p, toks, i)
                    given.append(p.key)
                    continue
                if p.required:
                    opts = getattr(p.value, "options", ())
                    close = suggest(str(tok), opts) if opts and tok.type == "WORD" else []
                    raise BindError(f"{what} needs {p.name} {p.value.describe()} here, got `{_shown(tok)}`",
                                    self.where(tok), hint=(f"did you mean {' or '.join(f'`{c}`' for c in close)}?"
                                                           if close else p.doc or None))
                pos.pop(0)
                continue
            hits = matches(str(tok), names) if tok.type == "WORD" else []
            if len(hits) > 1:
                raise BindError(f"keyword `{_shown(tok)}` is ambiguous: could be {', '.join(hits)}", self.where(tok))
            if len(hits) == 1:
                p = by_name[hits[0]]
                value, j = self._take_value(p, toks, i + 1, tok)
                locs[p.key] = self.where(toks[i + 1] if j > i + 1 else tok)
                if p.repeat:
                    args.setdefault(p.key, []).append(value)
                else:
                    args[p.key] = value       # given twice: the later value wins, as in 3DEC
                given.append(p.key)
                i = j
                continue
            j = on_other(i)
            if j is None:
                break
            i = j
        for p in pos:
            if p.required:
                raise BindError(f"{what} needs {p.name} {p.value.describe()}", self._end(toks), hint=p.doc or None)
        return i

    def _fill_defaults(self, what: str, params, args, toks) -> None:
        for p in params:
            if p.key not in args:
                if p.required:
                    raise BindError(f"{what} needs keyword `{p.name}` {p.value.describe()}", self._end(toks),
                                    hint=p.doc or None)
                args[p.key] = [] if p.repeat else p.default

    def _bind_args(self, cmd: Command, toks, i, pre, loc, inherited=()) -> CommandCall:
        args: dict[str, Any] = dict(pre)
        given: list[str] = list(pre)
        extra: dict[str, Any] = {}
        locs: dict[str, Any] = {}
        rng = None
        n = len(toks)

        def other(i):
            nonlocal rng
            tok = toks[i]
            if tok.type != "WORD":
                raise BindError(f"unexpected value `{_shown(tok)}`", self.where(tok), hint=self._keyword_hint(cmd))
            word = str(tok).lower()
            if cmd.range and (word == "range" or (len(word) >= 2 and matches(word, ["range"]) == ["range"])):
                rng = self._bind_range(toks, i + 1, cmd)
                return None
            if cmd.range and matches(word, self.reg.range_elements):
                rng = self._bind_range(toks, i, cmd)       # `range` omitted before the first element
                return None
            if cmd.open_keywords and i + 1 < n and toks[i + 1].type in ("NUMBER", "EXPR", "ATNAME", "STRING"):
                extra[word], _ = self._take(Param(word, _OPEN), toks, i + 1)
                return i + 2
            cands = list(cmd.keyword_names) + (["range"] + sorted(self.reg.range_elements) if cmd.range else [])
            close = suggest(word, cands)
            raise BindError(f"unknown keyword `{_shown(tok)}` for `{cmd.name}`", self.where(tok),
                            hint=f"did you mean {' or '.join(f'`{c}`' for c in close)}?" if close
                            else self._keyword_hint(cmd))

        what = f"`{cmd.name}`"
        names, by_name, params = cmd.keyword_names, cmd.by_name, cmd.positional + cmd.keywords
        extra_kw = tuple(p for p in inherited if p.name not in by_name)
        if extra_kw:       # keywords of a command group may also follow the command word
            names = names + tuple(p.name for p in extra_kw)
            by_name = {**by_name, **{p.name: p for p in extra_kw}}
            params = params + extra_kw
        self._bind_params(what, cmd.positional, names, by_name, toks, i, args, given, locs, other)
        self._fill_defaults(what, params, args, toks)
        return CommandCall(cmd, args, tuple(given), rng, loc, extra, locs)

    def _keyword_hint(self, cmd: Command) -> str:
        kws = [p.name for p in cmd.keywords]
        if cmd.range:
            kws.append("range …")
        return f"keywords of `{cmd.name}`: {', '.join(kws)}" if kws else f"`{cmd.name}` takes no keywords"

    def _end(self, toks):
        """Just after the last token: where a missing value would have stood."""
        last = toks[-1]
        loc = self.deck.location(last, self.stack)
        return SourceLocation(loc.file, loc.line, loc.column + len(str(last)), loc.text, 1, loc.stack)

    # ------------------------------------------------------------ ranges
    def _bind_range(self, toks, i, cmd: Command) -> RangeClause:
        elements: list[RangeCall] = []
        union = False
        n = len(toks)
        names = sorted(self.reg.range_elements)
        while i < n:
            tok = toks[i]
            if tok.type != "WORD":
                raise BindError(f"expected a range element, got `{_shown(tok)}`", self.where(tok),
                                hint=f"range elements: {', '.join(names)}")
            word = str(tok).lower()
            if word in ("not", "no") or matches(word, ["not"]) == ["not"] and word not in self.reg.range_elements:
                if not elements:
                    raise BindError("`not` must follow the range element it negates", self.where(tok))
                last = elements[-1]
                elements[-1] = RangeCall(last.element, last.args, not last.negate, last.location)
                i += 1
                continue
            if matches(word, ["union"]) == ["union"] and len(word) >= 2:
                union = True
                i += 1
                continue
            hits = matches(word, names)
            if len(hits) != 1:
                close = suggest(word, names)
                msg = (f"range element `{_shown(tok)}` is ambiguous: could be {', '.join(hits)}" if hits
                       else f"unknown range element `{_shown(tok)}`")
                raise BindError(msg, self.where(tok), hint=f"did you mean {' or '.join(close)}?" if close else
                                f"range elements: {', '.join(names)}")
            elem = self.reg.range_elements[hits[0]]
            if not elem.supported:
                raise UnimplementedError(f"range element `{elem.name}` is not supported yet", self.where(tok))
            if elem.stores and cmd.range not in elem.stores:
                raise BindError(f"range element `{elem.name}` does not apply to {cmd.range}s", self.where(tok))
            args, i = self._bind_element(elem, toks, i + 1, tok)
            elements.append(RangeCall(elem, args, False, self.where(tok)))
        if not elements:
            raise BindError("`range` needs at least one range element", self._end(toks),
                            hint=f"range elements: {', '.join(names)}")
        return RangeClause(tuple(elements), union)

    def _bind_element(self, elem: RangeElement, toks, i, head):
        args: dict[str, Any] = {}

        def other(i):
            tok = toks[i]
            if tok.type != "WORD":
                raise BindError(f"unexpected value `{_shown(tok)}` in range element `{elem.name}`", self.where(tok))
            return None                    # the next element, or a modifier

        names = tuple(p.name for p in elem.keywords)
        by_name = {p.name: p for p in elem.keywords}
        what = f"range element `{elem.name}`"
        i = self._bind_params(what, elem.positional, names, by_name, toks, i, args, [], {}, other)
        self._fill_defaults(what, elem.positional + elem.keywords, args, toks)
        return args, i


class _OpenValue(ValueType):
    """The value of an undeclared keyword (open_keywords commands): a string, a number, `[ ]`, `@`."""

    def take(self, toks, i, binder):
        vt = toks[i]
        if vt.type == "STRING":
            return str(vt)[1:-1], i + 1
        if vt.type == "NUMBER":
            return FLOAT.convert(float(str(vt)), binder.where(vt)), i + 1
        return binder.deferred(vt), i + 1


_OPEN = _OpenValue()


def _fish_inline(text: str):
    """A tree for an inline fragment only dec3d.fish reads: ("assign", name, ...) for an assignment
    (so later lines may use the name), ("fish", text) otherwise; None if FISH cannot parse it either."""
    from ..fish import FishSource, parse_inline

    try:
        node, _ = parse_inline(text, FishSource("<inline>", 1, [text]))
    except Exception:
        return None
    if node[0] == "assign" and node[1][0] == "name":
        return ("assign", node[1][1], node[2], ("fish", text), 0)
    return ("fish", text)


def _fish_knows(name: str, ctx: BindContext) -> bool:
    """A name dec3d's FISH runs: a FISH function of the deck, an implemented intrinsic, or a variable
    (`v(i)` indexes a list, map or vector held by a variable)."""
    from ..fish import intrinsics

    return (name in ctx.fish_functions or intrinsics.resolve(name) is not None or name in ctx.assigned
            or name in ctx.session_variables or name in ctx.fish_variables)
