"""`structure liner …`: liner structural elements (3DEC's "Liner Structural Elements": flat 3-node
shell elements, DKT bending + CST membrane, coupled to the block surface; stores
``dec3d.model.liners``, physics ``dec3d.physics.liners``). Keywords are Itasca's (``by-block-face``,
``by-quadrilateral``, ``size``, ``cross-diagonal``, ``isotropic``, ``thickness``, ``density``,
``coupling-…``)."""
from __future__ import annotations

import numpy as np

from ..config import DENSITY_LIMIT, MODULUS_LIMIT, STIFFNESS_LIMIT
from ..errors import BindError, CommandError, ResourceError
from ..model.liner_mesh import quadrilateral_triangles, surface_triangles
from ..model.liners import (L_E, L_NU, LELEMS, LPROPS, add_liner, has_liners, liner_stores,
                            update_liner_masses)
from ..units import paren
from .registry import REGISTRY, command
from .budget import GIB, budget
from .values import COORD, COORD_LIMIT, FLAG, POINT, Num, Nums, P, Text

#: (the limits of blocks and zones: a thickness beyond COORD_LIMIT, a density beyond DENSITY_LIMIT or a
#: modulus beyond MODULUS_LIMIT made node masses, inertias and stiffnesses infinite)
_SINGLE = {"thickness": ("thickness", "m", Num(lo=0, lo_open=True, hi=COORD_LIMIT)),
           "density": ("density (node masses, gravity)", "kg/m³", Num(lo=0, hi=DENSITY_LIMIT)),
           "coupling-stiffness-normal": ("normal coupling spring stiffness per unit area", "Pa/m",
                                         Num(lo=0, hi=STIFFNESS_LIMIT)),
           "coupling-stiffness-shear": ("shear coupling spring stiffness per unit area", "Pa/m",
                                        Num(lo=0, hi=STIFFNESS_LIMIT)),
           "coupling-yield-normal": ("normal coupling spring tensile strength (stress units; exceeded: "
                                     "the spring breaks)", "Pa", Num(lo=0)),
           "coupling-cohesion-shear": ("shear coupling spring cohesion (stress units)", "Pa", Num(lo=0)),
           "coupling-cohesion-shear-residual": ("shear coupling spring cohesion after the first slip "
                                                "(stress units)", "Pa", Num(lo=0)),
           "coupling-friction-shear": ("shear coupling spring friction angle", "°", Num(lo=0, hi=90, hi_open=True))}


def _check_create(call):
    a = call.args
    if (not a["by_block_face"]) == (a["by_quadrilateral"] is None):
        raise BindError("`structure liner create` needs one of `by-block-face` or `by-quadrilateral v1 v2 v3 v4`",
                        call.location)
    if a["by_quadrilateral"] is None and (a["size"] is not None or a["cross_diagonal"]):
        raise BindError("`size` and `cross-diagonal` go with `by-quadrilateral`", call.location)
    if a["by_quadrilateral"] is not None and call.range is not None:
        raise BindError("a range selects block faces for `by-block-face`; `by-quadrilateral` takes none",
                        call.location)


