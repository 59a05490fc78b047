"""`block create brick|polyhedron|prism|tetrahedron|tunnel`: new convex blocks.

Every form accepts `group '<g>' [slot '<s>']` (before or after the shape word) and
`face-group '<g>'` for the new faces. The geometry is checked before anything is added:
a refused shape leaves the model as it was.
"""
from __future__ import annotations

import numpy as np

from ..errors import Dec3dError
from ..geometry.polyhedron import (WARP_RELATIVE, brick_faces, build_many, polyhedron_from_faces, prism_faces,
                                   split_faces, tetrahedron_faces)
from ..geometry.tunnel import tunnel, tunnel_block_count
from ..model.blocks import add_blocks, add_pieces
from ..units import suffix
from .budget import check_blocks
from .registry import command
from .values import ANGLE, COORD, LENGTH, POINT, InPath, Nums, Num, P, Text

GROUP_KW = [P("group", Text(), "group of the new blocks"),
            P("slot", Text(), "group slot (default 'Default')"),
            P("face-group", Text(), "group of the new blocks' faces"),
            P("region", Num(integer=True), "3DEC 5 region number (`r=0` in old generators; default 0), "
                                                     "selected by `range region`")]


def _add(session, call, polys) -> None:
    m = session.model
    check_blocks(session, len(polys), f"`{call.name}`", call.location)
    rows = add_blocks(m, polys, group=call.args["group"], slot=call.args["slot"])
    _label(m, [call], rows)
    _warn_coincident(session, rows, [call] * len(rows))


def _warn_coincident(session, rows, calls) -> None:
    """One warning when new blocks ``rows`` (made by ``calls[i]``) lie exactly where a block made before
    them is (the same centroid within the tolerance and the same volume: a line given twice); the run
    goes on."""
    m = session.model
    b = m.blocks
    tol = max(m.tolerance, 1e-12)
    cen, vol = b["centroid"], b["volume"]
    live = np.flatnonzero(b["vert_count"] > 0)
    hits = []
    if len(rows) <= 8:                  # a line at a time: one vectorised look at every block
        for i, row in enumerate(rows):
            same = live[(np.abs(cen[live] - cen[row]) <= tol).all(axis=1)
                        & (np.abs(vol[live] - vol[row]) <= 1e-9 * vol[row]) & (live < row)]
            if len(same):
                hits.append((i, int(row), int(same[0])))
    else:                               # a run of lines: blocks by their centroid's cell
        seen: dict = {}
        for row, k in zip(live, map(tuple, np.round(cen[live] / tol).astype(np.int64))):
            seen.setdefault(k, []).append(int(row))
        keys = np.round(cen[rows] / tol).astype(np.int64)
        for i, (row, k) in enumerate(zip(rows, map(tuple, keys))):
            other = next((o for o in seen.get(k, ()) if o < row and abs(vol[o] - vol[row]) <= 1e-9 * vol[row]), None)
            if other is not None:
                hits.append((i, int(row), other))
    if hits:
        i, row, other = hits[0]
        more = f" ({len(hits)} new blocks in all)" if len(hits) > 1 else ""
        session.write(f"warning: {calls[i].location}: block {int(b['id'][row])} lies exactly where block "
                      f"{int(b['id'][other])} is (same centroid and volume){more}: blocks must not overlap; "
                      "is the line given twice?")


def _label(m, calls, rows) -> None:
    """Regions and groups of new blocks (and face groups of their faces), ``calls[i]`` giving its
    words to the blocks ``rows[i]`` (one row per call, or all rows for one call). Groups are named
    in the order the lines name them, so group codes come out as line-by-line running makes them."""
    per_call = len(calls) > 1
    assign: dict[tuple, list] = {}
    for i, call in enumerate(calls):
        a = call.args
        r = rows[i:i + 1] if per_call else rows
        if a.get("region") is not None:
            m.blocks["region"][r] = a["region"]
        if a["group"] is not None:
            assign.setdefault(("block", a["group"], a["slot"]), []).append(r)
        if a.get("face_group") is not None:
            fs, fc = m.blocks["face_start"][r], m.blocks["face_count"][r]
            assign.setdefault(("face", a["face_group"], a["slot"]), []).extend(
                np.arange(s, s + c) for s, c in zip(fs, fc))
    for (store, name, slot), parts in assign.items():
        m.groups.assign(m.blocks if store == "block" else m.faces, np.concatenate(parts), name, slot)


