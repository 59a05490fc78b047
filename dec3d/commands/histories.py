"""`block history`, `model history mechanical`, `history interval`, `history export`: sampled values.

Histories are sampled by the rigid engine every `history interval` steps (dec3d.physics.history);
`history export` writes a CSV under the output folder, a PNG per history beside it, and puts
`<name>.final|min|max|frequency` into the session's results (verification decks check them).
"""
from __future__ import annotations

import numpy as np

from ..errors import BindError, CommandError
from ..io.history import write_csv, write_png
from ..physics.history import (BLOCK_QUANTITIES, CONTACT_QUANTITIES, GRIDPOINT_QUANTITIES, MODEL_QUANTITIES,
                               POINT_QUANTITIES, RIGID_QUANTITIES, ROTATION_QUANTITIES, ZONE_QUANTITIES, figures,
                               histories)
from ..physics.history_lookup import nearest_block_id, nearest_gridpoint, zone_at
from ..model.model import KIND_DEFORMABLE, KIND_FE
from ..units import paren
from .registry import REGISTRY, command
from .values import NUMBERISH, VEC3, FLAG, Choice, Num, OutPath, P, Text, ValueType, _number_literal


class HistoryRefs(ValueType):
    """One or more histories, each by number or by quoted name (`1 2`, `'disp' 'ub'`)."""

    label = "<id|'name'>"
    fits_types = NUMBERISH + ("STRING",)

    def __init__(self, most: int = 10**6):
        self.most = most

    def take(self, toks, i, binder):
        out = []
        while i < len(toks) and len(out) < self.most and toks[i].type in self.fits_types:
            tok = toks[i]
            if tok.type in ("EXPR", "ATNAME"):
                out.append(binder.deferred(tok))
            else:
                out.append(str(tok)[1:-1] if tok.type == "STRING" else _number_literal(tok))
            i += 1
        if not out:
            raise BindError("expected a history number or name", binder.where(toks[min(i, len(toks) - 1)]))
        return (tuple(out) if self.most > 1 else out[0]), i

    def describe(self):
        return self.label + (" …" if self.most > 1 else "")


def _check_block(call):
    point = call.args.get("material_point")
    given = [k for k in ("position", "block_id", "gridpointid", "zone_id") if call.args.get(k) is not None]
    if call.args["position"] is not None and call.args["block_id"] is not None:
        raise BindError("give either `position <x y z>` or `block-id <i>`, not both", call.location)
    if len(given) > 1:
        word = "gridpointid" if "gridpointid" in given else "zone-id"
        what = "gridpoint" if word == "gridpointid" else "zone"
        if given == ["gridpointid", "zone_id"]:
            raise BindError("give `gridpointid <i>` or `zone-id <i>`, not both", call.location)
        raise BindError(f"`{word} <i>` names the {what} alone: give no `position` or `block-id` with it",
                        call.location)
    if given in (["gridpointid"], ["zone_id"]) and point is not None:
        raise BindError("`material-point` follows a point of a block, not a gridpoint or zone", call.location)
    if not given and point is None:
        raise BindError("give either `position <x y z>` or `block-id <i>`"
                        + (" (or `material-point <x y z>`)" if "material_point" in call.args else ""), call.location)


def _name(session, call):
    name = call.args.get("name")
    if name is not None and histories(session.model).find(name) is not None:
        raise CommandError(f"a history named '{name}' exists already", call.location)
    return name