@command("structure liner create",
         keywords=[P("by-block-face", FLAG, "line the surface faces of the blocks in range", bare=True),
                   P("by-quadrilateral", Nums(12, 12, item=COORD), "the corners v1 v2 v3 v4 of a quadrilateral",
                     units="m"),
                   P("size", Nums(2, 2, item=Num(integer=True, lo=1, hi=10000)),
                     "cells along v1 → v2 and along v1 → v4 (by-quadrilateral)", default=None),
                   P("cross-diagonal", FLAG, "four triangles about each cell's centre instead of two", bare=True),
                   P("tolerance", Num(lo=0, lo_open=True), "distance within which corners are one node",
                     units="m"),
                   P("id", Num(integer=True, lo=1), "liner id (default: the next free one)"),
                   P("group", Text(), "group of the new nodes and elements"),
                   P("slot", Text(), "group slot (default 'Default')")],
         range="face", check=_check_create,
         doc="Create a liner of flat 3-node shell elements on block faces or on a quadrilateral.",
         details="`by-block-face`: elements on the surface faces of the visible blocks in range (a face on which "
                 "no other block's face lies). A zoned block's surface triangles (its zones' faces) become "
                 "elements as they are, so the nodes are its gridpoints and follow them; a rigid block's face "
                 "polygon is split into triangles about its centroid and its nodes follow the block's motion. "
                 "Elements' z axes point out of the block. FE blocks are not lined.\n\n"
                 "`by-quadrilateral v1 v2 v3 v4 size n1 n2`: n1 × n2 cells of the bilinear quadrilateral, each "
                 "two triangles (or four with `cross-diagonal`); z by the right-hand rule v1 → v2 → v3 (give "
                 "the corners counter-clockwise seen from outside a block the liner lies on: the coupling "
                 "springs' normal is the z axis). A node inside or on a visible block is coupled to it (a zoned "
                 "block: to the zone holding it), others are free.\n\n"
                 "Corners within `tolerance` of each other are one node (default: the block tolerance, at least "
                 "10⁻³ of the median element edge for `by-block-face` — blocks that have moved since they were "
                 "cut no longer share their corners exactly — and 10⁻⁶ of the quadrilateral's size for "
                 "`by-quadrilateral`); a node is coupled to the block of the first face that made it. Each node has 3 "
                 "translations and 3 rotations; liner, beam and cable nodes share one id space. A quadrilateral "
                 "whose elements would take more memory than the budget (`model budget memory`, about 3 KiB an "
                 "element) is refused before any is made.",
         examples=["structure liner create by-block-face range group 'tunnel'",
                   "structure liner create by-quadrilateral 0 0 0 1 0 0 1 1 0 0 1 0 size 8 8 id 2"])
def liner_create(session, call):
    m = session.model
    a = call.args
    lid = a["id"]
    nodes, els = liner_stores(m)
    if lid is not None and np.any(els["liner"] == int(lid)):
        raise CommandError(f"there is a liner {int(lid)} already", call.locations.get("id", call.location))
    if a["by_quadrilateral"] is not None:
        c = np.array([float(v) for v in a["by_quadrilateral"]]).reshape(4, 3)
        size = max(float(np.ptp(c, axis=0).max()), 1e-300)
        n1, n2 = (int(v) for v in a["size"]) if a["size"] is not None else (1, 1)
        _check_budget(session, n1 * n2 * (4 if a["cross_diagonal"] else 2),
                      call.locations.get("size", call.location))
        tris = quadrilateral_triangles(c, n1, n2, bool(a["cross_diagonal"]))
        ar = 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
        if (ar <= 1e-12 * size * size).any():
            raise CommandError("the quadrilateral has a degenerate cell (are its corners in order and distinct?)",
                               call.locations.get("by_quadrilateral", call.location))
        tol = float(a["tolerance"]) if a["tolerance"] is not None else max(m.tolerance, 1e-6 * size)
        hosts = _corner_hosts(m, tris, tol)
    else:
        mask = session.range_mask(call, "face")
        tris, hosts = surface_triangles(m, mask, max(m.tolerance, 1e-9))
        if not len(tris):
            raise CommandError("no surface face of a visible rigid or zoned block is in range", call.location)
        # blocks that moved apart a little since they were cut: corners within 10⁻³ of the typical edge
        edge = float(np.median(np.linalg.norm(tris - np.roll(tris, 1, axis=1), axis=2)))
        tol = float(a["tolerance"]) if a["tolerance"] is not None else max(m.tolerance, 1e-3 * edge)
    lid = add_liner(m, tris, hosts, lid, a["group"], a["slot"], tol)
    update_liner_masses(m)
    new = nodes["liner"] == lid
    session.write(f"liner {lid}: {len(tris)} elements, {int(new.sum())} nodes, "
                  f"{int((new & (nodes['host'] >= 0)).sum())} coupled to blocks")


