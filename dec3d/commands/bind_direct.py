"""Binding a line straight from the deck's text, by the plan of its lexer key (issue 33).

A line cut by the template of its key (``lang.parser.KeyLine``: its ASCII digits as `0`) has its
items at the same places as every line of that key, and the same characters but its digits. So
``str.split`` of the stretch of the line that holds its numbers (commas as blanks) gives the same
pieces at the same indices on every line of the key: the numbers a plan takes (``Plan.compact``,
``Plan.batch``) are slices of that one list, converted by ``float`` with no token and no run made.

What ``bind_plan.run_values`` does to them is done here: an integer written with a minus sign whose
value is zero is `+0.0` (as ``float(int(text))``); angles to radians; the bounds. Whether every number
of a take lies inside its bounds is told by the key where it can be: a take whose numbers have no
exponent and at most ``_STATIC_DIGITS`` digits before the point lies within ±10^digits (its sign by
the key), so bounds beyond that need no look at the values; other takes are checked with min and
max. A number out of bounds, or any error, returns None: the line is then bound as before (its
items made), which gives the same call or reports the same error.
"""
from __future__ import annotations

import math

from ..errors import LazyLocation, SourceLocation
from ..lang.parser import _NUMBER_IN_RUN, item_at
from .bind_plan import RunLocation, Slot, _compact, fill_range, fill_value
from .values import Text, ValueType

_take_one = ValueType.take
_new, _set = object.__new__, object.__setattr__
_radians = math.radians
#: the most digits before the point for which a take's bounds are told by its key (10**15 is exact)
_STATIC_DIGITS = 15
_GAP = frozenset(" \t\f,")
#: number texts whose values a binder remembers (``Binder.numbers``; about 100 bytes each)
MAX_NUMBERS = 1 << 14
MIN_LOOKS = 512


class Direct:
    """A plan's replay on the text of the lines of one key (template ``tpl``): the stretch ``rs:re`` of
    a line split into pieces; per take of numbers (value number, first piece, end piece): ``simple``,
    tuples of numbers known within bounds, ``other``: (n, p0, p1, bounds or None, pieces of negative
    integers, angle, one value); ``texts``: (n, item, start, end) takes of a string by ``Text``;
    ``ones``: (n, value type, item) other takes of one token; locations as ``Plan.clocs`` and the
    range's element locations, with the items' places; ``lists``: (key, value numbers) of repeated
    keywords; the first token's column and length (the call's location)."""

    __slots__ = ("plan", "tpl", "rs", "re", "simple", "other", "texts", "ones", "n_items", "clocs", "cwhere",
                 "lists", "column", "length", "looks")


