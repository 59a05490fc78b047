"""Bind plans: a line bound once gives the plan for every later line of the same shape.

Every choice the binder makes (which command, which keyword, which value type takes which
tokens, where a range clause starts) depends only on the line's *shape*: the type of each
token and the text of each word. What a line's numbers, strings and `[ … ]` values are changes
only the values, which the value types work out (``ValueType.take``). A deck of 100 000
generated lines has a few dozen shapes.

So the binder binds a line of a new shape the ordinary way, with every value replaced by a
``Slot`` (a numbered hole) and the takes recorded in order — the ``Plan``. A later line of the
same shape replays the takes on its own tokens (the same value types at the same token
positions, which must consume the same tokens) and fills the holes. The plan is only a
shortcut: when any take fails or consumes other tokens than recorded, the line is bound the
ordinary way, which gives its result or its error, the same as without plans. The command's
``check`` runs on every filled call.

A line whose lexer items hold runs of numbers (``lang.parser.NumRun``: a `block create polyhedron`
line is 72 numbers in one run) is replayed on its items when every take of its plan is a real
number or numbers (``Num``, ``Nums``) or reads one token (``ValueType.take``): a run's numbers are
converted in one pass (``run_values``) and its tokens are never made; a number out of its bounds
(or anything else) sends the line to the replay on its tokens, then to the ordinary binding.
"""
from __future__ import annotations

import math

from ..errors import LazyLocation
from ..lang.parser import run_tokens
from .values import Choice, InPath, Num, Nums, OnOff, OutPath, Text, ValueType

# the shape of a non-word token: no word can be spelt with `<`; a run of numbers is its count
SHAPE_OF = {"NUMBER": "<n>", "STRING": "<s>", "EXPR": "<e>", "ATNAME": "<a>", "NUMRUN": None}
#: plans kept per binder (a deck whose every line has its own words has no use for more)
MAX_PLANS = 4096
_take_one = ValueType.take
_new, _set = object.__new__, object.__setattr__
_radians = math.radians
#: value types whose value of a word depends on the word alone (a string or a bool): a plan keeps
#: the value its line gave (the word is part of the shape)
_WORD_VALUES = frozenset((Choice, OnOff, Text, OutPath, InPath))


def shape(toks) -> tuple:
    """The line's shape: each word as written, each value by its type (a run of numbers by its
    count: the shape of a line's items says the shape of its tokens)."""
    kinds = SHAPE_OF
    return tuple([t.value if t.type == "WORD" else kinds[t.type] or len(t.nums) for t in toks])


class Slot:
    """The hole a recorded take leaves in a plan's call: the n-th value taken."""

    __slots__ = ("n",)

    def __init__(self, n: int):
        self.n = n


class RunLocation(LazyLocation):
    """The location of the k-th number of a run: its token is made only when asked for (from the
    run's text and place, not the run: what a bound call keeps stays small)."""

    __slots__ = ("text", "start", "line", "line_start", "k")

    def __init__(self, deck, run, k, stack=()):
        self.deck, self.k, self.stack = deck, k, stack
        self.text, self.start, self.line, self.line_start = run.text, run.start, run.line, run.line_start

    @property
    def token(self):
        return run_tokens(self.text, self.start, self.line, self.line_start)[self.k]

    def resolve(self):
        return self.deck.location(self.token, self.stack)


def run_values(strs, inline, text):
    """The numbers written ``strs`` as ``Nums.take`` converts them inline (``Num.inline``: bounds and
    degrees), or None when one is outside its bounds or not finite (the tokens' take then reports it).
    ``text``: what they were cut from (a `-0` in it asks for the check of the sign of zeros)."""
    lo, lo_closed, hi, hi_closed, angle = inline
    vals = list(map(float, strs))
    if "-0" in text and 0.0 in vals:    # an integer zero is +0.0 (`-0` is float(int('-0')))
        vals = [v if v or "." in s or "e" in s or "E" in s else 0.0 for v, s in zip(vals, strs)]
    mn, mx = min(vals), max(vals)
    if not ((lo < mn or (mn == lo and lo_closed)) and (mx < hi or (mx == hi and hi_closed))):
        return None
    if angle:
        return [_radians(v) for v in vals]
    return vals