def _block_history(quantity, kind="block"):
    def handler(session, call):
        m = session.model
        name = _name(session, call)
        point = call.args.get("material_point")
        if call.args.get("gridpointid") is not None:
            _gridpoint_history(session, call, quantity, name)
            return
        if call.args.get("zone_id") is not None:
            _zone_centroid_history(session, call, quantity, name)
            return
        if call.args["block_id"] is not None:
            bid = int(call.args["block_id"])
            if not (m.blocks["id"] == bid).any():
                raise CommandError(f"there is no block {bid}", call.locations.get("block_id", call.location))
        else:
            try:
                bid = nearest_block_id(m, call.args["position"] if call.args["position"] is not None else point)
            except ValueError as exc:
                raise CommandError(str(exc), call.location)
        row = int(np.flatnonzero(m.blocks["id"] == bid)[0])
        if (point is None and call.args["position"] is not None and quantity in GRIDPOINT_QUANTITIES
                and m.blocks["kind"][row] in (KIND_DEFORMABLE, KIND_FE)):
            # a zoned or FE block: the gridpoint of the nearest block nearest the point
            local = nearest_gridpoint(m, row, call.args["position"])
            histories(m).add_gridpoint(quantity, bid, local, name)
        elif point is not None:
            histories(m).add_point(quantity, bid, point, name)
        elif kind == "rigid":
            histories(m).add_rigid(quantity, bid, name)
        elif kind == "rotation":
            histories(m).add_rotation(quantity, bid, name)
        else:
            histories(m).add_block(quantity, bid, name)

    handler.__name__ = "block_history_" + quantity.replace("-", "_")
    return handler


def _motion_target(call, key: str, quantity: str, what: str):
    """(id, location) of the `key <i>` keyword of a gridpoint-quantity history, after checking
    that ``quantity`` is one (displacement, velocity or position) of a ``what``."""
    where = call.locations.get(key, call.location)
    if quantity not in GRIDPOINT_QUANTITIES:
        raise CommandError(f"`{quantity}` is not a {what} quantity (displacement, velocity or position)", where)
    return int(call.args[key]), where


def _gridpoint_history(session, call, quantity, name):
    """`block history <q> gridpointid <i>`: the gridpoint with id i (its vertex row + 1)."""
    m = session.model
    gid, where = _motion_target(call, "gridpointid", quantity, "gridpoint")
    v = m.vertices
    row = gid - 1
    if not (0 <= row < v.n) or "zoned" not in v or not v["zoned"][row]:
        raise CommandError(f"there is no gridpoint {gid} (gridpoints are the vertices of zoned blocks)", where)
    brow = int(v["block"][row])
    histories(m).add_gridpoint(quantity, int(m.blocks["id"][brow]), row - int(m.blocks["vert_start"][brow]), name)


def _zone_centroid_history(session, call, quantity, name):
    """`block history <q> zone-id <i>`: the value at the centroid of zone i, from its nodes."""
    m = session.model
    zid, where = _motion_target(call, "zone_id", quantity, "zone")
    z = m.stores.get("zones")
    if z is None or not z.n or not (z["id"] == zid).any():
        raise CommandError(f"there is no zone {zid}" + ("" if z is not None and z.n else
                                                           ": no block is zoned (`block zone generate`)"), where)
    histories(m).add_zone_centroid(quantity, zid, name)


_BLOCK_KW = [P("position", VEC3, "the block whose centroid is nearest this point", units="m"),
             P("block-id", Num(integer=True, lo=1), "the block with this id"),
             P("gridpointid", Num(integer=True), "a gridpoint of a zoned block by id (displacement, velocity, "
               "position)"),
             P("zone-id", Num(integer=True, lo=1), "a zone: the value at its centroid (displacement, velocity, "
               "position)")]
_POINT_KW = [P("material-point", VEC3, "follow the point fixed to the block that is here when the command runs "
                            "(a corner: its vertex)", units="m")]
_WHAT = {"displacement": "displacement", "velocity": "velocity", "rvelocity": "angular velocity",
         "position": "centroid position"}
_WHICH = ("The block is the one whose centroid is nearest `position` when the command runs, or the "
          "block `block-id`. A leading `name '<s>'` names the history (default: its number).")
_GP = (" When that block is zoned (deformable), `position` records the gridpoint of it nearest the point "
       "instead; `gridpointid <i>` names a gridpoint directly (its id is its vertex row + 1); `zone-id <i>` "
       "records the value at the centroid of zone i (its nodes weighted by the element's shape functions "
       "there: 1/4 each for a 4-node zone, -1/8 per corner and 1/4 per mid-edge node for a 10-node one).")
_POINT = (" With `material-point x y z` (dec3d) the value is that of the point fixed to the block that is at "
          "(x, y, z) when the command runs, instead of the centroid: its position now, its displacement "
          "since the block was made, its velocity v + ω × (p − c). Give a corner's coordinates to follow "
          "a vertex. `material-point` alone picks the block whose centroid is nearest the point; add `block-id` "
          "when the point is on several blocks.")

