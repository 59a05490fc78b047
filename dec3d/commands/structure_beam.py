"""`structure beam …`: beam structural elements (3DEC's "Beam Structural Elements"; stores
``dec3d.model.beams``, physics ``dec3d.physics.beams``). Property names are 3DEC's (``young``,
``poisson``, ``cross-sectional-area``, ``moi-y``, ``moi-z``, ``moi-polar``, ``density``,
``direction-y``)."""
from __future__ import annotations

import numpy as np

from ..config import DENSITY_LIMIT, MODULUS_LIMIT
from ..errors import BindError, CommandError
from ..model.beams import BELEMS, BPROPS, add_beam, beam_stores, element_axes, has_beams, update_beam_masses
from ..physics.beam_history import BEAM_QUANTITIES, add_beam_history
from ..physics.history import histories
from ..units import paren
from .histories import _name
from .registry import REGISTRY, command
from .values import COORD, COORD_LIMIT, POINT, VEC3, Num, Nums, P, Text

_UNITS = {"young": "Pa", "poisson": "", "cross-sectional-area": "m²", "moi-y": "m⁴", "moi-z": "m⁴",
          "moi-polar": "m⁴", "density": "kg/m³"}
_DOCS = {"young": "Young's modulus", "poisson": "Poisson's ratio (shear modulus E / 2(1 + ν), torsion)",
         "cross-sectional-area": "cross-sectional area", "moi-y": "second moment of area about the element's y axis",
         "moi-z": "second moment of area about the element's z axis",
         "moi-polar": "polar moment of inertia (torsion constant J)", "density": "density (node masses, gravity)"}


def _check_create(call):
    if call.args["by_line"] is None:
        raise BindError("`structure beam create` needs `by-line x1 y1 z1 x2 y2 z2`", call.location)


@command("structure beam create",
         keywords=[P("by-line", Nums(6, 6, item=COORD), "the two ends of the beam: x1 y1 z1 x2 y2 z2", units="m"),
                   P("segments", Num(integer=True, lo=1, hi=100000), "number of elements", default=1),
                   P("id", Num(integer=True, lo=1), "beam id (default: the next free one)"),
                   P("group", Text(), "group of the new nodes and elements")],
         check=_check_create,
         doc="Create a beam of equal elements along a straight line; nodes inside a block are linked to it.",
         details="Each element is a 3-D Euler-Bernoulli beam (axial, torsion, bending about its y and z axes); "
                 "each node has 3 translations and 3 rotations. A node inside a visible rigid block (its boundary "
                 "counts) is linked to the block by stiff springs (translation and rotation); a node inside a zoned "
                 "or FE block follows the element that holds it (a 4-node zone by barycentric weights, a 10-node "
                 "zone or a 20-node brick by its shape functions) through a stiff translational spring (zones "
                 "have no rotation to link to); other nodes are free (hold them with `structure node fix velocity "
                 "rotation`). A node in a deformable block that none of its elements holds is refused. The "
                 "element's y axis is horizontal (global z × x; global y for "
                 "a vertical beam) unless `structure beam property direction-y` sets it.",
         examples=["structure beam create by-line 0 0 0 10 0 0 segments 20",
                   "structure beam create by-line 0 0 0 0 0 5 segments 10 id 2 group 'pile'"])
def beam_create(session, call):
    m = session.model
    x = [float(v) for v in call.args["by_line"]]
    p1, p2 = np.array(x[:3]), np.array(x[3:])
    where = call.locations.get("by_line", call.location)
    if np.linalg.norm(p2 - p1) <= 0:
        raise CommandError("the two ends of the beam are the same point", where)
    nodes, els = beam_stores(m)
    bid = call.args["id"]
    if bid is not None and np.any(els["beam"] == int(bid)):
        raise CommandError(f"there is a beam {int(bid)} already", call.locations.get("id", call.location))
    n0, s0 = nodes.n, els.n
    size = float(np.linalg.norm(p2 - p1))
    bid, hosts = add_beam(m, p1, p2, int(call.args["segments"]), bid, call.args["group"],
                          max(m.tolerance, 1e-9 * size))
    if (hosts <= -2).any():
        nodes.compact(np.arange(nodes.n) < n0)
        els.compact(np.arange(els.n) < s0)
        raise CommandError("a node of the beam lies in a deformable block but in none of its zones or FE "
                           "elements (is the block zoned or meshed?)", where)
    update_beam_masses(m)
    session.write(f"beam {bid}: {int(call.args['segments'])} elements, {int((hosts >= 0).sum())} of "
                  f"{len(hosts)} nodes linked to blocks")


def _prop_keywords():
    # the limits of blocks, zones and liners (beyond them node masses or stiffnesses were infinite)
    hi = {"young": MODULUS_LIMIT, "density": DENSITY_LIMIT}
    out = [P(name, Num(lo=0, hi=0.5, hi_open=True) if name == "poisson" else Num(lo=0, hi=hi.get(name, COORD_LIMIT)),
             _DOCS[name], units=_UNITS[name]) for name in BPROPS]
    return out + [P("direction-y", VEC3, "the elements' y axis (made normal to the element)")]


