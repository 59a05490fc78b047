"""`structure hybrid …`: hybrid bolts (3DEC's rock bolt: a grouted cable plus a dowel shear spring at
every joint the bolt crosses). The cable part is an ordinary cable (``structure cable …`` reaches it
too); the dowels are ``dec3d.model.dowels``, their physics ``dec3d.physics.dowels``."""
from __future__ import annotations

import numpy as np

from ..errors import BindError, CommandError
from ..model.cables import PROPS, SEGMENTS, cable_stores, update_masses
from ..model.dowels import DOWELS, DPROPS, add_dowels, dowel_store, has_dowels
from ..units import paren
from .registry import REGISTRY, command
from .structure_cable import _DOCS, _UNITS, cable_create
from .values import COORD, POINT, Num, Nums, P, Text

_DDOCS = {"dowel-stiffness": "shear stiffness of the dowel at each joint crossing",
          "dowel-yield": "shear force at which the dowel yields (0: no limit)",
          "dowel-rupture": "shear displacement across the joint at which the dowel breaks (0: never)"}
_DUNITS = {"dowel-stiffness": "N/m", "dowel-yield": "N", "dowel-rupture": "m"}


def _check_create(call):
    if call.args["by_line"] is None:
        raise BindError("`structure hybrid create` needs `by-line x1 y1 z1 x2 y2 z2`", call.location)


@command("structure hybrid create",
         keywords=[P("by-line", Nums(6, 6, item=COORD), "the two ends of the bolt: x1 y1 z1 x2 y2 z2", units="m"),
                   P("segments", Num(integer=True, lo=1, hi=100000), "number of cable elements", default=1),
                   P("id", Num(integer=True, lo=1), "bolt (cable) id (default: the next free one)"),
                   P("group", Text(), "group of the new nodes, elements and dowels")],
         check=_check_create,
         doc="Create a hybrid bolt: a grouted cable along a straight line plus a dowel at each joint it crosses.",
         details="The cable part is made as `structure cable create by-line` makes it (same refusals: a bolt "
                 "in no block). Where the line leaves one block into another across their common face, a dowel "
                 "shear spring joins the two blocks at the crossing point (rigid blocks through their motion, "
                 "zoned blocks through the gridpoints of the zone there). Give the dowels their properties with "
                 "`structure hybrid property dowel-stiffness … dowel-yield … dowel-rupture …`.",
         examples=["structure hybrid create by-line 0 0 0 0 0 -4 segments 8",
                   "structure hybrid create by-line 1 0 2 1 0 -2 segments 10 id 5 group 'bolts'"])
def hybrid_create(session, call):
    m = session.model
    nodes, segs = cable_stores(m)
    s0 = segs.n
    cable_create(session, call)
    x = [float(v) for v in call.args["by_line"]]
    rows = np.arange(s0, segs.n)
    cid = int(segs["cable"][rows[0]])
    size = float(np.linalg.norm(np.subtract(x[3:], x[:3])))
    n, bad = add_dowels(m, cid, x[:3], x[3:], rows, max(m.tolerance, 1e-9 * size), call.args["group"])
    if bad:
        n0 = int(segs["na"][rows[0]])
        nodes.compact(np.arange(nodes.n) < n0)
        segs.compact(np.arange(segs.n) < s0)
        update_masses(m)
        raise CommandError(bad, call.locations.get("by_line", call.location))
    session.write(f"hybrid bolt {cid}: {n} dowel(s) at joint crossings")


def _prop_keywords():
    out = []
    for name in PROPS:
        v = Num(angle=True, lo=0, hi=90, hi_open=True) if name == "grout-friction" else Num(lo=0)
        out.append(P(name, v, _DOCS[name], units=_UNITS[name]))
    for name in DPROPS:
        out.append(P(name, Num(lo=0), _DDOCS[name], units=_DUNITS[name]))
    return out


def _check_property(call):
    if not any(k.replace("-", "_") in call.given for k in PROPS + DPROPS):
        raise BindError("`structure hybrid property` needs one of: " + ", ".join(PROPS + DPROPS), call.location)


