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
"""
from __future__ import annotations

from ..errors import LazyLocation, frozen_instance

# the shape of a non-word token: no word can be spelt with `<`
SHAPE_OF = {"NUMBER": "<n>", "STRING": "<s>", "EXPR": "<e>", "ATNAME": "<a>"}
#: plans kept per binder (a deck whose every line has its own words has no use for more)
MAX_PLANS = 4096


def shape(toks) -> tuple:
    """The line's shape: each word as written, each value by its type."""
    kinds = SHAPE_OF
    return tuple([t.value if t.type == "WORD" else kinds[t.type] for t in toks])


class Slot:
    """The hole a recorded take leaves in a plan's call: the n-th value taken."""

    __slots__ = ("n",)

    def __init__(self, n: int):
        self.n = n


class Plan:
    """A bound call with holes; the takes that fill them (param, first token, end); token indices
    of the locations it holds (by the identity of the recorded line's tokens)."""

    __slots__ = ("call", "steps", "holes", "lists", "locs", "where")

    def __init__(self, call, steps, toks):
        self.call = call
        self.steps = tuple(steps)
        self.holes = tuple((k, v.n) for k, v in call.args.items() if type(v) is Slot)
        self.lists = tuple(k for k, v in call.args.items() if type(v) is list)
        ids = {id(t): k for k, t in enumerate(toks)}
        self.locs = tuple((k, ids[id(loc.token)]) for k, loc in call.locations.items())
        self.where = {}
        if call.range is not None:
            for e in call.range.elements:
                self.where[id(e.location)] = ids[id(e.location.token)]


def fill_value(v, values):
    if type(v) is Slot:
        return values[v.n]
    if type(v) is list:                   # a repeated keyword: a new list for every call
        return [values[x.n] if type(x) is Slot else x for x in v]
    return v


def fill(plan: Plan, values, toks, deck, stack):
    """The plan's call with the holes filled from ``values`` and the locations on ``toks`` (the
    classes are the recorded call's own)."""
    tpl = plan.call
    args = tpl.args.copy()                # the keys in the order binding gave them
    for k, n in plan.holes:
        args[k] = values[n]
    for k in plan.lists:                  # a repeated keyword: a new list for every call
        args[k] = fill_value(args[k], values)
    extra = {k: fill_value(v, values) for k, v in tpl.extra.items()} if tpl.extra else {}
    locs = {k: LazyLocation(deck, toks[i], stack) for k, i in plan.locs}
    rng = tpl.range
    if rng is not None:
        where = plan.where
        one = type(rng.elements[0])
        rng = type(rng)(tuple(one(e.element, {k: fill_value(v, values) for k, v in e.args.items()}, e.negate,
                                  LazyLocation(deck, toks[where[id(e.location)]], stack))
                              for e in rng.elements), rng.union)
    first = toks[0]
    return frozen_instance(type(tpl), {"command": tpl.command, "args": args, "given": tpl.given, "range": rng,
                                       "location": deck.location(first, stack), "extra": extra, "locations": locs,
                                       "span": (deck.source_lines, first.line, toks[-1].line)})