def _compact(steps, toks, items):
    """What replaying on ``items`` needs: per take (0, n, segments, inline, one value) for real
    numbers — a segment (item, first, end) of a run or (item, None, None) of a token — or
    (1, n, param, item) for a take of one token (n: the value's number); the item (and number of a
    run, or None) of each token. None when a take is neither, or the line does not start with a token."""
    where = []
    for a, it in enumerate(items):
        if it.type == "NUMRUN":
            where.extend((a, o) for o in range(len(it.nums)))
        else:
            where.append((a, None))
    if len(where) != len(toks) or where[0][1] is not None:
        return None
    out = []
    for n, param, i, j in steps:
        vt = param.value
        kind = type(vt)
        inline = vt.inline if kind is Num else vt.item.inline if kind is Nums else None
        if inline is not None and (kind is Nums or j == i + 1):
            segs: list[list] = []
            for a, o in where[i:j]:
                if segs and segs[-1][0] == a and o is not None:
                    segs[-1][2] = o + 1
                else:
                    segs.append([a, o, None if o is None else o + 1])
            out.append((0, n, tuple(map(tuple, segs)), inline, kind is Num))
        elif j == i + 1 and where[i][1] is None and kind.take is _take_one:
            out.append((1, n, param, where[i][0]))
        else:
            return None
    return tuple(out), where


class Plan:
    """A bound call with holes; the takes that fill them (param, first token, end), of which those
    of a word by a type in ``_WORD_VALUES`` keep their value (``values``; ``vsteps``: the others, with
    their value's number); token indices of the locations it holds (by the identity of the recorded
    line's tokens); for a line with runs of numbers, the same on its items (``compact``, ``clocs``,
    ``cwhere``), or None."""

    __slots__ = ("call", "steps", "vsteps", "values", "holes", "lists", "locs", "where", "compact", "clocs",
                 "cwhere", "batch", "direct")

    def __init__(self, call, steps, toks, items=None, values=None):
        self.call = call
        self.steps = tuple(steps)
        self.values = [None] * len(self.steps)
        vsteps = []
        for n, (param, i, j) in enumerate(self.steps):
            if (values is not None and j == i + 1 and toks[i].type == "WORD"
                    and type(param.value) in _WORD_VALUES):
                self.values[n] = values[n]
            else:
                vsteps.append((n, param, i, j))
        self.vsteps = tuple(vsteps)
        self.holes = tuple((k, v.n) for k, v in call.args.items() if type(v) is Slot)
        self.lists = tuple(k for k, v in call.args.items() if type(v) is list)
        ids = {id(t): k for k, t in enumerate(toks)}
        self.locs = tuple((k, ids[id(loc.token)]) for k, loc in call.locations.items())
        self.where = {}
        if call.range is not None:
            for e in call.range.elements:
                self.where[id(e.location)] = ids[id(e.location.token)]
        self.compact = self.clocs = self.cwhere = self.batch = None
        self.direct = {}                  # lexer key -> its replay on the text (``bind_direct``), or False
        if items is not None and items is not toks:
            got = _compact(self.vsteps, toks, items)
            if got is not None:
                self.compact, where = got
                self.clocs = tuple((k, *where[i]) for k, i in self.locs)
                self.cwhere = {k: where[i] for k, i in self.where.items()}
                self.compact, self.batch = _batched(self.compact, items)


def _batched(compact, items):
    """``compact`` without its takes of numbers that are each one whole run of numbers under the same
    bounds, when there are two or more (a polyhedron's six faces): those are converted in one
    ``run_values`` (``batch``: bounds, then (value number, item, count) per take), not one each."""
    whole = [st for st in compact
             if not st[0] and not st[4] and len(st[2]) == 1 and st[2][0][1] == 0
             and st[2][0][2] == len(items[st[2][0][0]].nums)]
    if len(whole) < 2 or len({st[3] for st in whole}) != 1:
        return compact, None
    batch = (whole[0][3], tuple((st[1], st[2][0][0], st[2][0][2]) for st in whole))
    return tuple(st for st in compact if not any(st is w for w in whole)), batch


def fill_value(v, values):
    if type(v) is Slot:
        return values[v.n]
    if type(v) is list:                   # a repeated keyword: a new list for every call
        return [values[x.n] if type(x) is Slot else x for x in v]
    return v


def fill(plan: Plan, values, toks, deck, stack):
    """The plan's call with the holes filled from ``values`` and the locations on ``toks`` (the
    classes are the recorded call's own)."""
    locs = {k: LazyLocation(deck, toks[i], stack) for k, i in plan.locs}
    rng = plan.call.range
    if rng is not None:
        where = plan.where
        rng = fill_range(rng, values, [LazyLocation(deck, toks[where[id(e.location)]], stack) for e in rng.elements])
    return fill_call(plan, values, locs, rng, toks[0], toks[-1].line, deck, stack)


