"""`structure cable …` and `structure node …`: grouted cable structural elements on rigid blocks
(3DEC's "Cable Structural Elements"; stores ``dec3d.model.cables``, physics ``dec3d.physics.cables``).

Property names and command words are 3DEC's (``structure cable create by-line``, ``structure cable
property young … grout-cohesion …``, ``structure cable apply tension value``, ``structure node fix
velocity-x``, ``structure node initialize velocity``, ``structure node apply force``).
"""
from __future__ import annotations

import numpy as np

from ..config import DENSITY_LIMIT, MODULUS_LIMIT, STIFFNESS_LIMIT
from ..errors import BindError, CommandError
from ..model.cables import NODES, PROPS, SEGMENTS, add_cable, cable_stores, has_cables, update_masses
from ..units import paren
from .registry import command
from .values import COORD, COORD_LIMIT, FLAG, ONOFF, VEC3, Num, Nums, P, Text

_NONNEG = Num(lo=0)
#: the limits of blocks, zones and liners (a modulus, stiffness, density or size beyond them made node
#: masses or stiffnesses infinite); strengths stay unlimited
_BOUNDED = {"young": Num(lo=0, hi=MODULUS_LIMIT), "cross-sectional-area": Num(lo=0, hi=COORD_LIMIT),
            "grout-stiffness": Num(lo=0, hi=STIFFNESS_LIMIT), "grout-perimeter": Num(lo=0, hi=COORD_LIMIT),
            "density": Num(lo=0, hi=DENSITY_LIMIT)}
_UNITS = {"young": "Pa", "cross-sectional-area": "m²", "yield-tension": "N", "yield-compression": "N",
          "grout-stiffness": "N/m/m", "grout-cohesion": "N/m", "grout-friction": "°", "grout-perimeter": "m",
          "density": "kg/m³", "tensile-failure-strain": "-"}
_DOCS = {"young": "Young's modulus of the cable", "cross-sectional-area": "cross-sectional area",
         "yield-tension": "tensile yield force (0: no limit)", "yield-compression": "compressive yield force, "
         "given positive (0: no limit)", "grout-stiffness": "grout shear stiffness per length of cable",
         "grout-cohesion": "grout cohesive strength per length of cable",
         "grout-friction": "grout friction angle", "grout-perimeter": "grout exposed perimeter",
         "density": "density of the cable (its nodes' mass, gravity)",
         "tensile-failure-strain": "axial strain at which an element ruptures (0: never)"}


def _check_create(call):
    if call.args["by_line"] is None:
        raise BindError("`structure cable create` needs `by-line x1 y1 z1 x2 y2 z2`", call.location)


@command("structure cable create",
         keywords=[P("by-line", Nums(6, 6, item=COORD), "the two ends of the cable: x1 y1 z1 x2 y2 z2", units="m"),
                   P("segments", Num(integer=True, lo=1, hi=100000), "number of elements", default=1),
                   P("id", Num(integer=True, lo=1), "cable id (default: the next free one)"),
                   P("group", Text(), "group of the new nodes and elements")],
         check=_check_create,
         doc="Create a cable of equal elements along a straight line; each node is grouted to the block it lies in.",
         details="The nodes lie at the ends and at the segment boundaries; a node inside a rigid block (on its "
                 "boundary counts) is attached to it by the grout, a node outside every block is free (ungrouted). "
                 "In a deformable block the node follows the element that holds it: a 4-node zone (its gridpoints, "
                 "by barycentric weights), a 10-node zone or an FE block's 20-node brick (its nodes, by the shape "
                 "functions at the node); the grout's reaction goes to those nodes by the same weights and the "
                 "grout is confined by that element's stress. A cable with no node in any block is refused, and "
                 "so is a node in a deformable block that no zone or element of it holds. A block zoned (or meshed) "
                 "later takes its cable nodes and dowels onto the zones or elements holding them; a cut through "
                 "a zoned block is refused (cut first).",
         examples=["structure cable create by-line 0 0 0 0 0 -10 segments 20",
                   "structure cable create by-line 0 0 0 5 0 0 segments 10 id 2 group 'bolts'"])
