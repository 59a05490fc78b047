"""`block cut joint-set` and `block tolerance`."""
from __future__ import annotations

from ..geometry.cutting import cut_joint_set, joint_set_estimate
from ..model.model import KIND_RIGID
from .budget import check_blocks
from .registry import command
from .values import ANGLE, FLAG, LENGTH, POINT, Num, P


@command("block cut joint-set",
         keywords=[P("dip", ANGLE, "dip of the joints, degrees down from horizontal", default=0.0),
                   P("dip-direction", ANGLE, "dip direction, degrees clockwise from +y (north)", default=0.0),
                   P("origin", POINT, "a point on the first joint", default=(0.0, 0.0, 0.0), units="m"),
                   P("spacing", LENGTH, "distance between joints (none: one joint)", units="m"),
                   P("number", Num(integer=True, lo=1), "number of joints, from the origin along the normal"),
                   P("join", FLAG, "join the pieces of each block (one rigid body)", bare=True),
                   P("persistence", Num(lo=0, hi=1), "fraction of blocks cut", supported=False),
                   P("jointset-id", Num(integer=True), "id of the joint set", supported=False)],
         range="block",
         doc="Cut the visible blocks in range by a set of parallel joints.",
         details="The joints' upward normal is (sin δ sin α, sin δ cos α, cos δ) for dip δ and dip direction "
                 "α (z up). Without `spacing` there is one joint through the origin; with `spacing` and no "
                 "`number` the set fills every block in range. Hidden blocks are not cut. Cuts are exact: "
                 "pieces are convex, their volumes add up to the parent's, the two sides of a joint share "
                 "their corners, and a joint closer than the tolerance (`block tolerance`) to a corner "
                 "passes through it rather than leaving a sliver. The lowest piece of a block keeps its id; "
                 "the others take new ids and copy its properties and groups.",
         examples=["block cut joint-set dip 90 dip-direction 90 origin 0.3230 0 0",
                   "block cut joint-set dip 72 dip-direction 90 spacing 0.9 origin (15,3,2) range position-y 3.1 22",
                   "block cut joint-set dip 0 spacing 0.5 number 3 join"])
def block_cut_joint_set(session, call):
    a = call.args
    mask = session.range_mask(call, "block")
    new = joint_set_estimate(session.model, a["dip"], a["dip_direction"], origin=a["origin"], spacing=a["spacing"],
                             number=a["number"], mask=mask)
    check_blocks(session, new, "this joint set", call.location)
    made = cut_joint_set(session.model, a["dip"], a["dip_direction"], origin=a["origin"], spacing=a["spacing"],
                         number=a["number"], mask=mask, join=bool(a["join"]),
                         keep_whole=session.model.blocks["kind"] != KIND_RIGID)
    session.results["blocks_made"] = float(made)


@command("block tolerance",
         positional=[P("tolerance", Num(lo=0, lo_open=True), "geometric tolerance", required=True, units="m")],
         keywords=[P("angle", Num(), "angle tolerance", supported=False),
                   P("edge", Num(), "edge tolerance", supported=False),
                   P("gap", Num(), "gap tolerance", supported=False),
                   P("planarity", Num(), "planarity tolerance", supported=False)],
         doc="Set the geometric tolerance used by cutting, shape checks and ranges.",
         details="Points closer than the tolerance are one point, a face whose corners stray from its plane by "
                 "more is not planar, a joint closer than it to a corner passes through the corner, and "
                 "range bounds are widened by it. Default 1e-6 m.",
         examples=["block tolerance 1e-5"])
def block_tolerance(session, call):
    session.model.tolerance = float(call.args["tolerance"])
