"""Range elements over the geometry stores: position, plane, cylinder, sphere, group, id.

Each element is a declaration plus a thin call of the pure mask function of the same
name in ``dec3d.model.ranges`` (which documents the semantics). Blocks are located by
their centroid, faces by their area centroid, gridpoints/vertices by their position; a
store added later is located by its ``centroid`` or ``pos`` field. A store without what
an element needs gives a clear error when the command runs.
`not` and `union` are handled by the binder and ``Session.range_mask``.
"""
from __future__ import annotations

from ..errors import CommandError
from ..model import ranges as R
from .registry import range_element
from .values import ANGLE, FLAG, FLOAT, VEC3, Nums, Num, P, Text

def _run(fn, session, store, **kw):
    try:
        return fn(session.model, store, **kw)
    except (KeyError, ValueError) as exc:
        msg = exc.args[0] if exc.args else str(exc)
        raise CommandError(str(msg)) from None


@range_element("position", positional=[P("corners", Nums(3, 6, counts=(3, 6)),
                                          "two corners x1 y1 z1 x2 y2 z2 of a box (or one point)",
                                          required=True)],
               doc="inside the axis-aligned box between two corners (bounds included)")
def position(session, store, args):
    c = args["corners"]
    lo, hi = (c[:3], c[3:]) if len(c) == 6 else (c, c)
    return _run(R.mask_position, session, store, lower=lo, upper=hi)


def _axis(name: str, fn, axis: str):
    @range_element(name, positional=[P("bounds", Nums(1, 2), f"{axis} or {axis}1 {axis}2", required=True)],
                   doc=f"{axis} in [{axis}1, {axis}2], or at {axis} within the tolerance")
    def element(session, store, args):
        b = args["bounds"]
        return _run(fn, session, store, a=b[0], b=b[1] if len(b) > 1 else None)
    return element


position_x = _axis("position-x", R.mask_position_x, "x")
position_y = _axis("position-y", R.mask_position_y, "y")
position_z = _axis("position-z", R.mask_position_z, "z")


@range_element("plane", keywords=[P("origin", VEC3, "a point of the plane", default=(0.0, 0.0, 0.0)),
                                  P("dip", ANGLE, "dip, degrees"),
                                  P("dip-direction", ANGLE, "dip direction, degrees clockwise from +y"),
                                  P("normal", VEC3, "normal vector (instead of dip and dip-direction)"),
                                  P("above", FLAG, "on the side the normal points to", bare=True),
                                  P("below", FLAG, "on the other side", bare=True),
                                  P("distance", Num(lo=0), "within this distance of the plane")],
               doc="on one side of a plane (`above`/`below`), or near it (`distance`)")
def plane(session, store, args):
    if args["above"] and args["below"]:
        raise CommandError("range element `plane`: give `above` or `below`, not both")
    if args["dip"] is None and args["normal"] is None:
        raise CommandError("range element `plane` needs `dip` (and `dip-direction`) or `normal`")
    side = "above" if args["above"] else "below" if args["below"] else None
    return _run(R.mask_plane, session, store, side=side, origin=args["origin"], dip=args["dip"],
                dip_direction=args["dip_direction"], normal=args["normal"], distance=args["distance"])


@range_element("cylinder", keywords=[P("end-1", VEC3, "centre of one end", required=True),
                                     P("end-2", VEC3, "centre of the other end", required=True),
                                     P("radius", Nums(1, 2), "radius, or inner and outer radii", required=True)],
               doc="inside a cylinder (or the annulus between two radii)")
def cylinder(session, store, args):
    r = args["radius"]
    return _run(R.mask_cylinder, session, store, end1=args["end_1"], end2=args["end_2"], radius=r[0],
                radius2=r[1] if len(r) > 1 else None)


@range_element("sphere", keywords=[P("centre", VEC3, "centre of the sphere"),
                                   P("center", VEC3, "same as centre"),
                                   P("radius", FLOAT, "radius", required=True)],
               doc="inside a sphere")
def sphere(session, store, args):
    c = args["centre"] if args["centre"] is not None else args["center"]
    if c is None:
        raise CommandError("range element `sphere` needs `centre`")
    return _run(R.mask_sphere, session, store, centre=c, radius=args["radius"])


@range_element("group", positional=[P("name", Text(), "group name", required=True)],
               keywords=[P("slot", Text(), "only this slot (default: any slot)"),
                         P("or", Text(), "another group name", repeat=True)],
               doc="in the group (or any of the `or` groups)")
def group(session, store, args):
    return _run(R.mask_group, session, store, names=[args["name"], *args["or"]], slot=args["slot"])


@range_element("group-intersection", positional=[P("first", Text(), "group name", required=True),
                                                 P("second", Text(), "group name", required=True)],
               keywords=[P("slot", Text(), "only groups of this slot (default: any slot)")],
               doc="in both groups (contacts: between a block of one and a block of the other)")
def group_intersection(session, store, args):
    return _run(R.mask_group_intersection, session, store, a=args["first"], b=args["second"], slot=args["slot"])


@range_element("id", positional=[P("id", Num(integer=True), "id", required=True)],
               doc="the entity with this id")
def id_(session, store, args):
    return _run(R.mask_id, session, store, id=args["id"])


@range_element("id-list", positional=[P("ids", Nums(1, 10**6, item=Num(integer=True)), "ids", required=True)],
               doc="the entities with these ids")
def id_list(session, store, args):
    return _run(R.mask_id_list, session, store, ids=args["ids"])


@range_element("region", positional=[P("region", Num(integer=True), "3DEC 5 region number", required=True)],
               doc="blocks created with this region number (`r=<i>`; 0 when none was given), and their "
                   "faces, vertices and gridpoints")
def region(session, store, args):
    return _run(R.mask_region, session, store, region=args["region"])