def cable_create(session, call):
    m = session.model
    x = [float(v) for v in call.args["by_line"]]
    p1, p2 = np.array(x[:3]), np.array(x[3:])
    where = call.locations.get("by_line", call.location)
    if np.linalg.norm(p2 - p1) <= 0:
        raise CommandError("the two ends of the cable are the same point", where)
    nodes, segs = cable_stores(m)
    cid = call.args["id"]
    if cid is not None and (np.any(nodes["cable"] == int(cid))):
        raise CommandError(f"there is a cable {int(cid)} already", call.locations.get("id", call.location))
    size = float(np.linalg.norm(p2 - p1))
    tol = max(m.tolerance, 1e-9 * size)
    n0, s0 = nodes.n, segs.n
    cid, hosts = add_cable(m, p1, p2, int(call.args["segments"]), cid, call.args["group"], tol)
    bad = None
    if (hosts <= -2).any():
        bad = ("a node of the cable lies in a deformable block but in none of its zones or FE elements (is "
               "the block zoned or meshed?)")
    elif not (hosts >= 0).any():
        bad = ("the cable lies in no block: none of its nodes is inside a visible block (a rigid one, or a zone "
               "of a zoned one)")
    if bad:
        keep_n = np.arange(nodes.n) < n0
        keep_s = np.arange(segs.n) < s0
        nodes.compact(keep_n)
        segs.compact(keep_s)
        raise CommandError(bad, where)
    update_masses(m)
    session.write(f"cable {cid}: {int(call.args['segments'])} elements, "
                  f"{int((hosts >= 0).sum())} of {len(hosts)} nodes grouted")


def _prop_keywords():
    out = []
    for name in PROPS:
        v = Num(angle=True, lo=0, hi=90, hi_open=True) if name == "grout-friction" else _BOUNDED.get(name, _NONNEG)
        out.append(P(name, v, _DOCS[name], units=_UNITS[name]))
    return out


def _need_cables(session, call):
    if not has_cables(session.model):
        raise CommandError("there is no cable: make one first (`structure cable create by-line …`)", call.location)


def _check_property(call):
    if not any(k.replace("-", "_") in call.given for k in PROPS):
        raise BindError("`structure cable property` needs one of: " + ", ".join(PROPS), call.location)


@command("structure cable property", keywords=_prop_keywords(), range=SEGMENTS, check=_check_property,
         doc="Set properties of the cable elements in range.",
         details="Negative values are refused. `grout-friction` is in degrees. `yield-tension` and "
                 "`yield-compression` of 0 (the default) mean no limit. The grout strength per length is "
                 "`grout-cohesion` + σ_m tan(`grout-friction`) `grout-perimeter`; on rigid blocks σ_m is 0 "
                 "(they carry no stress), so the cohesion alone bounds it there. An element whose axial strain "
                 "(L − L0) / L0 (L0: its length as created) goes past `tensile-failure-strain` ruptures: from "
                 "then on it carries no axial force and no grout force, for good (`structure cable list` shows "
                 "it as ruptured; 0, the default, means it never ruptures). The name is Itasca's rockbolt "
                 "property; here it is the total axial strain that counts, yielded or not.",
         examples=["structure cable property young 200e9 cross-sectional-area 5e-4 yield-tension 2.5e5",
                   "structure cable property tensile-failure-strain 0.1",
                   "structure cable property grout-stiffness 1e8 grout-cohesion 2e5 range id 1"])
def cable_property(session, call):
    _need_cables(session, call)
    mask = session.range_mask(call, SEGMENTS)
    _, segs = cable_stores(session.model)
    for col, name in enumerate(PROPS):
        v = call.args[name.replace("-", "_")]
        if v is not None:
            segs["prop"][mask, col] = float(v)
    update_masses(session.model)


@command("structure cable apply tension", keywords=[P("value", Num(), "axial tension held in the elements", units="N"),
                                                    P("active", ONOFF, "hold the tension (on) or let it evolve (off)")],
         range=SEGMENTS,
         doc="Hold an axial tension in the cable elements in range (pre-tension); `active off` lets it evolve again.",
         details="As 3DEC's `structure cable apply tension`: the elements in range keep the given axial force "
                 "whatever their stretch, until `active off`; from then on the force evolves from where it was. "
                 "Meant for the (ungrouted) end elements of a bolt.",
         examples=["structure cable apply tension value 1e5 range id 1", "structure cable apply tension active off"])
def cable_apply_tension(session, call):
    _need_cables(session, call)
    mask = session.range_mask(call, SEGMENTS)
    _, segs = cable_stores(session.model)
    if call.args["value"] is not None:
        segs["tapp"][mask] = float(call.args["value"])
        segs["tact"][mask] = 1
    if call.args["active"] is not None:
        segs["tact"][mask] = 1 if call.args["active"] else 0


@command("structure cable list", range=SEGMENTS,
         doc="List the cable elements in range: nodes, axial force, grout forces, yield state.",
         details="State words: yield-t / yield-c (yielding in tension / compression now), slip (grout slipping "
                 "now at an end), yielded, slipped (in the past), ruptured (broken at its "
                 "`tensile-failure-strain`: it carries nothing).",
         examples=["structure cable list", "structure cable list range id-list 1 2 3"])