def _shape(call, tol: float):
    """(corners (n, 3), corners per face) of one `block create brick|polyhedron|prism|tetrahedron` line."""
    kind, a = call.command.path[-1], call.args
    if kind == "brick":
        b = list(a["bounds"])
        while len(b) < 6:
            b += b[-2:]
        return brick_faces(*b, tol=tol)
    if kind == "polyhedron":
        faces = [np.asarray(f, dtype=np.float64).reshape(-1, 3) for f in a["face"]]
        if not faces:
            return np.zeros((0, 3)), np.zeros(0, dtype=np.int64)
        return np.concatenate(faces), np.array([len(f) for f in faces], dtype=np.int64)
    if kind == "prism":
        return prism_faces(a["face_1"], a["face_2"], tol)
    return tetrahedron_faces(*np.reshape(a["corners"], (4, 3)))


def _create(session, call) -> None:
    tol = session.model.tolerance
    pts, fn = _shape(call, tol)
    warped: list = []
    poly = polyhedron_from_faces(split_faces(pts, fn), tol, call.command.path[-1], WARP_RELATIVE, warped)
    _add(session, call, [poly])
    if warped:          # one warning for the block, naming its most warped face
        fi, corner, dist, limit = max(warped, key=lambda w: w[2])
        more = f" (and {len(warped) - 1} other face(s))" if len(warped) > 1 else ""
        bid = int(session.model.blocks["id"][session.model.blocks.n - 1])
        L = suffix(session, "length")
        session.write(f"warning: {call.location}: block {bid}: face {fi} is warped: corner {corner} lies {dist:.3g}{L} "
                      f"off the face's plane{more} (tolerance {tol:g}{L}; accepted up to {100 * WARP_RELATIVE:g} % of "
                      f"the block's size, {limit:.3g}{L}): the block is built as the convex hull of its corners, "
                      "the warped face split into triangles")


def _create_many(session, calls) -> int:
    """`block create brick|polyhedron|prism|tetrahedron` lines in a row, built in one compiled pass
    (a deck of thousands of bricks or masonry polyhedra). Stops before the first line whose shape is
    refused or that the block budget would refuse: that line runs on its own and reports."""
    m = session.model
    tol = m.tolerance
    shapes = []
    for call in calls:
        try:
            shapes.append(_shape(call, tol))
        except Dec3dError:
            break
    built, batch = build_many(shapes, tol)
    if built == 0:
        return 0
    try:
        check_blocks(session, built, f"`{calls[0].name}`", calls[0].location)
    except Dec3dError:
        return 0
    rows = add_pieces(m, batch)
    _label(m, calls[:built], rows)
    _warn_coincident(session, rows, calls[:built])
    return built


@command("block create brick",
         positional=[P("bounds", Nums(2, 6, counts=(2, 4, 6), item=COORD), "x1 x2 [y1 y2 [z1 z2]]", required=True, units="m")],
         keywords=GROUP_KW,
         doc="Create a block spanning x1..x2, y1..y2, z1..z2 (a pair left out repeats the one before).",
         examples=["block create brick 0 1.292 -0.05 0 0.0 0.210 group 'S'", "block create brick 0 10",
                   "block create group 'rock' brick 0 10 0 10 0 10"],
         batch=_create_many)
def create_brick(session, call):
    _create(session, call)


