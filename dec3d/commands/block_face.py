"""`block face group` and `block face triangulate`."""
from __future__ import annotations

import numpy as np

from ..errors import BindError
from ..geometry.triangulate import triangulate_blocks
from ..model.blocks import group_faces
from .registry import command
from .values import FLAG, Num, P, Text


@command("block face group", positional=[P("name", Text(), "group name", required=True)],
         keywords=[P("slot", Text(), "group slot (default 'Default')"),
                   P("remove", FLAG, "take the faces out of the group instead", bare=True)],
         range="face",
         doc="Put the block faces in range in a group (faces are located by their area centroid).",
         examples=["block face group 'base' range position-z 0", "block face group 'east' slot 'bc' range pos-x 10"])
def block_face_group(session, call):
    a = call.args
    group_faces(session.model, session.range_mask(call, "face"), a["name"], a["slot"], remove=bool(a["remove"]))


@command("block face triangulate",
         keywords=[P("radial", FLAG, "a fan of triangles around each face's centroid", bare=True),
                   P("radial-8", FLAG, "as radial, with the edge mid-points (8 triangles on a quadrilateral)", bare=True),
                   P("edge-max", Num(lo=0, lo_open=True), "radial, then halved until no edge is longer",
                     units="m")],
         range="block",
         doc="Split the faces of the blocks in range into triangles (more sub-contacts on rigid blocks).",
         details="Give one of `radial`, `radial-8` or `edge-max <f>`. Mid-points are shared by the faces "
                 "on an edge, so the surface stays closed. The shape, volume and mass properties do not "
                 "change; triangles keep the groups of their face.",
         examples=["block face triangulate radial-8", "block face triangulate radial range group 'arch'",
                   "block face triangulate edge-max 0.5"])
def block_face_triangulate(session, call):
    a = call.args
    modes = [m for m, on in (("radial", a["radial"]), ("radial-8", a["radial_8"]),
                             ("edge-max", a["edge_max"] is not None)) if on]
    if len(modes) != 1:
        raise BindError("`block face triangulate` takes exactly one of radial, radial-8, edge-max <f>",
                        call.location)
    rows = np.flatnonzero(session.range_mask(call, "block"))
    triangulate_blocks(session.model, rows, modes[0], a["edge_max"])