def replay(plan: Plan, raw, items, binder):
    """``raw`` bound by its shape's plan; None when a take fails or takes other tokens (the line is
    then bound the ordinary way, which reports what is wrong). A line with runs of numbers is
    replayed on its items first (``replay_compact``), then on its tokens."""
    if plan.compact is not None:
        try:
            call = replay_compact(plan, items, binder)
            if call is not None:
                cmd = call.command
                if cmd.check is not None:
                    cmd.check(call)
                return call
        except Exception:
            pass
    toks = raw.tokens
    values = plan.values.copy()
    try:
        for n, param, i, j in plan.vsteps:
            v, end = param.value.take(toks, i, binder)     # as Binder._take (its errors end the replay)
            if end != j:
                return None
            values[n] = v
        deck, stack = binder.deck, binder.stack            # fill, written out
        locs = {k: LazyLocation(deck, toks[i], stack) for k, i in plan.locs}
        rng = plan.call.range
        if rng is not None:
            where = plan.where
            rng = fill_range(rng, values, [LazyLocation(deck, toks[where[id(e.location)]], stack)
                                           for e in rng.elements])
        call = fill_call(plan, values, locs, rng, toks[0], toks[-1].line, deck, stack)
        cmd = call.command
        if cmd.check is not None:
            cmd.check(call)
    except Exception:
        return None
    return call


def _at(deck, items, a, o, stack):
    return LazyLocation(deck, items[a], stack) if o is None else RunLocation(deck, items[a], o, stack)


def replay_compact(plan: Plan, items, binder):
    """The plan's call made from the line's items (``Plan.compact``), or None when a number is out of
    its bounds (the caller replays on the tokens, whose take reports it). Other errors propagate."""
    values = plan.values.copy()
    batch = plan.batch
    if batch is not None:                            # whole runs under one set of bounds: one pass
        strs: list = []
        for _, a, _ in batch[1]:
            strs += items[a].nums
        nums = run_values(strs, batch[0], " ".join([items[a].text for _, a, _ in batch[1]]))
        if nums is None:
            return None
        o = 0
        for n, _, count in batch[1]:
            values[n] = tuple(nums[o:o + count])
            o += count
    for step in plan.compact:
        if step[0]:
            values[step[1]] = _take_one(step[2].value, items, step[3], binder)[0]
            continue
        _, n, segs, inline, one = step
        if len(segs) == 1 and segs[0][1] == 0:       # the numbers of one run, from its first
            a, _, o1 = segs[0]
            it = items[a]
            nums = it.nums
            nums = run_values(nums if o1 == len(nums) else nums[:o1], inline, it.text)
            if nums is None:
                return None
            values[n] = nums[0] if one else tuple(nums)
            continue
        out = []
        for a, o0, o1 in segs:
            it = items[a]
            if o0 is None:
                if it.type != "NUMBER":
                    out.append(binder.deferred(it))
                    continue
                nums = run_values((it.value,), inline, it.value)
            else:
                nums = it.nums
                nums = run_values(nums if o0 == 0 and o1 == len(nums) else nums[o0:o1], inline, it.text)
            if nums is None:
                return None
            out.extend(nums)
        values[n] = out[0] if one else tuple(out)
    deck, stack = binder.deck, binder.stack
    locs = {k: LazyLocation(deck, items[a], stack) if o is None else RunLocation(deck, items[a], o, stack)
            for k, a, o in plan.clocs}
    rng = plan.call.range
    if rng is not None:
        where = plan.cwhere
        rng = fill_range(rng, values, [_at(deck, items, *where[id(e.location)], stack) for e in rng.elements])
    return fill_call(plan, values, locs, rng, items[0], items[-1].line, deck, stack)


def fill_range(rng, values, locations):
    one = type(rng.elements[0])
    return type(rng)(tuple(one(e.element, {k: fill_value(v, values) for k, v in e.args.items()}, e.negate, loc)
                           for e, loc in zip(rng.elements, locations)), rng.union)


def fill_call(plan: Plan, values, locs, rng, first, last_line, deck, stack):
    return make_call(plan, values, locs, rng, deck.location(first, stack), (deck.source_lines, first.line, last_line))


def make_call(plan: Plan, values, locs, rng, location, span):
    """The plan's call with the holes filled from ``values``, at ``location``, spanning ``span``."""
    tpl = plan.call
    args = tpl.args.copy()                # the keys in the order binding gave them
    for k, n in plan.holes:
        args[k] = values[n]
    for k in plan.lists:                  # a repeated keyword: a new list for every call
        args[k] = fill_value(args[k], values)
    extra = {k: fill_value(v, values) for k, v in tpl.extra.items()} if tpl.extra else {}
    call = _new(type(tpl))                # errors.frozen_instance written out
    _set(call, "__dict__", {"command": tpl.command, "args": args, "given": tpl.given, "range": rng,
                            "location": location, "extra": extra, "locations": locs, "span": span})
    return call
