"""`block face group` and `block face triangulate`."""
from __future__ import annotations

import numpy as np

from ..errors import BindError
from ..geometry.triangulate import triangulate_blocks
from ..model.blocks import group_faces
from .registry import command
from .values import FLAG, Num, Nums, P, Text


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


_STRESS_KEYS = ("stress-xx", "stress-yy", "stress-zz", "stress-xy", "stress-xz", "stress-yz")


@command("block face apply",
         keywords=[P("stress", Nums(6, 6), "sxx syy szz sxy sxz syz", units="Pa"),
                   *[P(k, Num(), f"the {k[-2:]} component alone", units="Pa") for k in _STRESS_KEYS],
                   P("stress-normal", Num(), "normal stress (tension positive)", units="Pa")],
         range="face",
         doc="Apply a stress to the boundary triangles of zoned blocks in range (located by centroid).",
         details="The traction t = σ·n on each triangle, times its area, goes a third to each of its "
                 "gridpoints every step; the two triangles of a hexahedral zone's face are loaded as the "
                 "quadrilateral (the mean of its two diagonal splits: a quarter to each corner of a "
                 "parallelogram) and the faces of 10-node zones as 6-node triangles. Loads add to what is there; only faces on the outside of a "
                 "joined continuum take them. `block face apply-remove` clears them.",
         examples=["block face apply stress-normal -1e6 range position-z 1",
                   "block face apply stress -1e6 -2e6 -1e6 0 0 0 range group 'hole'"])
def block_face_apply(session, call):
    from ..model.face_loads import apply_face_stress
    a = call.args
    s = np.zeros(6)
    given = 0
    if a["stress"] is not None:
        s += np.asarray(a["stress"], float)
        given += 1
    for i, k in enumerate(_STRESS_KEYS):
        if a[k.replace("-", "_")] is not None:
            s[i] += a[k.replace("-", "_")]
            given += 1
    if a["stress_normal"] is not None:
        s[:3] += a["stress_normal"]
        given += 1
    if not given:
        raise BindError("`block face apply` needs stress <6 values>, stress-xx … or stress-normal <f>", call.location)
    if not np.isfinite(s).all():
        raise BindError("`block face apply`: the stress must be finite", call.location)
    n = apply_face_stress(session.model, session.range_mask(call, "face"), s)
    if n == 0:
        session.write(f"warning: {call.location}: `block face apply` selected no boundary face of a zoned "
                      "block (faces of rigid blocks take no applied stress)")


@command("block face apply-remove", range="face",
         keywords=[P("stress", FLAG, "the applied stresses (the only face load here; accepted as 3DEC writes it)",
                     bare=True)],
         doc="Remove the stresses applied to the faces in range (`block face apply`).",
         examples=["block face apply-remove", "block face apply-remove stress range position-z 1"])
def block_face_apply_remove(session, call):
    from ..model.face_loads import remove_face_stress
    remove_face_stress(session.model, session.range_mask(call, "face"))