#: bytes a liner element costs at the peak of `structure liner create` (measured: 180 000 elements of a
#: `by-quadrilateral … size 300 300` took 0.41 GB above the starting process, ~2.3 KB each; rounded up)
BYTES_PER_ELEMENT = 3 * 1024


def _check_budget(session, n: int, where) -> None:
    """Refuse a quadrilateral of more elements than the session's memory budget (`model budget memory`)
    holds, before any is made (`size 10000 10000` would be 2·10⁸ elements, hundreds of GB)."""
    b = budget(session)
    gib = n * BYTES_PER_ELEMENT / GIB
    if gib > b.memory_gib:
        raise ResourceError(f"this liner would have {n:,} elements (about {gib:.3g} GiB); the budget allows "
                            f"{b.memory_gib:g} GiB", where,
                            hint="use a smaller `size`, or raise the budget with `model budget memory <GiB>` if "
                                 "the machine has the memory")


def _corner_hosts(m, tris, tol) -> np.ndarray:
    from ..model.cables import _first_block, host_blocks

    pts = tris.reshape(-1, 3)
    h = host_blocks(m, pts, tol)
    for k in np.flatnonzero(h == -2):
        h[k] = _first_block(m, pts[k], tol)
    return h.reshape(-1, 3)


def _check_property(call):
    a = call.args
    keys = ("isotropic",) + tuple(_SINGLE)
    if not any(k.replace("-", "_") in call.given for k in keys):
        raise BindError("`structure liner property` needs one of: " + ", ".join(keys), call.location)
    iso = a["isotropic"]
    if iso is not None and all(isinstance(v, (int, float)) for v in iso):
        _check_isotropic(iso, BindError, call.locations.get("isotropic", call.location))


def _check_isotropic(iso, error, where):
    e, nu = (float(v) for v in iso)
    if not 0 < e <= MODULUS_LIMIT:
        raise error(f"`isotropic`: Young's modulus must be in (0, {MODULUS_LIMIT:g}] (got {e:g})", where)
    if not -1.0 < nu < 0.5:
        raise error(f"`isotropic`: Poisson's ratio must be in (-1, 0.5) (got {nu:g})", where)


@command("structure liner property",
         keywords=[P("isotropic", Nums(2, 2), "Young's modulus E [Pa] and Poisson's ratio ν")]
         + [P(k, v[2], v[0], units=v[1]) for k, v in _SINGLE.items()],
         range=LELEMS, check=_check_property,
         doc="Set properties of the liner elements in range.",
         details="`isotropic E ν` (0 < E ≤ 1e16 Pa, −1 < ν < 0.5), `thickness` (> 0) and `density` set the shell; the "
                 "coupling springs join each node to its block: per node the springs are the values times its "
                 "tributary area (a third of each of its elements'). The normal spring carries compression without "
                 "limit and tension up to `coupling-yield-normal` × area, then breaks (compression only when the "
                 "liner comes back onto the surface); the shear spring slides at cohesion × area + normal force × "
                 "tan(`coupling-friction-shear`), its cohesion `coupling-cohesion-shear-residual` after the first "
                 "slip. Zero stiffnesses leave the nodes uncoupled; zero strengths let them slide or part at once.",
         examples=["structure liner property isotropic 30e9 0.2 thickness 0.1 density 2500",
                   "structure liner property coupling-stiffness-normal 1e9 coupling-stiffness-shear 1e9 "
                   "coupling-yield-normal 1e6 coupling-cohesion-shear 1e6 coupling-friction-shear 30"])
def liner_property(session, call):
    _need_liners(session, call)
    mask = session.range_mask(call, LELEMS)
    _, els = liner_stores(session.model)
    iso = call.args["isotropic"]
    if iso is not None:
        _check_isotropic(iso, CommandError, call.locations.get("isotropic", call.location))
        els["prop"][mask, L_E] = float(iso[0])
        els["prop"][mask, L_NU] = float(iso[1])
    for col, name in enumerate(LPROPS):
        if name in _SINGLE:
            v = call.args[name.replace("-", "_")]
            if v is not None:
                els["prop"][mask, col] = float(v)
    update_liner_masses(session.model)