def make_direct(plan, raw) -> Direct | None:
    """The direct replay of ``plan`` on lines of the key of ``raw`` (a ``KeyLine``), or None when the
    plan takes something other than numbers, whole tokens and runs split by blanks and commas."""
    tpl, key = raw.tpl[0], raw.key
    if key is None or len(tpl) == 0:
        return None
    compact, batch, clocs, cwhere = plan.compact, plan.batch, plan.clocs, plan.cwhere
    if compact is None:
        if raw.tpl[2]:
            return None
        items = raw.items                # no runs: the plan's tokens are the line's items
        got = _compact(plan.vsteps, items, items)
        if got is None:
            return None
        compact, where = got
        clocs = tuple((k, *where[i]) for k, i in plan.locs)
        cwhere = {k: where[i] for k, i in plan.where.items()}
    used = set()                         # items whose numbers are taken
    steps = []                           # (n, segments, inline, one)
    for st in compact:
        if st[0]:
            continue
        _, n, segs, inline, one = st
        for a, o0, _ in segs:
            if tpl[a][0] != ("NUMBER" if o0 is None else "NUMRUN"):
                return None              # `[ ]` or `@name` among the numbers
            used.add(a)
        steps.append((n, segs, inline, one))
    if batch is not None:
        inline, takes = batch
        for n, a, count in takes:
            if tpl[a][0] != "NUMRUN":
                return None
            used.add(a)
            steps.append((n, ((a, 0, count),), inline, False))
    d = _new(Direct)
    d.plan, d.tpl, d.n_items = plan, raw.tpl, len(tpl)
    d.simple, d.other = [], []
    if used:
        first, last = min(used), max(used)
        d.rs, d.re = tpl[first][1], tpl[last][2]
        region = key[d.rs:d.re]
        if "(" in region or ")" in region or "=" in region:
            return None
        pieces = region.replace(",", " ").split()
        start = {}                       # item -> index of its first piece
        p, at = 0, d.rs
        for a in range(first, last + 1):
            kind, s, e = tpl[a]
            if not set(key[at:s]) <= _GAP:
                return None
            text = key[s:e]
            cnt = len(text.replace(",", " ").split())
            if kind in ("NUMBER", "WORD") and cnt != 1:     # a run's pieces are its numbers (``NumRun.nums``)
                return None
            start[a] = p
            p, at = p + cnt, e
        if p != len(pieces):
            return None
        for n, segs, inline, one in steps:
            idx = []
            for a, o0, o1 in segs:
                idx.extend([start[a]] if o0 is None else range(start[a] + o0, start[a] + o1))
            p0, p1 = idx[0], idx[-1] + 1
            forms = set(pieces[p0:p1])   # digits are 0 in the key: a few forms
            if idx != list(range(p0, p1)) or not all(_NUMBER_IN_RUN.fullmatch(q) for q in forms):
                return None
            lo, lo_closed, hi, hi_closed, angle = inline
            negint = tuple(k for k in range(p0, p1) if pieces[k][0] == "-" and "." not in pieces[k]
                           and "e" not in pieces[k] and "E" not in pieces[k])
            bounds = None if _within(forms, inline) else (lo, lo_closed, hi, hi_closed)
            if bounds is None and not negint and not angle and not one:
                d.simple.append((n, p0, p1))
            else:
                d.other.append((n, p0, p1, bounds, negint, angle, one))
    else:
        d.rs = d.re = 0
    d.simple, d.other = tuple(d.simple), tuple(d.other)
    d.looks = len(d.simple) + len(d.other)
    ones = [(st[1], st[2].value, st[3]) for st in compact if st[0]]
    d.texts = tuple((n, a, tpl[a][1], tpl[a][2]) for n, vt, a in ones if type(vt) is Text and tpl[a][0] == "STRING")
    d.ones = tuple(st for st in ones if not (type(st[1]) is Text and tpl[st[2]][0] == "STRING"))
    d.clocs = tuple((k, tpl[a], o) for k, a, o in clocs)
    rng = plan.call.range
    d.cwhere = None if rng is None else tuple((tpl[a], o) for a, o in (cwhere[id(e.location)]
                                                                       for e in rng.elements))
    lists = []
    for k in plan.lists:
        v = plan.call.args[k]
        if not all(type(x) is Slot for x in v):
            lists = None
            break
        lists.append((k, tuple(x.n for x in v)))
    d.lists = None if lists is None else tuple(lists)
    d.column, d.length = tpl[0][1] + 1, (tpl[0][2] - tpl[0][1]) or 1
    return d


def _within(pieces, inline) -> bool:
    """Every number of a line whose key has these ``pieces`` (digits as 0) lies inside the bounds."""
    lo, lo_closed, hi, hi_closed, _ = inline
    for q in pieces:
        if "e" in q or "E" in q:
            return False
        digits = len(q.lstrip("+-").split(".")[0])
        if digits > _STATIC_DIGITS:
            return False
        big = 10.0 ** digits             # the value is at most this in size
        vmin, vmax = (-big, 0.0) if q[0] == "-" else (0.0, big)
        if not ((lo < vmin or (vmin == lo and lo_closed)) and (vmax < hi or (vmax == hi and hi_closed))):
            return False
    return True