for _q in BLOCK_QUANTITIES:
    _what = _WHAT[_q.split("-")[0]]
    _comp = f"{_q[-1]} component of the" if "-" in _q else "magnitude of the"
    if _q.startswith("position"):
        _comp = f"{_q[-1]} coordinate of the" if "-" in _q else "distance from the origin of the"
    _pt = _q in POINT_QUANTITIES
    command(f"block history {_q}", keywords=_BLOCK_KW + (_POINT_KW if _pt else []), check=_check_block,
            doc=f"Record the {_comp} {_what} of one block every `history interval` steps.",
            details=_WHICH + (_GP if _q in GRIDPOINT_QUANTITIES else "")
            + ("" if _q.split("-")[0] in ("displacement", "velocity") else
                              " (dec3d: `rvelocity` and `position` are not 3DEC history variables.)")
            + (_POINT if _pt else ""),
            examples=[f"block history {_q} position 0.5 0.5 0.5", f"block history name 'h{_q[0]}' {_q} block-id 2"]
            + ([f"block history {_q} block-id 2 material-point 1 0 1"] if _pt else []),
            )(_block_history(_q))

for _q in ROTATION_QUANTITIES:
    _what = "angle θ [rad]" if _q == "rotation" else f"{_q[-1]} component θ n{_q[-1]} [rad] of the rotation vector"
    command(f"block history {_q}", keywords=_BLOCK_KW, check=_check_block,
            doc=f"Record the {_what} of one block's rotation since the block was made.",
            details=_WHICH + " dec3d only (not a 3DEC variable). The rotation R of the block since it was made "
                    "is the best (Kabsch) fit of its vertex arms now to its arms then (arms from the mean of "
                    "the vertices); it is written as the rotation vector θ n (axis n, angle θ, radians). "
                    "Each sample takes the equivalent vector (θ + 2πk) n nearest the previous sample, so a block "
                    "turning about a fixed axis at ω reads ω t also past half a turn (sample at least twice "
                    "per turn). `rotation` is the length of that vector.",
            examples=[f"block history {_q} block-id 2", f"block history name 'r' {_q} position 0.5 0.5 0.5"],
            )(_block_history(_q, kind="rotation"))

for _q in RIGID_QUANTITIES:
    if _q == "shape-error":
        _doc = ("Record how far the block's vertices are from a rigid motion: the largest distance [m] between "
                "a vertex arm (vertex − centroid) and the best-fit rotation of its arm when the history was made.")
    else:
        _doc = (f"Record the {_q[-1] + ' component' if '-' in _q else 'magnitude'} of the angular momentum "
                "I(t) ω [kg·m²/s] of one block about its centroid.")
    command(f"block history {_q}", keywords=_BLOCK_KW, check=_check_block, doc=_doc,
            details=_WHICH + " dec3d only (not a 3DEC variable): I(t) = R I₀ Rᵀ with I₀ the inertia tensor when "
                    "the history is made and R the best-fit (Kabsch) rotation of the vertex arms since then.",
            examples=[f"block history {_q} position 0.5 0.5 0.5"])(_block_history(_q, kind="rigid"))

REGISTRY.node_keywords("block contact history", [P("name", Text(), "history name")])
REGISTRY.node_keywords("block zone history", [P("name", Text(), "history name")])


def _check_zone(call):
    if (call.args["position"] is None) == (call.args["zone_id"] is None):
        raise BindError("give either `position <x y z>` or `zone-id <i>`", call.location)


def _zone_history(quantity):
    def handler(session, call):
        m = session.model
        name = _name(session, call)
        if call.args["zone_id"] is not None:
            zid = int(call.args["zone_id"])
            if "zones" not in m.stores or not (m.store("zones")["id"] == zid).any():
                raise CommandError(f"there is no zone {zid}", call.locations.get("zone_id", call.location))
        else:
            try:
                zid = zone_at(m, call.args["position"])
            except ValueError as exc:
                raise CommandError(str(exc), call.location)
        histories(m).add_zone(quantity, zid, name)

    handler.__name__ = "zone_history_" + quantity.replace("-", "_")
    return handler


