"""`block apply`, `block apply-remove`: applied velocity, angular velocity, force and moment of rigid blocks.

The values live in the block store (``dec3d.model.model``):

- ``velocity`` / ``spin`` take an applied (angular) velocity component, and the component's bit is set
  in ``apply_fix`` (bits 0-2 velocity x, y, z; bits 3-5 rotation x, y, z, as ``fixity``); the engine
  holds a component whose bit is set in ``fixity | apply_fix``;
- ``fapp`` [N] and ``mapp`` [N·m] hold the applied force and moment. Applying a force or moment ADDS it to
  what is applied already, as 3DEC's applied loads do (``block face apply`` documents the pitfall and decks
  remove the old load first with ``apply-remove``). Applying a velocity sets it.

Time functions (``table <id>``, ``fish <name>``) are recognised and refused at bind time.
"""
from __future__ import annotations

import numpy as np

from ..errors import BindError, NotSupportedError
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
    out.append(P("table", _TIMEFN, "time function: multiply the value by table <id> (not supported yet)"))
    out.append(P("fish", _TIMEFN, "time function: multiply the value by FISH function <s> (not supported yet)"))
    return out


def _check_apply(call):
    for tf in ("table", "fish"):
        if call.args.get(tf) is not None:
            raise NotSupportedError(f"`block apply … {tf} <…>`: time functions ({tf}) are not supported yet",
                                    call.locations.get(tf, call.location),
                                    hint="apply a constant value, or change it between `model cycle` commands")
    if not any(k.replace("-", "_") in call.given for k in _KEYS):
        raise BindError("`block apply` needs one of: " + ", ".join(_KEYS), call.location)


@command("block apply", keywords=_apply_keywords(), range="block", check=_check_apply,
         doc="Apply a velocity, angular velocity, force or moment to the rigid blocks in range.",
         details="`velocity`, `rvelocity`, `force` and `moment` take a vector (3 numbers); the `-x`, `-y`, `-z` "
                 "forms take one component. An applied velocity (angular velocity) sets the component and holds "
                 "it during cycling, like `block fix`, until `block apply-remove`. An applied force or moment is "
                 "ADDED to the force or moment already applied to the block (as in 3DEC, where applied loads "
                 "accumulate): remove the old one first with `block apply-remove force` to replace it. "
                 "Forces act at the centroid. Time functions (`table <id>`, `fish <name>`) are not supported yet.",
         examples=["block apply velocity-x 0.1 range position-z 1 2",
                   "block apply force-z -1e6 range id 2",
                   "block apply rvelocity 0 0 0.5",
                   "block apply moment 0 0 1e3 range group 'top'"])
def block_apply(session, call):
    mask = session.range_mask(call, "block")
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
    for kw in call.given:                          # in the order written
        kw = kw.replace("_", "-")
        if kw not in vals:
            continue
        kind, comp = _KEYS[kw]
        comps = range(3) if comp is None else (comp,)
        vec = vals[kw]
        for j, i in enumerate(comps):
            x = vec[j] if comp is None else vec[0]
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
    for kw in picked:
        kind, comp = _KEYS[kw]
        for i in (range(3) if comp is None else (comp,)):
            if kind == "velocity":
                b["apply_fix"][mask] &= np.uint8(~(1 << i) & 0xFF)
            elif kind == "rvelocity":
                b["apply_fix"][mask] &= np.uint8(~(8 << i) & 0xFF)
            elif kind == "force":
                b["fapp"][mask, i] = 0.0
            else:
                b["mapp"][mask, i] = 0.0
