"""FISH state in save files: globals as plain JSON, functions as their source text (never pickle).

`to_state(rt)` gives a JSON-ready dict that `model save` puts under ``meta['extra']['fish']``;
`read_state(d)` checks it and parses every function again (raising ValueError naming what is
wrong, before anything changes); `apply_state(rt, snap, bind)` replaces the run time's globals,
functions, tables, callbacks and settings by the snapshot's, compiling the functions again.

Values: integers, floats, booleans, strings and null are JSON's own; a list is a JSON array; a
vector is ``{"vec": [x, y, z]}``, a map ``{"map": [[key, value], …]}``, a table reference
``{"table": id}``, a contact ``{"contact": [ida, idb]}``, a sub-contact ``{"subcontact": [ida, idb, k]}``.
Other values are refused when saving, naming the variable.
"""
from __future__ import annotations

import math
import re

from ..errors import Dec3dError
from .lexer import FishSource
from .syntax import parse_fish
from .values import MAX_LIST, MAX_STRING, Vec, type_name

FORMAT = 1
_NAME = re.compile(r"[a-z_][a-z0-9_]{0,127}\Z")
#: nesting of lists/maps kept in a save file
MAX_DEPTH = 64


class FishStateError(Dec3dError):
    """FISH values that cannot go into a save file."""


def encode(v, what: str, depth: int = 0):
    t = type(v)
    if depth > MAX_DEPTH:
        raise FishStateError(f"{what}: lists nested deeper than {MAX_DEPTH} cannot be saved")
    if t in (int, str, bool) or v is None:
        return v
    if t is float:
        if not math.isfinite(v):
            raise FishStateError(f"{what}: {v} is not a finite number")
        return v
    if t is Vec:
        return {"vec": [encode(c, what, depth + 1) for c in v]}
    if t is list:
        return [encode(x, what, depth + 1) for x in v]
    if t is dict:
        return {"map": [[encode(k, what, depth + 1), encode(x, what, depth + 1)] for k, x in v.items()]}
    from .contact_intrinsics import ContactPtr
    from .table_intrinsics import Table
    if t is Table:
        return {"table": v.id}
    if t is ContactPtr:
        return {v.kind: list(v.key)}
    raise FishStateError(f"{what}: a {type_name(v)} cannot be saved")


def decode(v, what: str, tables: dict, depth: int = 0):
    if depth > MAX_DEPTH:
        raise ValueError(f"{what}: nested deeper than {MAX_DEPTH}")
    t = type(v)
    if t in (int, bool) or v is None:
        return v
    if t is str:
        if len(v) > MAX_STRING:
            raise ValueError(f"{what}: a string longer than {MAX_STRING} characters")
        return v
    if t is float:
        if not math.isfinite(v):
            raise ValueError(f"{what}: {v} is not a finite number")
        return v
    if t is list:
        if len(v) > MAX_LIST:
            raise ValueError(f"{what}: a list longer than {MAX_LIST} items")
        return [decode(x, what, tables, depth + 1) for x in v]
    if t is dict and len(v) == 1:
        (tag, body), = v.items()
        if tag == "vec" and type(body) is list and len(body) == 3 and all(
                type(c) in (int, float) and math.isfinite(c) for c in body):
            return Vec(*body)
        if tag == "map" and type(body) is list:
            out = {}
            for kv in body:
                if not (type(kv) is list and len(kv) == 2 and type(kv[0]) in (int, float, str, bool)):
                    raise ValueError(f"{what}: a map entry is not a [key, value] pair with a plain key")
                out[kv[0]] = decode(kv[1], what, tables, depth + 1)
            return out
        if tag in ("contact", "subcontact") and type(body) is list and len(body) == (2 if tag == "contact" else 3) \
                and all(_int(x) for x in body):
            from .contact_intrinsics import ContactPtr
            return ContactPtr(tag, tuple(body))
        if tag == "table" and type(body) in (int, str):
            key = body.lower() if type(body) is str else body
            if key not in tables:
                raise ValueError(f"{what}: table {body!r} is not among the saved tables")
            return tables[key]
    raise ValueError(f"{what}: {str(v)[:60]!r} is not a FISH value")