for _q in ZONE_QUANTITIES:
    command(f"block zone history {_q}",
            keywords=[P("position", VEC3, "the zone containing this point (else the one whose centroid is nearest)",
                        units="m"),
                      P("zone-id", Num(integer=True, lo=1), "the zone with this id")],
            check=_check_zone,
            doc=f"Record the {_q[-2:]} stress [Pa, tension positive] of one zone every `history interval` steps.",
            details="The zone is the one containing `position` when the command runs (the first by number when "
                    "the point is on a face shared by several), or, when no zone contains it, the zone whose "
                    "centroid is nearest; or the zone `zone-id`. A leading `name '<s>'` names the history. The "
                    "value is NaN once the zone is gone.",
            examples=[f"block zone history {_q} position 0.5 0.5 0.5",
                      f"block zone history name 's' {_q} zone-id 12"])(_zone_history(_q))


def _contact_history(quantity):
    def handler(session, call):
        name = _name(session, call)
        histories(session.model).add_contact(quantity, call.args["position"], name)

    handler.__name__ = "contact_history_" + quantity.replace("-", "_")
    return handler


for _q in CONTACT_QUANTITIES:
    _fld, _how = CONTACT_QUANTITIES[_q]
    _doc = {"force-normal": "the normal force [N] (compression positive), summed over its sub-contacts",
            "force-shear": "the magnitude of the shear force [N] summed over its sub-contacts",
            "displacement-normal": "the mean normal displacement [m] of its sub-contacts (gap: positive)",
            "displacement-shear": "the magnitude of the mean accumulated shear displacement [m] of its sub-contacts",
            "pore-pressure": "its mean pore pressure [Pa]: the water force on it over its area (`block water`, "
                             "`block contact apply pore-pressure`)"
            }.get(_q, f"the {_q[-1]} component of the shear force [N] on the second block, summed over its sub-contacts")
    command(f"block contact history {_q}",
            keywords=[P("position", VEC3, "the contact whose centre is nearest this point", units="m", required=True),
                      P("contact-id", Num(integer=True), "a contact by id", supported=False)],
            doc=f"Record, for one contact, {_doc}.",
            details="The contact is the one whose centre is nearest `position` at the first sample; it is then "
                    "followed by its two blocks (0 when they separate). A leading `name '<s>'` names the history.",
            examples=[f"block contact history {_q} position 0.5 0.5 1", f"block contact history name 'c' {_q} position 0 0 0"],
            )(_contact_history(_q))


# other 3DEC history sources, known by name and not implemented yet
for _other in ("energy", "fluid", "thermal"):        # (`model history dynamic`: commands/model_dynamic.py)
    REGISTRY.know(f"model history {_other}")


@command("model history mechanical",
         positional=[P("quantity", Choice(MODEL_QUANTITIES), "what to record", required=True)],
         doc="Record the largest unbalanced force, a mechanical ratio, the total time or the kinetic energy.",
         details="A leading `name '<s>'` names the history (default: its number). `unbalanced-maximum`, `ratio`, "
                 "`ratio-average`, `ratio-local` and `ratio-maximum` are the measures `model solve` uses, with the "
                 "same definitions (see `model solve`).",
         examples=["model history mechanical unbalanced-maximum", "model history name 'ub' mechanical ratio"])
def model_history(session, call):
    name = _name(session, call)
    histories(session.model).add_model(call.args["quantity"], name)


@command("history interval", positional=[P("n", Num(integer=True, lo=1), "steps between samples", required=True)],
         doc="Sample the histories every n steps (default 10).",
         examples=["history interval 1"])
def history_interval(session, call):
    histories(session.model).interval = int(call.args["n"])


def _find(hs, key, call, slot):
    h = hs.find(key)
    if h is None and isinstance(key, str) and key.strip().isdigit():
        h = hs.find(int(key))
    if h is None:
        raise CommandError(f"there is no history {key}", call.locations.get(slot, call.location))
    return h