@command("block create polyhedron",
         keywords=[P("face", Nums(9, 10**6, multiple_of=3, item=COORD), "the corners x,y,z of one face, in order around it",
                     repeat=True, units="m"), *GROUP_KW],
         doc="Create a convex block from its faces (every face given, either winding).",
         details="Corners closer than the tolerance are merged. The faces must close the block; an open or "
                 "non-convex shape, or a zero volume is refused with the number of the offending face. A face "
                 "whose corners lie off its plane by more than the tolerance (`block tolerance`) but by at most "
                 "0.5 % of the block's size (its bounding-box diagonal; the rule `block generate from-vrml` uses) "
                 "is accepted with a warning naming the block, the face and the warp: the block is built as the "
                 "convex hull of its corners, the warped face split into triangles, so its volume is that of the "
                 "faces as built (dec3d's rule: 3DEC's documentation we could read states none). A face warped "
                 "by more is refused with the distance and the limit.",
         examples=["block create polyhedron face 0,0,0 1,0,0 0,1,0 face 0,0,0 0,0,1 1,0,0 "
                   "face 0,0,0 0,1,0 0,0,1 face 1,0,0 0,0,1 0,1,0",
                   "block create group 'Supports' poly face 0 0 0 1 0 0 0 1 0 face 0 0 0 0 0 1 1 0 0 "
                   "face 0 0 0 0 1 0 0 0 1 face 1 0 0 0 0 1 0 1 0"],
         batch=_create_many)
def create_polyhedron(session, call):
    _create(session, call)


@command("block create prism",
         keywords=[P("face-1", Nums(9, 10**6, multiple_of=3, item=COORD), "corners of one end face", required=True, units="m"),
                   P("face-2", Nums(9, 10**6, multiple_of=3, item=COORD), "corners of the other end, in the same order",
                     required=True, units="m"), *GROUP_KW],
         doc="Create a prism between two polygons with as many corners (corner i joined to corner i).",
         examples=["block create prism face-1 0 0 0 1 0 0 0 1 0 face-2 0 0 1 1 0 1 0 1 1 group 'p'"],
         batch=_create_many)
def create_prism(session, call):
    _create(session, call)


@command("block create tetrahedron",
         positional=[P("corners", Nums(12, 12, item=COORD), "four corners v1 v2 v3 v4", required=True, units="m")],
         keywords=GROUP_KW,
         doc="Create a tetrahedron on four corners.",
         examples=["block create tetrahedron 0 0 0 1 0 0 0 1 0 0 0 1"],
         batch=_create_many)
def create_tetrahedron(session, call):
    _create(session, call)


@command("block create tunnel",
         keywords=[P("dip", ANGLE, "plunge of the axis, degrees", default=0.0),
                   P("dip-direction", ANGLE, "trend of the axis, degrees clockwise from +y", default=0.0),
                   P("radius", LENGTH, "radius of the opening", required=True, units="m"),
                   P("length", Nums(2, 2, item=COORD), "axial start and end, from the origin", required=True, units="m"),
                   P("origin", POINT, "a point of the axis", default=(0.0, 0.0, 0.0), units="m"),
                   P("blocks-axial", Num(integer=True, lo=1), "blocks along the axis", default=1),
                   P("blocks-radial", Num(integer=True, lo=1), "rings between the opening and the boundary",
                     default=1),
                   P("blocks-tangential", Num(integer=True, lo=1), "blocks per 45° around the axis", default=1),
                   P("boundary", LENGTH, "distance from the opening to the square boundary",
                     required=True, units="m"),
                   P("radius-ratio", Num(lo=0, lo_open=True, hi=1000), "growth of the ring widths outwards", default=1.0),
                   *GROUP_KW],
         doc="Create the blocks of a square rock mass around a circular tunnel (opening filled).",
         details="The axis runs along the dip vector (dip 0, dip-direction 0: along +y). The section is the "
                 "square |u|, |v| ≤ radius + boundary; rays at equal angles (blocks-tangential per 45°) run "
                 "from the opening's polygon to the square, cut into blocks-radial rings whose widths grow "
                 "by radius-ratio. The opening is filled with prisms: delete them with "
                 "`block delete range cylinder ... radius 0 <radius>`.",
         examples=["block create tunnel dip 0 dip-direction 0 radius 1 length 0 1 blocks-axial 1 "
                   "blocks-radial 10 blocks-tangential 5 boundary 9 radius-ratio 1.4"])