def to_state(rt) -> dict:
    """The run time as plain JSON data (FishStateError names a value that cannot be saved)."""
    glob = {}
    for name in sorted(rt.globals):
        glob[name] = encode(rt.globals[name], f"FISH variable `{name}`")
    funcs = []
    for name in sorted(rt.functions):
        fn = rt.functions[name]
        src = fn.fdef.source
        loc = fn.location
        funcs.append({"name": fn.name, "params": list(fn.params), "file": src.filename,
                      "first_line": src.first_line, "lines": list(src.lines), "pos": list(fn.fdef.pos),
                      "header": loc.text if loc is not None else ""})
    tables = [{"id": t.id, "label": t.label, "x": list(t.xs), "y": list(t.ys)}
              for _k, t in sorted(rt.tables.items(), key=lambda kv: (type(kv[0]) is str, str(kv[0])))]
    callbacks = [{"function": name, "position": pos, "interval": interval}
                 for pos, name, interval, _site in rt.callbacks]
    return {"format": FORMAT, "auto_create": bool(rt.auto_create), "globals": glob, "functions": funcs,
            "tables": tables, "callbacks": callbacks}


class Snapshot:
    __slots__ = ("auto_create", "globals", "fdefs", "tables", "callbacks")


def _int(v) -> bool:
    return type(v) is int


def read_state(d) -> Snapshot:
    """Check a saved FISH state and parse its functions again; ValueError says what is wrong."""
    from .table_intrinsics import Table, add_points

    if type(d) is not dict or d.get("format") != FORMAT:
        raise ValueError("the FISH state has an unknown format")
    for k, t in (("auto_create", bool), ("globals", dict), ("functions", list), ("tables", list),
                 ("callbacks", list)):
        if type(d.get(k)) is not t:
            raise ValueError(f"the FISH state's `{k}` is missing or has the wrong type")
    snap = Snapshot()
    snap.auto_create = d["auto_create"]
    tables = {}
    for t in d["tables"]:
        if not (type(t) is dict and type(t.get("id")) in (int, str) and type(t.get("label")) is str
                and type(t.get("x")) is list and type(t.get("y")) is list and len(t["x"]) == len(t["y"])):
            raise ValueError("a saved FISH table is malformed")
        tab = Table(t["id"])
        tab.label = t["label"]
        try:
            add_points(tab, zip(t["x"], t["y"]))
        except Dec3dError as exc:
            raise ValueError(f"saved table {t['id']!r}: {exc.message}") from None
        tables[t["id"].lower() if type(t["id"]) is str else t["id"]] = tab
    snap.tables = tables
    glob = {}
    for name, v in d["globals"].items():
        if not _NAME.match(name):
            raise ValueError(f"{name[:40]!r} is not a FISH variable name")
        glob[name] = decode(v, f"FISH variable `{name}`", tables)
    snap.globals = glob
    fdefs = []
    for f in d["functions"]:
        if not (type(f) is dict and type(f.get("name")) is str and _NAME.match(f["name"])
                and type(f.get("params")) is list and all(type(p) is str and _NAME.match(p) for p in f["params"])
                and type(f.get("file")) is str and _int(f.get("first_line")) and f["first_line"] >= 1
                and type(f.get("lines")) is list and all(type(x) is str for x in f["lines"])
                and type(f.get("pos")) is list and len(f["pos"]) == 2 and all(_int(x) for x in f["pos"])
                and type(f.get("header")) is str):
            raise ValueError("a saved FISH function is malformed")
        src = FishSource(f["file"], f["first_line"], f["lines"])
        try:
            fdef = parse_fish(f["name"], tuple(f["params"]), src, tuple(f["pos"]))
        except Dec3dError as exc:
            raise ValueError(f"saved FISH function `{f['name']}` does not parse: {exc.message}") from None
        fdefs.append((fdef, f["header"]))
    snap.fdefs = fdefs
    cbs = []
    for c in d["callbacks"]:
        if not (type(c) is dict and type(c.get("function")) is str and type(c.get("position")) in (int, float)
                and math.isfinite(c["position"]) and _int(c.get("interval")) and c["interval"] >= 1):
            raise ValueError("a saved FISH callback is malformed")
        if c["function"] not in {fd.name for fd, _h in fdefs}:
            raise ValueError(f"saved FISH callback `{c['function']}` names no saved function")
        cbs.append((float(c["position"]), c["function"], c["interval"], None))
    snap.callbacks = cbs
    return snap


def apply_state(rt, snap: Snapshot, compile_one) -> None:
    """Replace the run time's FISH state by the snapshot's; `compile_one(fdef, header)` compiles a
    function (the session binds its command sections). Functions compile before anything changes."""
    auto = rt.auto_create
    rt.auto_create = True            # names were checked when the function was first defined
    try:
        fns = [compile_one(fdef, header) for fdef, header in snap.fdefs]
    finally:
        rt.auto_create = auto
    rt.clear()
    rt.globals.clear()
    rt.globals.update(snap.globals)
    for fn in fns:
        rt.define(fn)
    rt.tables.update(snap.tables)
    rt.callbacks.extend(snap.callbacks)
    rt.auto_create = snap.auto_create