@command("history export",
         positional=[P("ids", HistoryRefs(), "history numbers or names", required=True)],
         keywords=[P("vs", HistoryRefs(1), "plot and tabulate against this history instead of time"),
                   P("file", OutPath(), "CSV file (in the output folder)", required=True),
                   P("truncate", FLAG, "replace the file if it exists (what dec3d always does: it writes the "
                     "whole table, with its header, at every export)", bare=True)],
         doc="Write the histories to a CSV file and a PNG plot per history; report their figures.",
         details="Each history's `<name>.final`, `.min`, `.max` and `.frequency` (Hz, from the zero crossings "
                 "of the value minus its mean) go into the session results. The plots are `<file>_<name>.png`.",
         examples=["history export 1 file 'disp.csv'", "history export 1 2 vs 3 file 'h.csv'",
                   "history export 'settle' file 'settle.csv'", "history export 1 2 file 'h.csv' truncate"])
def history_export(session, call):
    hs = histories(session.model)
    picked = []
    for i in call.args["ids"]:
        picked.append(_find(hs, i, call, "ids"))
    vs = None if call.args["vs"] is None else _find(hs, call.args["vs"], call, "vs")
    where = call.locations.get("file", call.location)
    path = session.out_path(call.args["file"], where)
    # every file is checked before any is written: a history name becomes part of a file name
    pngs = [session.out_path(path.with_name(f"{path.stem}_{_file_part(h.name)}.png"), where) for h in picked]
    write_csv(path, picked, vs)
    for h, png in zip(picked, pngs):
        write_png(png, h, vs, paren(session, "time"))
        for key, v in figures(h.times, h.values).items():
            session.results[f"{h.name}.{key}"] = v


def _file_part(name: str) -> str:
    """A history name as part of a file name: path separators and control characters become '_'."""
    return "".join("_" if (ch in "/\\" or not ch.isprintable()) else ch for ch in str(name)) or "_"


@command("history rename", positional=[P("old", HistoryRefs(1), "the history's number or name", required=True)],
         keywords=[P("name", Text(), "its new name", required=True)],
         doc="Give a history a new name (what `history export` and result figures use).",
         details="The history is found by name, else by number; a name another history has is refused.",
         examples=["history rename 'shearforce' name '5'", "history rename 1 name 'settle'"])
def history_rename(session, call):
    hs = histories(session.model)
    h = _find(hs, call.args["old"], call, "old")
    new = str(call.args["name"])
    if not new.strip():
        raise CommandError("a history name cannot be empty", call.locations.get("name", call.location))
    other = hs.find(new)
    if other is not None and other is not h:
        raise CommandError(f"a history named '{new}' exists already", call.locations.get("name", call.location))
    h.name = new


@command("history list", doc="Print every history: number, name, what it records and its number of samples.",
         examples=["history list"])
def history_list(session, call):
    hs = histories(session.model)
    if not hs.items:
        session.write("no histories")
    for h in hs.items:
        last = f", last {h.values[-1]:.6g} at step {h.steps[-1]}" if h.values else ""
        session.write(f"{h.id:4d}  '{h.name}'  {h.label}  ({len(h.values)} samples{last})")


@command("history name", positional=[P("history", HistoryRefs(1), "the history's name or number", required=True)],
         keywords=[P("label", Text(), "its new label (the CSV header and plot title)", required=True)],
         doc="Set the label of a history (what `history export` writes as its column header and plot title).",
         details="The history is found by name, else by number (a history's name is its number unless it was "
                 "given one).",
         examples=["history name '1' label 'Unbalanced Force'", "history name 3 label 'C2_MiddleSail'"])
def history_name(session, call):
    h = _find(histories(session.model), call.args["history"], call, "history")
    h.label = str(call.args["label"])


@command("history delete", positional=[P("ids", HistoryRefs(), "history numbers or names; omitted: every history")],
         doc="Delete histories (all of them when none is named) with their samples.",
         details="Histories made afterwards are numbered on from the last one left (from 1 when none is left).",
         examples=["history delete", "history delete 2 'settle'"])
def history_delete(session, call):
    hs = histories(session.model)
    ids = call.args["ids"]
    if not ids:
        hs.items.clear()
        return
    gone = {id(_find(hs, key, call, "ids")) for key in ids}
    hs.items[:] = [h for h in hs.items if id(h) not in gone]