def create_tunnel(session, call):
    a = call.args
    check_blocks(session, tunnel_block_count(a["blocks_axial"], a["blocks_radial"], a["blocks_tangential"]),
                 "this tunnel", call.location)
    polys = tunnel(a["dip"], a["dip_direction"], a["radius"], a["length"], a["blocks_axial"],
                   a["blocks_radial"], a["blocks_tangential"], a["boundary"], a["radius_ratio"],
                   origin=a["origin"], tol=session.model.tolerance)
    _add(session, call, polys)


@command("block generate from-vrml",
         keywords=[P("filename", InPath(exts=(".wrl",)), "the VRML 2.0 file: beside the calling deck, else in the "
                     "output folder (.wrl tried when there is no extension)", required=True),
                   P("group", Text(), "group of the new blocks"), P("slot", Text(), "group slot (default 'Default')"),
                   P("tolerance", Num(lo=0, lo_open=True), "planarity and convexity tolerance for this file "
                     "(dec3d; default 0.5 % of each shape's size, at least `block tolerance`)", units="m")],
         doc="Create one convex block per IndexedFaceSet of a VRML 2.0 (.wrl) file.",
         details="The file's node tree is read with DEF/USE; Transform nodes (translation, rotation, scale, "
                 "scaleOrientation, center) place their children; Group, Anchor, Collision and Switch hold "
                 "shapes; appearance, normals, lights and viewpoints are skipped. Faces that a CAD exporter "
                 "split into triangles are merged back where neighbours lie in one plane (within the model "
                 "tolerance). Every shape must be closed and convex: a refused shape is named by its number and "
                 "the file's line, and no block of the file is added. Other geometry nodes (Box, Sphere, ...), "
                 "PROTO and Inline are refused by name. CAD exports of curved masonry fold a brick's faces by a "
                 "fraction of a millimetre (the public scaffree dome bricks: 0.7 mm, a concave fold), so each "
                 "shape is checked with a tolerance of 0.5 % of its size (its bounding-box diagonal; at least the "
                 "model tolerance): a face folded by less is read as one face, its corners within that distance "
                 "of its plane. `tolerance <f>` gives the tolerance in metres instead (`tolerance 1e-6`: strict).",
         examples=["block generate from-vrml filename 'dome_herringbone_5_1_65_8_1_1_0_0.wrl'",
                   "block generate from-vrml filename 'course_1' group 'C1'",
                   "block generate from-vrml filename 'dome.wrl' tolerance 1e-6"])
def generate_from_vrml(session, call):
    from ..io.vrml import VrmlError, vrml_polys
    from ..errors import CommandError
    from ..io.paths import os_error_text

    where = call.locations.get("filename", call.location)
    name = call.args["filename"]
    path = session.in_path(name, where, (".wrl",), "VRML file")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise CommandError(f"cannot read VRML file '{name}': {os_error_text(exc)}").with_location(where) from None
    text = raw.decode("utf-8", errors="replace")
    from ..io.vrml import RELATIVE_TOLERANCE

    given = call.args.get("tolerance")
    try:
        if given is not None:
            polys = vrml_polys(text, path.name, float(given))
        else:
            polys = vrml_polys(text, path.name, session.model.tolerance, RELATIVE_TOLERANCE)
    except VrmlError as exc:
        if "not convex" in exc.message or "not planar" in exc.message:
            exc.hint = exc.hint or (f"faces are counted after merging coplanar triangles; a shape folded by less "
                                    f"than a millimetre (a CAD export of curved masonry) reads with a larger "
                                    f"`tolerance`, e.g. `block generate from-vrml filename '{name}' tolerance 0.002`")
        raise exc.with_location(where) from None
    _add(session, call, polys)