def _check_property(call):
    if not any(k.replace("-", "_") in call.given for k in BPROPS + ("direction-y",)):
        raise BindError("`structure beam property` needs one of: " + ", ".join(BPROPS + ("direction-y",)),
                        call.location)


def _need_beams(session, call):
    if not has_beams(session.model):
        raise CommandError("there is no beam: make one first (`structure beam create by-line …`)", call.location)


@command("structure beam property", keywords=_prop_keywords(), range=BELEMS, check=_check_property,
         doc="Set properties of the beam elements in range.",
         details="Negative values are refused (`poisson` in [0, 0.5)). `moi-y` and `moi-z` are the second "
                 "moments of area about the element's y and z axes, `moi-polar` the torsion constant. "
                 "`direction-y` sets the elements' y axis (its part normal to the element); a direction along "
                 "an element is refused.",
         examples=["structure beam property young 200e9 poisson 0.3 cross-sectional-area 1e-2 moi-y 1e-5 "
                   "moi-z 2e-5 moi-polar 3e-5 density 7800",
                   "structure beam property direction-y 0 0 1 range id 1"])
def beam_property(session, call):
    _need_beams(session, call)
    mask = session.range_mask(call, BELEMS)
    nodes, els = beam_stores(session.model)
    for col, name in enumerate(BPROPS):
        v = call.args[name.replace("-", "_")]
        if v is not None:
            els["prop"][mask, col] = float(v)
    yd = call.args["direction_y"]
    if yd is not None:
        y = np.array([float(v) for v in yd])
        for e in np.flatnonzero(mask):
            xa = els["axes"][e, 0]
            if np.linalg.norm(y - np.dot(y, xa) * xa) < 1e-9 * max(np.linalg.norm(y), 1e-300):
                raise CommandError(f"`direction-y` is along beam element {int(els['id'][e])}",
                                   call.locations.get("direction_y", call.location))
            els["ydir"][e] = y
            els["axes"][e] = element_axes(xa, y)
    update_beam_masses(session.model)


@command("structure beam list", range=BELEMS,
         doc="List the beam elements in range: nodes, axial force, torsion and bending moments at both ends.",
         details="Forces and moments are in the element's axes (x along it from its first node): axial force "
                 "(tension positive), torsion, moments about y and z at end 1 and end 2 as the nodes put them on "
                 "the element.",
         examples=["structure beam list"])
def beam_list(session, call):
    _need_beams(session, call)
    mask = session.range_mask(call, BELEMS)
    nodes, els = beam_stores(session.model)
    n, nm = paren(session, "force"), paren(session, "moment")
    session.write(f"    id  beam  node-1  node-2 {'axial' + n:>11} {'torsion' + nm:>14} {'M-y1' + nm:>11} "
                  f"{'M-z1' + nm:>11} {'M-y2' + nm:>11} {'M-z2' + nm:>11}")
    for e in np.flatnonzero(mask):
        f = els["fl"][e]
        session.write(f"{int(els['id'][e]):6d} {int(els['beam'][e]):5d} {int(nodes['id'][els['na'][e]]):7d} "
                      f"{int(nodes['id'][els['nb'][e]]):7d} {f[6]:11.4g} {f[9]:14.4g} {f[4]:11.4g} {f[5]:11.4g} "
                      f"{f[10]:11.4g} {f[11]:11.4g}")


# ------------------------------------------------------------------ histories
_WHICH = [P("component-id", Num(integer=True, lo=1), "id of the element"),
          P("position", POINT, "the element whose midpoint is nearest this point", units="m")]
REGISTRY.node_keywords("structure beam history", [P("name", Text(), "history name")])


def _check_hist(call):
    if (call.args["component_id"] is None) == (call.args["position"] is None):
        raise BindError("give either `component-id <i>` or `position <x y z>`", call.location)


def _handler(quantity):
    def handler(session, call):
        _need_beams(session, call)
        name = _name(session, call)
        if call.args["component_id"] is not None:
            ident = int(call.args["component_id"])
        else:
            _, els = beam_stores(session.model)
            d = np.linalg.norm(els["pos"] - np.asarray([float(x) for x in call.args["position"]]), axis=1)
            ident = int(els["id"][int(np.argmin(d))])
        try:
            add_beam_history(histories(session.model), quantity, ident, name)
        except CommandError as exc:
            raise exc.with_location(call.locations.get("component_id", call.location))
    return handler


_HDOC = {"force": "axial force (N, tension positive)", "moment-x": "torsion (N·m) at end 1",
         "moment-y": "bending moment about the element's y axis (N·m) at end 1",
         "moment-z": "bending moment about the element's z axis (N·m) at end 1"}
for _q in BEAM_QUANTITIES:
    command(f"structure beam history {_q}", keywords=_WHICH, check=_check_hist,
            doc=f"Record the {_HDOC[_q]} of a beam element.",
            details="The element is named by `component-id <i>` or by `position x y z` (nearest midpoint as "
                    "created). A leading `name '<s>'` names the history.",
            examples=[f"structure beam history {_q} component-id 1"])(_handler(_q))
