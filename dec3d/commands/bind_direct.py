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
from .bind_plan import RunLocation, fill_range, make_call
from .values import ValueType

_take_one = ValueType.take
_new, _set = object.__new__, object.__setattr__
_radians = math.radians
#: the most digits before the point for which a take's bounds are told by its key (10**15 is exact)
_STATIC_DIGITS = 15
_GAP = frozenset(" \t\f,")


class Direct:
    """A plan's replay on the text of the lines of one key: the stretch ``rs:re`` of the line split
    into pieces; per take of numbers (value number, first piece, end piece); ``simple``: tuples of
    numbers known within bounds, ``other``: (n, p0, p1, bounds or None, pieces of negative integers,
    angle, one value); ``ones``: (n, value type, item) takes of one token; ``need``: items made as
    tokens (for ``ones`` and locations); locations as ``Plan.clocs`` and ``Plan.cwhere``."""

    __slots__ = ("plan", "tpl", "rs", "re", "simple", "other", "ones", "need", "n_items", "clocs", "cwhere",
                 "column", "length")


def make_direct(plan, raw) -> Direct | None:
    """The direct replay of ``plan`` on lines of the key of ``raw`` (a ``KeyLine``), or None when the
    plan takes something other than numbers, whole tokens and runs split by blanks and commas."""
    if plan.compact is None:
        return None
    tpl, key = raw.tpl[0], raw.key
    if key is None or len(tpl) == 0:
        return None
    used = set()                         # items whose numbers are taken
    steps = []                           # (n, segments, inline, one)
    for st in plan.compact:
        if st[0]:
            continue
        _, n, segs, inline, one = st
        for a, o0, _ in segs:
            if tpl[a][0] != ("NUMBER" if o0 is None else "NUMRUN"):
                return None              # `[ ]` or `@name` among the numbers
            used.add(a)
        steps.append((n, segs, inline, one))
    if plan.batch is not None:
        inline, takes = plan.batch
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
            if kind == "NUMRUN" and cnt != len(_NUMBER_IN_RUN.findall(text)) or kind in ("NUMBER", "WORD") and cnt != 1:
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
            if idx != list(range(p0, p1)) or not all(_NUMBER_IN_RUN.fullmatch(q) for q in pieces[p0:p1]):
                return None
            lo, lo_closed, hi, hi_closed, angle = inline
            negint = tuple(k for k in range(p0, p1) if pieces[k][0] == "-" and not any(c in pieces[k] for c in ".eE"))
            bounds = None if _within(pieces[p0:p1], inline) else (lo, lo_closed, hi, hi_closed)
            if bounds is None and not negint and not angle and not one:
                d.simple.append((n, p0, p1))
            else:
                d.other.append((n, p0, p1, bounds, negint, angle, one))
    else:
        d.rs = d.re = 0
    d.simple, d.other = tuple(d.simple), tuple(d.other)
    d.ones = tuple((st[1], st[2].value, st[3]) for st in plan.compact if st[0])
    d.clocs, d.cwhere = plan.clocs, plan.cwhere
    d.need = tuple(sorted({a for _, _, a in d.ones} | {a for _, a, o in d.clocs if o is None}
                          | {a for a, o in (d.cwhere or {}).values() if o is None}))
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
        for n, p0, p1 in d.simple:
            values[n] = tuple(map(float, pieces[p0:p1]))
        for n, p0, p1, bounds, negint, angle, one in d.other:
            vals = list(map(float, pieces[p0:p1]))
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
        tpl = d.tpl[0]
        items = None
        if d.need:
            items = [None] * d.n_items
            for a in d.need:
                kind, s, e = tpl[a]
                items[a] = item_at(text, pos, line, kind, s, e)
            for n, vt, a in d.ones:
                values[n] = _take_one(vt, items, a, binder)[0]
        locs = {k: LazyLocation(deck, items[a], stack) if o is None else _run_location(deck, raw, tpl[a], o, stack)
                for k, a, o in d.clocs}
        rng = plan.call.range
        if rng is not None:
            where = d.cwhere
            rng = fill_range(rng, values, [LazyLocation(deck, items[a], stack) if o is None
                                           else _run_location(deck, raw, tpl[a], o, stack)
                                           for a, o in (where[id(e.location)] for e in rng.elements)])
        lines = deck.source_lines
        loc = _new(SourceLocation)           # ParsedDeck.location of the line's first token, written out
        _set(loc, "__dict__", {"file": deck.filename, "line": line, "column": d.column,
                               "text": lines[line - 1] if 0 < line <= len(lines) else "", "length": d.length,
                               "stack": stack if type(stack) is tuple else tuple(stack)})
        call = make_call(plan, values, locs, rng, loc, (lines, line, line))
        cmd = call.command
        if cmd.check is not None:
            cmd.check(call)
    except Exception:
        return None
    return call


def _run_location(deck, raw, item, k, stack) -> RunLocation:
    """``RunLocation`` of the k-th number of the run at ``item`` (kind, start, end) of the line ``raw``."""
    pos = raw.pos
    loc = _new(RunLocation)
    loc.deck, loc.k, loc.stack = deck, k, stack
    loc.text, loc.start, loc.line, loc.line_start = raw.text[pos + item[1]:pos + item[2]], pos + item[1], raw.line, pos
    return loc