def _need_liners(session, call):
    if not has_liners(session.model):
        raise CommandError("there is no liner: make one first (`structure liner create …`)", call.location)


@command("structure liner list", range=LELEMS,
         doc="List the liner elements in range: nodes, membrane forces and bending moments at the centroid.",
         details="In the element's axes (x from its first node to its second, z its normal): membrane forces "
                 "N_xx, N_yy, N_xy [N/m] (tension positive) and moments M_xx, M_yy, M_xy [N·m/m], M = −D (w,xx + ν "
                 "w,yy) … (Timoshenko's signs: positive M_xx makes +z concave), from the nodes' displacements and "
                 "rotations (constant over the element for the membrane, at the centroid for bending).",
         examples=["structure liner list", "structure liner list range id 1"])
def liner_list(session, call):
    from ..model.liner_output import element_resultants

    _need_liners(session, call)
    mask = session.range_mask(call, LELEMS)
    nodes, els = liner_stores(session.model)
    res = element_resultants(session.model)
    n, mo = paren(session, "force"), paren(session, "moment")
    session.write(f"    id liner  nodes              {'N-xx' + n:>11} {'N-yy':>11} {'N-xy':>11} {'M-xx' + mo:>11} "
                  f"{'M-yy':>11} {'M-xy':>11}   (per unit length)")
    ids = nodes["id"]
    for e in np.flatnonzero(mask):
        c = els["nodes"][e]
        r = res[e]
        session.write(f"{int(els['id'][e]):6d} {int(els['liner'][e]):5d}  {int(ids[c[0]]):6d} {int(ids[c[1]]):6d} "
                      f"{int(ids[c[2]]):6d} " + " ".join(f"{x:11.4g}" for x in r))


# ------------------------------------------------------------------ histories
_WHICH = [P("component-id", Num(integer=True, lo=1), "id of the element"),
          P("position", POINT, "the element whose centroid (as created) is nearest this point", units="m"),
          P("node", Num(integer=True, lo=1, hi=3), "the element's node 1, 2 or 3", default=1)]
REGISTRY.node_keywords("structure liner history", [P("name", Text(), "history name")])
_HDOC = {"coupling-displacement-normal": "normal displacement of the node from its host point (m, separation "
                                         "positive)",
         "coupling-displacement-shear": "shear displacement of the node from its host point (m, magnitude)",
         "coupling-stress-normal": "normal coupling stress (Pa, tension positive: force over the node's area)",
         "coupling-stress-shear": "shear coupling stress (Pa, magnitude: force over the node's area)"}


def _check_hist(call):
    if (call.args["component_id"] is None) == (call.args["position"] is None):
        raise BindError("give either `component-id <i>` or `position <x y z>`", call.location)


def _handler(quantity):
    def handler(session, call):
        from ..physics.history import histories
        from ..physics.liner_history import add_liner_history
        from .histories import _name

        _need_liners(session, call)
        name = _name(session, call)
        if call.args["component_id"] is not None:
            ident = int(call.args["component_id"])
        else:
            _, els = liner_stores(session.model)
            d = np.linalg.norm(els["pos"] - np.asarray([float(x) for x in call.args["position"]]), axis=1)
            ident = int(els["id"][int(np.argmin(d))])
        try:
            add_liner_history(histories(session.model), quantity, ident, int(call.args["node"]), name)
        except CommandError as exc:
            raise exc.with_location(call.locations.get("component_id", call.location))
    return handler


for _q in _HDOC:
    command(f"structure liner history {_q}", keywords=_WHICH, check=_check_hist,
            doc=f"Record the {_HDOC[_q]} at a node of a liner element.",
            details="The element is named by `component-id <i>` or by `position x y z` (nearest centroid as "
                    "created), the node by `node 1|2|3` (default 1). A free node records 0. A leading "
                    "`name '<s>'` names the history.",
            examples=[f"structure liner history {_q} component-id 1 node 2"])(_handler(_q))