@command("structure hybrid property", keywords=_prop_keywords(), range=SEGMENTS, check=_check_property,
         doc="Set the cable and dowel properties of the hybrid bolt elements in range.",
         details="The cable properties are those of `structure cable property`; the dowel properties go to the "
                 "dowels whose crossing lies in an element in range. Negative values are refused. A dowel "
                 "resists the shear displacement of the two blocks across the bolt with `dowel-stiffness` "
                 "until the shear force reaches `dowel-yield` (then it holds that force), and carries nothing "
                 "once the shear displacement reaches `dowel-rupture`.",
         examples=["structure hybrid property young 200e9 cross-sectional-area 5e-4 grout-stiffness 1e8 "
                   "grout-cohesion 2e5",
                   "structure hybrid property dowel-stiffness 5e7 dowel-yield 1e5 dowel-rupture 0.05"])
def hybrid_property(session, call):
    m = session.model
    if not has_dowels(m) and not (SEGMENTS in m.stores and m.stores[SEGMENTS].n):
        raise CommandError("there is no hybrid bolt: make one first (`structure hybrid create by-line …`)",
                           call.location)
    mask = session.range_mask(call, SEGMENTS)
    _, segs = cable_stores(m)
    for col, name in enumerate(PROPS):
        v = call.args[name.replace("-", "_")]
        if v is not None:
            segs["prop"][mask, col] = float(v)
    st = dowel_store(m)
    on = mask[st["seg"]] if st.n else np.zeros(0, bool)
    for col, name in enumerate(DPROPS):
        v = call.args[name.replace("-", "_")]
        if v is not None:
            st["prop"][on, col] = float(v)
    update_masses(m)


@command("structure hybrid list",
         doc="List the dowels of the hybrid bolts: blocks, shear force, shear displacement, state.",
         details="State words: yield (yielding now), yielded (in the past), ruptured.",
         examples=["structure hybrid list"])
def hybrid_list(session, call):
    m = session.model
    if not has_dowels(m):
        session.write("no dowels")
        return
    st = m.stores[DOWELS]
    bid = m.blocks["id"]
    session.write(f"    id  bolt  block-a  block-b {'shear force' + paren(m, 'force'):>16} "
                  f"{'shear disp' + paren(m, 'length'):>15}  state")
    for i in range(st.n):
        s = int(st["state"][i])
        words = [w for bit, w in ((1, "yield"), (2, "yielded"), (4, "ruptured")) if s & bit]
        session.write(f"{int(st['id'][i]):6d} {int(st['cable'][i]):5d} {int(bid[st['blk'][i, 0]]):8d} "
                      f"{int(bid[st['blk'][i, 1]]):8d} {np.linalg.norm(st['fs'][i]):16.5g} "
                      f"{np.linalg.norm(st['us'][i]):15.5g}  {' '.join(words) or '-'}")


# ------------------------------------------------------------------ histories
REGISTRY.node_keywords("structure hybrid history", [P("name", Text(), "history name")])


def _check_hist(call):
    if (call.args["component_id"] is None) == (call.args["position"] is None):
        raise BindError("give either `component-id <i>` or `position <x y z>`", call.location)


def _hist_handler(quantity):
    def handler(session, call):
        from ..physics.dowels import add_dowel_history
        from ..physics.history import histories
        from .histories import _name

        m = session.model
        if not has_dowels(m):
            raise CommandError("there is no dowel: make a hybrid bolt across a joint first", call.location)
        name = _name(session, call)
        st = m.stores[DOWELS]
        if call.args["component_id"] is not None:
            ident = int(call.args["component_id"])
        else:
            d = np.linalg.norm(st["pos"] - np.asarray([float(x) for x in call.args["position"]]), axis=1)
            ident = int(st["id"][int(np.argmin(d))])
        try:
            add_dowel_history(histories(m), quantity, ident, name)
        except CommandError as exc:
            raise exc.with_location(call.locations.get("component_id", call.location))
    return handler


for _q, _what in (("shear-force", "shear force (N)"), ("shear-displacement", "shear displacement (m)")):
    command(f"structure hybrid history {_q}",
            keywords=[P("component-id", Num(integer=True, lo=1), "id of the dowel (as `structure hybrid list` shows)"),
                      P("position", POINT, "the dowel nearest this point", units="m")],
            check=_check_hist, doc=f"Record the {_what} of a hybrid bolt's dowel (its magnitude).",
            details="The dowel is named by `component-id <i>` or by `position x y z` (the nearest dowel point). "
                    "A leading `name '<s>'` names the history.",
            examples=[f"structure hybrid history {_q} component-id 1"])(_hist_handler(_q))
