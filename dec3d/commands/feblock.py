"""`feblock generate|read|change|gravity|list`: FE blocks of 20-node bricks (FE-block text, shared/seeds/003_*)."""
from __future__ import annotations

import numpy as np

from ..config import MODULUS_LIMIT
from ..errors import BindError, CommandError, ResourceError
from ..geometry.assemble import block_poly
from ..geometry.febmesh import (MeshFileError, brick_corners, brick_mesh, complete_20, divisions, mesh_surface,
                                parse_fe_mesh, side_faces)
from ..kernels.feblock_hg import HOURGLASS
from ..model.feblocks import add_feblock, element_volumes, feblock_store, install_feblock_mesh, set_material
from ..model.model import KIND_DEFORMABLE, KIND_FE
from ..model.zones import ZMODEL_ELASTIC, ZMODEL_NULL
from .registry import command
from .values import DENSITY, FLAG, Choice, InPath, Num, Nums, P, Text

# Memory budget: about 3 kB per element (stress at 27 Gauss points, 20 node rows, nodes);
# refuse beyond this many elements per command.
FE_BUDGET = 2_000_000


def _need_configured(session, call, what: str) -> None:
    if "feblock" not in session.model.settings.configure:
        raise CommandError(f"`{what}` needs `model configure feblock` first (FE blocks are off in this model)",
                           call.location)


@command("feblock generate",
         positional=[P("size", Nums(3, 3, item=Num(lo=0, lo_open=True)),
                       "target element sizes along the block's x, y and z axes", required=True, units="m")],
         keywords=[P("integration", Num(integer=True, lo=2, hi=3),
                     "Gauss points per direction: 2 (2 x 2 x 2, default) or 3 (3 x 3 x 3) (dec3d keyword)",
                     default=2)],
         range="block",
         doc="Turn the visible 8-vertex hexahedral blocks in range into FE blocks meshed by 20-node bricks.",
         details="Each block gets a regular mesh of n1 x n2 x n3 elements, n = the mean edge length along "
                 "the block's axis divided by the size, rounded, at least 1 (the block's axes are those of "
                 "its hexahedron nearest to x, y, z). Nodes are shared between elements and are gridpoints "
                 "(`block gridpoint apply …` acts on them). The surface is approximated by eight triangles per "
                 "element face around a mid-face slave node, as in the FE-block text. Needs `model configure "
                 "feblock`. A block that is not an 8-vertex hexahedron, or a zoned block, is an error and "
                 "nothing is changed; blocks already FE blocks are left as they are. With 2 x 2 x 2 "
                 "integration, elements with no neighbour across the faces normal to two of their axes (a "
                 "mesh one element across in two directions) have zero-energy modes; they get a small "
                 "stiffness-based hourglass control (0.1 of the elastic moduli on the strain the eight points "
                 "miss, at the six face centres), which leaves uniform, linear and bilinear strain fields alone. "
                 "`feblock change hourglass` sets it per element. FE blocks of one joined set (`block join`, "
                 "before or after meshing) share their coincident nodes and carry no contact between them: "
                 "one body, as joined zoned blocks. Cable, beam and liner nodes made on a block before it was "
                 "meshed are coupled to its elements from then on.",
         examples=["feblock generate 1 1 1", "feblock generate 20 2.5 20 range group 'liner'",
                   "feblock generate 0.5 0.5 0.5 integration 3"])
def feblock_generate(session, call):
    _need_configured(session, call, "feblock generate")
    a = call.args
    sizes = [float(x) for x in a["size"]]
    nq = int(a["integration"])
    model = session.model
    b = model.blocks
    sel = session.range_mask(call, "block") & ~b["hidden"]
    rows = [int(r) for r in np.flatnonzero(sel) if int(b["kind"][r]) != KIND_FE]
    plans = []
    total = 0
    for r in rows:
        bid = int(b["id"][r])
        if int(b["kind"][r]) == KIND_DEFORMABLE:
            raise CommandError(f"block {bid} is zoned; `feblock generate` needs a rigid 8-vertex brick block",
                               call.location)
        poly = block_poly(model, r)
        faces = poly.faces()
        order = brick_corners(poly.vertices, faces)
        if order is None:
            raise CommandError(f"block {bid} is not an 8-vertex hexahedron ({len(poly.vertices)} vertices, "
                               f"{len(faces)} faces); `feblock generate` meshes brick blocks only",
                               call.location)
        x8 = poly.vertices[order]
        n = divisions(x8, sizes)
        total += int(np.prod(n))
        if total > FE_BUDGET:
            raise ResourceError(f"`feblock generate` would make more than {FE_BUDGET} elements; use larger sizes",
                                call.location)
        points, elems, slaves, tris, sides, nmaster = brick_mesh(x8, n)
        _, bad = element_volumes(points, elems)
        if bad >= 0:
            raise CommandError(f"block {bid}: element {bad + 1} of its mesh has a non-positive Jacobian "
                               "(the block is too distorted for a regular mesh)", call.location)
        src = side_faces(order, faces)[sides]
        plans.append((bid, points, elems, slaves, tris, src, nmaster, n))
    feblock_store(model)
    thin = []
    for bid, points, elems, slaves, tris, src, nmaster, n in plans:
        row = int(np.flatnonzero(b["id"][: b.n] == bid)[0])      # rows move as blocks are rewritten
        sl = install_feblock_mesh(model, row, points, elems, slaves, tris, src, nmaster, nq)
        if (model.store("feblocks")["hourglass"][sl] > 0).any():
            thin.append(bid)
    if plans:
        from ..model.cables import rehost
        from ..model.zone_mesh import relink
        relink(model)       # FE blocks joined before they were meshed share their coincident nodes
        rehost(model)       # cable, beam and liner nodes made on these blocks before: on their elements now
    if thin:
        session.write(f"note: {call.location}: blocks {', '.join(str(i) for i in thin[:10])} are one element "
                      "thick in two directions: with 2x2x2 integration their cross-sections have a zero-energy "
                      f"mode, held by hourglass control (eps_h = {HOURGLASS:g}; `feblock change hourglass`); "
                      "`integration 3` has no such mode")


