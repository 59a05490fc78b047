"""`block apply`, `block apply-remove`: applied velocity, angular velocity, force and moment of rigid blocks.

The values live in the block store (``dec3d.model.model``):

- ``velocity`` / ``spin`` take an applied (angular) velocity component, and the component's bit is set
  in ``apply_fix`` (bits 0-2 velocity x, y, z; bits 3-5 rotation x, y, z, as ``fixity``); the engine
  holds a component whose bit is set in ``fixity | apply_fix``;
- ``fapp`` [N] and ``mapp`` [N·m] hold the applied force and moment. Applying a force or moment ADDS it to
  what is applied already, as 3DEC's applied loads do (``block face apply`` documents the pitfall and decks
  remove the old load first with ``apply-remove``). Applying a velocity sets it.

Time functions (``table <id>``, ``fish <name>``): the value is multiplied by table(t) (linear
interpolation, end values held outside) or by the FISH function's value at the time of each step
(the dynamic time in dynamic mode, else the model's time); they are kept in the mechanical settings
and set by a step of the cycle (``dec3d.physics.dynamic.TimeFunctions``).
"""
from __future__ import annotations

import numpy as np

from ..errors import BindError, CommandError
from ..physics.dynamic import add_timefn, load_time, remove_timefns, timefn_factor
from .registry import command
from .values import FLAG, VEC3, Num, P, Text

#: keyword -> (kind, component or None for the vector form)
_KINDS = ("velocity", "rvelocity", "force", "moment")
_KEYS = {f"{k}{s}": (k, c) for k in _KINDS for s, c in (("", None), ("-x", 0), ("-y", 1), ("-z", 2))}
_UNITS = {"velocity": "m/s", "rvelocity": "rad/s", "force": "N", "moment": "N·m"}
_WHAT = {"velocity": "velocity", "rvelocity": "angular velocity", "force": "force", "moment": "moment"}
_TIMEFN = Text(label="<i|s>", fits_types=("NUMBER", "WORD", "STRING", "EXPR", "ATNAME"))


def _apply_keywords():
    out = []
    for kw, (kind, comp) in _KEYS.items():
        what = _WHAT[kind] if comp is None else f"{'xyz'[comp]} component of the {_WHAT[kind]}"
        out.append(P(kw, VEC3 if comp is None else Num(), f"applied {what}", units=_UNITS[kind]))
    out.append(P("table", _TIMEFN, "time function: multiply the value by table <id> at the current time"))
    out.append(P("fish", _TIMEFN, "time function: multiply the value by FISH function <s> at the current time"))
    return out


def check_timefn(call):
    """Bind-time rule shared with `block gridpoint apply`: table and fish exclude each other."""
    if call.args.get("table") is not None and call.args.get("fish") is not None:
        raise BindError("give a time function as `table <id>` or `fish <name>`, not both",
                        call.locations.get("fish", call.location))


def timefn_source(session, call):
    """(table id or None, FISH function name or None) of a time function, checked to exist now; CommandError
    (at the keyword's position) otherwise."""
    table, fish = call.args.get("table"), call.args.get("fish")
    if table is None and fish is None:
        return None, None
    rt = session.fish_rt
    if table is not None:
        where = call.locations.get("table", call.location)
        tid = table
        if isinstance(tid, str):
            try:
                tid = int(tid)
            except ValueError:
                pass
        key = tid.lower() if isinstance(tid, str) else tid
        tab = rt.tables.get(key)
        if tab is None:
            raise CommandError(f"there is no table {tid}: make it first (`table {tid} add …` or "
                               f"`table {tid} import '<file>'`)", where)
        if not tab.xs:
            raise CommandError(f"table {tid} has no points", where)
        return key, None
    where = call.locations.get("fish", call.location)
    name = str(fish).lstrip("@")
    if name.lower() in rt.functions:
        name = name.lower()
    elif name not in rt.functions:
        raise CommandError(f"there is no FISH function `{name}` (define it with `fish define {name}` first)", where)
    return None, name


def where_text(call) -> str:
    """file:line:column of the command, kept with a time function for errors while cycling."""
    loc = call.location
    return str(loc.resolve() if hasattr(loc, "resolve") else loc)


def _check_apply(call):
    check_timefn(call)
    if not any(k.replace("-", "_") in call.given for k in _KEYS):
        raise BindError("`block apply` needs one of: " + ", ".join(_KEYS), call.location)


