"""FISH tables (basics): `table.get`, `table.label`, `table(t, x) = y`, `table(t, x)`, `table.size`.

A table is a list of (x, y) points kept sorted by x, named by an integer or string id
(Itasca FISH: `table.get(id)` returns the table, creating it when absent; assigning
`table(t, x) = y` adds the point, replacing one at the same x; reading `table(t, x)`
interpolates linearly between the neighbouring points, holding the end values outside).
Tables live on the FISH run time of the session; the `table` command (dec3d.commands.fish_cmds)
adds, imports, lists and deletes them. `table.x(t, i)` / `table.y(t, i)` read point i (from 1).
"""
from __future__ import annotations

from bisect import bisect_left

from .intrinsics import intrinsic, setter
from .values import MAX_LIST, FishValueError, to_string, type_name


class Table:
    __slots__ = ("id", "label", "xs", "ys")

    def __init__(self, tid):
        self.id, self.label, self.xs, self.ys = tid, "", [], []

    def __repr__(self):
        return f"table {to_string(self.id)}"


def table_key(t):
    """The key a table id is kept under: names are case-insensitive."""
    return t.lower() if type(t) is str else t


def add_points(tab: Table, points) -> None:
    """Add (x, y) points, keeping x increasing; a point at an x already there replaces its y."""
    for x, y in points:
        x, y = _num(x, "a table x"), _num(y, "a table y")
        if x - x or y - y:
            raise FishValueError("a table point must be finite")
        k = bisect_left(tab.xs, x)
        if k < len(tab.xs) and tab.xs[k] == x:
            tab.ys[k] = y
            continue
        if len(tab.xs) >= MAX_LIST:
            raise FishValueError(f"a table with more than {MAX_LIST} points")
        tab.xs.insert(k, x)
        tab.ys.insert(k, y)


def _tables(rt) -> dict:
    t = getattr(rt, "tables", None)
    if t is None:
        t = rt.tables = {}
    return t


def _table(rt, t, name) -> Table:
    if isinstance(t, Table):
        return t
    if type(t) not in (int, str):
        raise FishValueError(f"`{name}` takes a table or its id (integer or string), not a {type_name(t)}")
    tables = _tables(rt)
    key = t.lower() if type(t) is str else t
    if key not in tables:
        raise FishValueError(f"`{name}`: there is no table {to_string(t)}")
    return tables[key]


def _num(v, what):
    if type(v) is not int and type(v) is not float:
        raise FishValueError(f"{what} must be a number, not a {type_name(v)}")
    return float(v)


@intrinsic("table.get", 1)
def _table_get(rt, t):
    if type(t) not in (int, str):
        raise FishValueError(f"`table.get` takes an id (integer or string), not a {type_name(t)}")
    tables = _tables(rt)
    key = t.lower() if type(t) is str else t
    if key not in tables:
        tables[key] = Table(t)
    return tables[key]


@setter("table.label")
def _set_label(rt, t, value):
    if type(value) is not str:
        raise FishValueError(f"a table label is a string, not a {type_name(value)}")
    _table(rt, t, "table.label").label = value


@intrinsic("table.label", 1)
def _get_label(rt, t):
    return _table(rt, t, "table.label").label


@intrinsic("table.size", 1)
def _table_size(rt, t):
    return len(_table(rt, t, "table.size").xs)


@setter("table")
def _set_point(rt, t, x, y):
    tab = t if isinstance(t, Table) else _table_get(rt, t)
    add_points(tab, [(x, y)])


def _point(rt, t, i, name):
    tab = _table(rt, t, name)
    if type(i) is not int:
        raise FishValueError(f"`{name}`: the point index must be an integer, not a {type_name(i)}")
    if not 1 <= i <= len(tab.xs):
        raise FishValueError(f"`{name}`: point {i} is out of range 1..{len(tab.xs)}")
    return tab, i - 1


@intrinsic("table.x", 2)
def _table_x(rt, t, i):
    tab, k = _point(rt, t, i, "table.x")
    return tab.xs[k]


@intrinsic("table.y", 2)
def _table_y(rt, t, i):
    tab, k = _point(rt, t, i, "table.y")
    return tab.ys[k]


@intrinsic("table", 2)
def _get_point(rt, t, x):
    tab = _table(rt, t, "table")
    x = _num(x, "a table x")
    xs, ys = tab.xs, tab.ys
    if not xs:
        raise FishValueError(f"table {to_string(tab.id)} has no points")
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    k = bisect_left(xs, x)
    x0, x1, y0, y1 = xs[k - 1], xs[k], ys[k - 1], ys[k]
    return y0 + (y1 - y0) * (x - x0) / (x1 - x0)