@command("feblock read", positional=[P("file", InPath(), "the mesh file", required=True)],
         keywords=[P("integration", Num(integer=True, lo=2, hi=3),
                     "Gauss points per direction: 2 (default) or 3 (dec3d keyword)", default=2),
                   P("group", Text(), "group of the new block")],
         doc="Read a mesh of 20-node (or 8-node) bricks from an ASCII file into one new FE block.",
         details="The format of the FE-block text: a title line; `NN NE`; NN lines `x y z` (node n is the "
                 "n-th); NE lines of 20 node numbers in the VTK quadratic-hexahedron / C3D20 order (corners "
                 "counter-clockwise at the bottom then the top, then the mid-edge nodes of the bottom, top and "
                 "vertical edges), or of 8 corner numbers (the mid-edge nodes are then inserted). Node "
                 "numbering is free. The mesh surface (element faces met once) becomes the block's faces, eight "
                 "triangles per face around a mid-face slave node. A malformed or truncated file, or an element "
                 "with a non-positive Jacobian, is an error naming the file and line; nothing is changed.",
         examples=["feblock read 'dam.fem'", "feblock read 'liner.txt' integration 3 group 'liner'"])
def feblock_read(session, call):
    _need_configured(session, call, "feblock read")
    a = call.args
    path = session.in_path(a["file"], call.locations.get("file", call.location))
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise CommandError(f"cannot read '{a['file']}': {exc.strerror or exc}", call.location) from None
    try:
        pts, elems, where = parse_fe_mesh(text)
        if len(elems) > FE_BUDGET:
            raise ResourceError(f"'{path.name}' has {len(elems)} elements, over the budget of {FE_BUDGET}",
                                call.location)
        if elems.shape[1] == 8:
            pts, elems = complete_20(pts, elems)
        _, bad = element_volumes(pts, elems)
        if bad >= 0:
            raise MeshFileError(int(where[bad]), f"element {bad + 1} has a non-positive Jacobian (inverted, "
                                                 "badly distorted, or its nodes not in the Table 1 order)")
        used = np.zeros(len(pts), bool)
        used[elems.ravel()] = True
        if not used.all():
            raise MeshFileError(0, f"node {int(np.flatnonzero(~used)[0]) + 1} belongs to no element")
        nmaster = len(pts)
        allpts, slaves, tris = mesh_surface(pts, elems)
    except MeshFileError as exc:
        at = f"{path.name}:{exc.line}" if exc.line else path.name
        raise CommandError(f"{at}: {exc}", call.location) from None
    model = session.model
    row = add_feblock(model, allpts, elems, slaves, tris, nmaster, int(a["integration"]))
    if a["group"] is not None:
        model.groups.assign(model.blocks, np.array([row]), a["group"], None)


_POS = Num(lo=0, lo_open=True)
_MODULUS = Num(lo=0, lo_open=True, hi=MODULUS_LIMIT)     # (dec3d.config: a larger modulus is a typo)
_CMODELS = {"elastic": ZMODEL_ELASTIC, "null": ZMODEL_NULL}


@command("feblock change",
         keywords=[P("cmodel", Choice(tuple(_CMODELS)), "constitutive model: elastic, or null (no stress)"),
                   P("young", _MODULUS, "Young's modulus E", units="Pa"),
                   P("poisson", Num(lo=-1, hi=0.5, lo_open=True, hi_open=True), "Poisson's ratio, -1 < nu < 0.5"),
                   P("bulk", _MODULUS, "bulk modulus K", units="Pa"),
                   P("shear", _MODULUS, "shear modulus G", units="Pa"),
                   P("density", DENSITY, "mass density", units="kg/m³"),
                   P("hourglass", Num(lo=0, hi=1), "hourglass control eps_h of 2x2x2 elements, 0 to 1 "
                     "(0: none; dec3d keyword)")],
         range="block",
         doc="Set the constitutive model and properties of the FE elements in range.",
         details="The FE-block text assigns material per element with `feblock change`; the range selects "
                 "elements by their centroid (the mean of their corners), id or group. `hourglass` sets the "
                 "hourglass control of 2x2x2 elements (ignored by 3x3x3 ones; see `feblock generate`). Moduli are kept as bulk "
                 "and shear (give bulk/shear or young/poisson, not both pairs); young or poisson alone keeps "
                 "the other as the element's present moduli give it.",
         examples=["feblock change cmodel elastic young 30e9 poisson 0.2 density 2400",
                   "feblock change hourglass 0.05 range group 'liner'",
                   "feblock change density 2500 range position-x 0 5"])