def replay_direct(d: Direct, raw, binder):
    """The call of the ``KeyLine`` ``raw`` by ``d``; None when a number is out of its bounds or anything
    fails (the line is then bound from its items, which reports what is wrong)."""
    plan = d.plan
    text, pos, line = raw.text, raw.pos, raw.line
    values = plan.values.copy()
    try:
        pieces = text[pos + d.rs:pos + d.re].replace(",", " ").split()
        numbers = binder.numbers
        if numbers is None:              # the table is off (``_remember``)
            for n, p0, p1 in d.simple:
                values[n] = tuple(map(float, pieces[p0:p1]))
            known = float
        else:
            known = numbers.__getitem__
            binder.looked += d.looks
            for n, p0, p1 in d.simple:
                strs = pieces[p0:p1]
                try:
                    values[n] = tuple(map(known, strs))
                except KeyError:
                    values[n] = vals = tuple(map(float, strs))
                    _remember(binder, strs, vals)
        for n, p0, p1, bounds, negint, angle, one in d.other:
            strs = pieces[p0:p1]
            try:
                vals = list(map(known, strs))
            except KeyError:
                vals = list(map(float, strs))
                _remember(binder, strs, vals)
            for k in negint:                 # an integer zero is +0.0 (`-0` is float(int('-0')))
                if vals[k - p0] == 0.0:
                    vals[k - p0] = 0.0
            if bounds is not None:
                lo, lo_closed, hi, hi_closed = bounds
                mn, mx = min(vals), max(vals)
                if not ((lo < mn or (mn == lo and lo_closed)) and (mx < hi or (mx == hi and hi_closed))):
                    return None
            if angle:
                vals = [_radians(v) for v in vals]
            values[n] = vals[0] if one else tuple(vals)
        deck, stack = binder.deck, binder.stack
        for n, a, s, e in d.texts:           # Text.take of a STRING, written out
            values[n] = text[pos + s + 1:pos + e - 1]
        if d.ones:
            tpl = d.tpl[0]
            items = [None] * d.n_items
            for n, vt, a in d.ones:
                kind, s, e = tpl[a]
                items[a] = item_at(text, pos, line, kind, s, e)
                values[n] = _take_one(vt, items, a, binder)[0]
        locs = {}
        for k, item, o in d.clocs:
            locs[k] = _location(deck, raw, item, o, stack)
        rng = plan.call.range
        if rng is not None:
            rng = fill_range(rng, values, [_location(deck, raw, item, o, stack) for item, o in d.cwhere])
        lines = deck.source_lines
        loc = _new(SourceLocation)           # ParsedDeck.location of the line's first token, written out
        _set(loc, "__dict__", {"file": deck.filename, "line": line, "column": d.column,
                               "text": lines[line - 1] if 0 < line <= len(lines) else "", "length": d.length,
                               "stack": stack if type(stack) is tuple else tuple(stack)})
        # bind_plan.make_call, written out
        tcall = plan.call
        args = tcall.args.copy()
        for k, n in plan.holes:
            args[k] = values[n]
        if d.lists is not None:              # repeated keywords: a new list for every call
            get = values.__getitem__
            for k, ns in d.lists:
                args[k] = list(map(get, ns))
        else:
            for k in plan.lists:
                args[k] = fill_value(args[k], values)
        extra = {k: fill_value(v, values) for k, v in tcall.extra.items()} if tcall.extra else {}
        call = _new(type(tcall))
        _set(call, "__dict__", {"command": tcall.command, "args": args, "given": tcall.given, "range": rng,
                                "location": loc, "extra": extra, "locations": locs, "span": (lines, line, line)})
        cmd = tcall.command
        if cmd.check is not None:
            cmd.check(call)
    except Exception:
        return None
    return call


def _remember(binder, strs, vals) -> None:
    """The binder's table of numbers learns the values of the texts ``strs`` (emptied when it holds
    ``MAX_NUMBERS``); it is given up (None) when more than a third of the takes looked up there
    missed it, after the first ``MIN_LOOKS`` takes: a take that misses costs its look-ups, an exception
    and the insertions (twice what the hit of one saves), numbers that seldom come back are faster
    converted every time."""
    numbers = binder.numbers
    binder.missed += 1
    if binder.looked >= MIN_LOOKS and binder.missed * 3 > binder.looked:
        binder.numbers = None
        return
    if len(numbers) >= MAX_NUMBERS:
        numbers.clear()
    numbers.update(zip(strs, vals))


def _location(deck, raw, item, o, stack):
    """The location of the item (kind, start, end) of the line ``raw``, or of its o-th number."""
    pos = raw.pos
    if o is None:
        loc = _new(ItemLocation)
        loc.deck, loc.stack, loc.text, loc.pos, loc.line, loc.item = deck, stack, raw.text, pos, raw.line, item
        return loc
    loc = _new(RunLocation)
    loc.deck, loc.k, loc.stack = deck, o, stack
    loc.text, loc.start, loc.line, loc.line_start = raw.text[pos + item[1]:pos + item[2]], pos + item[1], raw.line, pos
    return loc


class ItemLocation(LazyLocation):
    """The location of an item of a line bound from its text: its token is made only when asked for."""

    __slots__ = ("text", "pos", "line", "item")

    @property
    def token(self):
        return item_at(self.text, self.pos, self.line, *self.item)