def cable_list(session, call):
    _need_cables(session, call)
    mask = session.range_mask(call, SEGMENTS)
    nodes, segs = cable_stores(session.model)
    n = paren(session, "force")
    session.write(f"    id  cable  node-a  node-b {'axial' + n:>11} {'grout-a' + n:>12} {'grout-b' + n:>12}  state")
    for e in np.flatnonzero(mask):
        st = int(segs["state"][e])
        words = [w for bit, w in ((1, "yield-t"), (2, "yield-c"), (4, "slip"), (8, "yielded"), (16, "slipped"),
                                                   (32, "ruptured"))
                 if st & bit]
        session.write(f"{int(segs['id'][e]):6d} {int(segs['cable'][e]):6d} {int(nodes['id'][segs['na'][e]]):7d} "
                      f"{int(nodes['id'][segs['nb'][e]]):7d} {segs['fa'][e]:11.4g} {segs['gf'][e, 0]:12.4g} "
                      f"{segs['gf'][e, 1]:12.4g}  {' '.join(words) or '-'}")


# ------------------------------------------------------------------ nodes (cables' and beams')
_FIX = {"velocity": 7, "velocity-x": 1, "velocity-y": 2, "velocity-z": 4,
        "rotation": 56, "rotation-x": 8, "rotation-y": 16, "rotation-z": 32}
_FIXKW = [P(k, FLAG, f"the {k} component(s)" + (" (beam and liner nodes)" if k.startswith("rot") else ""), bare=True)
          for k in _FIX]


def _bits(call) -> int:
    bits = 0
    for k, v in _FIX.items():
        if call.args[k.replace("-", "_")]:
            bits |= v
    return bits or 7


def _node_stores(session, call):
    """[(store, range mask)] of the cable, beam and liner nodes (one id space, ``model.beams.next_node_id``)."""
    m = session.model
    out = [(m.stores[n], session.range_mask(call, n)) for n in (NODES, "beam_nodes", "liner_nodes")
           if n in m.stores and m.stores[n].n]
    if not out:
        raise CommandError("there is no structural node: make a cable, a beam or a liner first (`structure cable "
                           "create by-line …`, `structure beam create by-line …`, `structure liner create …`)",
                           call.location)
    return out


@command("structure node fix", keywords=_FIXKW, range=NODES,
         doc="Hold velocity (and, on beam and liner nodes, rotational velocity) components of the structural "
             "nodes in range (the three velocities when none is named).",
         details="`rotation`, `rotation-x|y|z` hold the rotational velocity of beam and liner nodes (cable nodes "
                 "have none). Cable, beam and liner nodes share one id space.",
         examples=["structure node fix velocity range id 1", "structure node fix velocity rotation range id 1"])
def node_fix(session, call):
    for st, mask in _node_stores(session, call):
        st["fix"][mask] |= np.uint8(_bits(call))


@command("structure node free", keywords=_FIXKW, range=NODES,
         doc="Free velocity (and rotational velocity) components of the structural nodes in range (the three "
             "velocities when none is named).",
         examples=["structure node free velocity-x", "structure node free rotation"])
def node_free(session, call):
    for st, mask in _node_stores(session, call):
        st["fix"][mask] &= np.uint8(~_bits(call) & 0xFF)


_VKW = [P("velocity", VEC3, "velocity", units="m/s")] + [P(f"velocity-{a}", Num(), f"{a} component of the velocity",
                                                          units="m/s") for a in "xyz"]


@command("structure node initialize", keywords=_VKW, range=NODES,
         doc="Set the velocity of the structural nodes in range (fix the component too to hold it).",
         examples=["structure node initialize velocity-x -1e-5 range id 1"])
def node_initialize(session, call):
    for st, mask in _node_stores(session, call):
        _set_vector(st["vel"], mask, call, "velocity")


@command("structure node apply", keywords=[P("force", VEC3, "applied force", units="N")] +
         [P(f"force-{a}", Num(), f"{a} component of the applied force", units="N") for a in "xyz"] +
         [P("moment", VEC3, "applied moment (beam and liner nodes)", units="N·m")] +
         [P(f"moment-{a}", Num(), f"{a} component of the applied moment (beam and liner nodes)", units="N·m")
          for a in "xyz"],
         range=NODES,
         doc="Set the applied force (and, on beam and liner nodes, moment) of the structural nodes in range (it "
             "replaces the one applied before).",
         examples=["structure node apply force-x 1e4 range id 1", "structure node apply moment-y 500 range id 11"])
def node_apply(session, call):
    for st, mask in _node_stores(session, call):
        _set_vector(st["fapp"], mask, call, "force")
        if "mapp" in st.fields:
            _set_vector(st["mapp"], mask, call, "moment")


def _set_vector(arr, mask, call, name):
    v = call.args[name]
    if v is not None:
        arr[mask] = np.asarray([float(x) for x in v])
    for i, a in enumerate("xyz"):
        c = call.args[f"{name}_{a}"]
        if c is not None:
            arr[mask, i] = float(c)