def feblock_change(session, call):
    _need_configured(session, call, "feblock change")
    a = call.args
    keys = [k for k in ("cmodel", "young", "poisson", "bulk", "shear", "density", "hourglass") if a[k] is not None]
    if not keys:
        raise BindError("`feblock change` needs cmodel, young, poisson, bulk, shear, density or hourglass",
                        call.location)
    if (a["bulk"] is not None or a["shear"] is not None) and (a["young"] is not None or a["poisson"] is not None):
        raise BindError("`feblock change`: give bulk/shear or young/poisson, not both pairs in one command",
                        call.location)
    model = session.model
    feblock_store(model)
    rows = np.flatnonzero(session.range_mask(call, "feblocks"))
    if not len(rows):
        session.write(f"warning: {call.location}: `feblock change` selected no FE element")
        return
    try:
        set_material(model, rows, _CMODELS[a["cmodel"]] if a["cmodel"] is not None else None, a["young"],
                     a["poisson"], a["bulk"], a["shear"], a["density"])
    except ValueError as exc:
        raise BindError(f"`feblock change`: young and poisson are both needed: {exc}", call.location) from None
    if a["hourglass"] is not None:
        es = model.store("feblocks")
        es["hourglass"][rows] = float(a["hourglass"])
        if float(a["hourglass"]) == 0.0:
            two = rows[es["nq"][rows] == 2]
            es["gstress"][two, 8:14] = 0.0           # the control's stresses go with it (2x2x2 rows only)


@command("feblock gravity", keywords=[P("delete", FLAG, "take the gravity forces off instead", bare=True)],
         range="block",
         doc="Put the gravity forces of `model gravity` back on the FE blocks in range, or take them off (delete).",
         details="dec3d's reading: the FE-block text names `feblock gravity` without defining it, and says that "
                 "FE blocks take gravity by the consistent nodal forces of its Eq. (8) (rho ∫ N_I dV g per node) "
                 "rather than m g at the nodes. In dec3d FE blocks carry those forces under `model gravity` by "
                 "default; `feblock gravity delete` removes them from every element of the FE blocks in range "
                 "(their mass, for inertia and damping, stays), and `feblock gravity` puts them back. The "
                 "choice is kept per element in the model (`model save|restore`). No FE block in range is a "
                 "warning; without `model configure feblock`, an error.",
         examples=["feblock gravity delete", "feblock gravity delete range group 'liner'", "feblock gravity"])
def feblock_gravity(session, call):
    _need_configured(session, call, "feblock gravity")
    model = session.model
    es = feblock_store(model)
    b = model.blocks
    sel = session.range_mask(call, "block") & (b["kind"] == KIND_FE)
    rows = np.flatnonzero(sel[es["block"][: es.n]]) if es.n else np.zeros(0, np.int64)
    if not len(rows):
        session.write(f"warning: {call.location}: `feblock gravity` found no FE block in range")
        return
    es["gravity"][rows] = 0 if call.args["delete"] else 1


@command("feblock list", range="block",
         doc="List the FE blocks in range: elements, nodes (masters and slaves), volume, Gauss rule.",
         examples=["feblock list", "feblock list range group 'liner'"])
def feblock_list(session, call):
    _need_configured(session, call, "feblock list")
    model = session.model
    es = feblock_store(model)
    b, v = model.blocks, model.vertices
    sel = session.range_mask(call, "block")
    rows = [int(r) for r in np.flatnonzero(sel) if int(b["kind"][r]) == KIND_FE]
    eb = es["block"][: es.n]
    tot_e = int(np.isin(eb, rows).sum())
    session.write(f"FE blocks {len(rows)}, elements {tot_e}")
    if not rows:
        return
    session.write(f"{'block':>7} {'elements':>9} {'nodes':>7} {'slaves':>7} {'volume':>11} {'gauss':>6}")
    for r in rows:
        mine = eb == r
        v0, nv = int(b["vert_start"][r]), int(b["vert_count"][r])
        ns = int(v["feslave"][v0:v0 + nv].sum())
        nq = sorted(set(int(q) for q in es["nq"][: es.n][mine]))
        rule = "/".join(f"{q}x{q}x{q}" for q in nq)
        session.write(f"{int(b['id'][r]):>7} {int(mine.sum()):>9} {nv - ns:>7} {ns:>7} "
                      f"{es['volume'][: es.n][mine].sum():>11.6g} {rule:>6}")