@command("block apply", keywords=_apply_keywords(), range="block", check=_check_apply,
         doc="Apply a velocity, angular velocity, force or moment to the rigid blocks in range.",
         details="`velocity`, `rvelocity`, `force` and `moment` take a vector (3 numbers); the `-x`, `-y`, `-z` "
                 "forms take one component. An applied velocity (angular velocity) sets the component and holds "
                 "it during cycling, like `block fix`, until `block apply-remove`. An applied force or moment is "
                 "ADDED to the force or moment already applied to the block (as in 3DEC, where applied loads "
                 "accumulate): remove the old one first with `block apply-remove force` to replace it. "
                 "Forces act at the centroid. With `table <id>` or `fish <name>` the value is multiplied, at every "
                 "step, by the table at the current time (linear interpolation, end values held outside) or by "
                 "the value the FISH function returns then; the time is the dynamic time in dynamic mode, else "
                 "the model's time; a velocity is taken at the middle of the step, a force at its start. A time "
                 "function's velocity replaces the one applied before; its force adds to the applied force.",
         examples=["block apply velocity-x 0.1 range position-z 1 2",
                   "block apply force-z -1e6 range id 2",
                   "block apply rvelocity 0 0 0.5",
                   "block apply moment 0 0 1e3 range group 'top'",
                   "block apply velocity-x 1 table 1 range id 1",
                   "block apply force-z -1e3 fish pulse range id 2"])
def block_apply(session, call):
    mask = session.range_mask(call, "block")
    table, fish = timefn_source(session, call)
    b = session.model.blocks
    vals = {}
    for kw, (kind, comp) in _KEYS.items():       # validate (deferred values are numbers by now) before changing
        v = call.args[kw.replace("-", "_")]
        if v is None:
            continue
        vec = np.asarray(v, dtype=float).reshape(-1)
        if not np.isfinite(vec).all():
            raise BindError(f"`{kw}` must be finite", call.locations.get(kw.replace("-", "_"), call.location))
        vals[kw] = vec
    m = session.model
    ids = b["id"][mask]
    if table is not None or fish is not None:
        from .fish_cmds import attach_fish

        attach_fish(session)
    for kw in call.given:                          # in the order written
        kw = kw.replace("_", "-")
        if kw not in vals:
            continue
        kind, comp = _KEYS[kw]
        comps = range(3) if comp is None else (comp,)
        vec = vals[kw]
        for j, i in enumerate(comps):
            x = vec[j] if comp is None else vec[0]
            if table is not None or fish is not None:
                add_timefn(m, "block", kind, i, x, ids, table=table, fish=fish, where=where_text(call))
                if kind in ("velocity", "rvelocity"):
                    e = m.settings.mechanical["timefns"][-1]
                    x = x * timefn_factor(m, e, load_time(m))
                    b["velocity" if kind == "velocity" else "spin"][mask, i] = x
                    b["apply_fix"][mask] |= np.uint8((1 if kind == "velocity" else 8) << i)
                continue
            if kind in ("velocity", "rvelocity"):
                remove_timefns(m, "block", ids, {(kind, i)})
            if kind == "velocity":
                b["velocity"][mask, i] = x
                b["apply_fix"][mask] |= np.uint8(1 << i)
            elif kind == "rvelocity":
                b["spin"][mask, i] = x
                b["apply_fix"][mask] |= np.uint8(8 << i)
            elif kind == "force":
                b["fapp"][mask, i] += x
            else:
                b["mapp"][mask, i] += x


_REMOVE_KW = [P(k, FLAG, f"remove the applied {_WHAT[kind] if c is None else 'xyz'[c] + ' ' + _WHAT[kind]}"
                + ("" if c is None else " component"))
              for k, (kind, c) in _KEYS.items()]


@command("block apply-remove", keywords=_REMOVE_KW, range="block",
         doc="Remove applied velocities, angular velocities, forces or moments from the blocks in range.",
         details="Without a keyword everything applied by `block apply` is removed; with one, that kind (or that "
                 "component) only. A block whose applied velocity is removed keeps its current velocity and "
                 "moves freely from then on (unless `block fix` holds it).",
         examples=["block apply-remove", "block apply-remove force range position-z 1 2",
                   "block apply-remove velocity-x"])
def block_apply_remove(session, call):
    mask = session.range_mask(call, "block")
    b = session.model.blocks
    picked = [k for k in _KEYS if call.args[k.replace("-", "_")]] or [k for k in _KINDS]
    ids = b["id"][mask]
    for kw in picked:
        kind, comp = _KEYS[kw]
        for i in (range(3) if comp is None else (comp,)):
            remove_timefns(session.model, "block", ids, {(kind, i)})
            if kind == "velocity":
                b["apply_fix"][mask] &= np.uint8(~(1 << i) & 0xFF)
            elif kind == "rvelocity":
                b["apply_fix"][mask] &= np.uint8(~(8 << i) & 0xFF)
            elif kind == "force":
                b["fapp"][mask, i] = 0.0
            else:
                b["mapp"][mask, i] = 0.0
