"""The stores of grouted cable structural elements (``structure cable …``; physics in
``dec3d.physics.cables``, kernel ``dec3d.kernels.cable``).

``cable_nodes``   one row per cable node
    id ()          int64  node id, from 1 (``range id``)
    cable ()       int64  id of the cable the node belongs to
    pos, vel, disp (3,)   m, m/s, m
    mass ()        kg     real mass: density × area × tributary length (0 without density)
    imass ()       kg     inertial mass of the last step (density-scaled to the step, see physics.cables)
    host ()        int64  row of the block the node lies in, -1 none (ungrouted)
    hz ()          int8   0: a rigid host; else the node follows an element of a deformable host
                   (``model.hosts``: 1 a 4-node zone, 2 a 10-node zone, 3 an FE brick): hzone () its row,
                   hgp (NHOST,) its node rows, hw (NHOST,) the node's weights (shape functions) in it
    hpos (3,)      m      host point: the material point of the host block where the node sits
    fix ()         uint8  bits 0-2: velocity components held (``structure node fix``)
    fapp (3,)      N      applied force (``structure node apply``)
    force (3,)     N      unbalanced force of the last step
    hforce, hmoment (3,)  N, N·m  force of the grout on the host block at the last step, and its
                   moment about the block's centroid (added to the block's ``fapp``/``mapp``)
    group (1,)     int32  group code
``cable_segments`` one row per cable element (segment)
    id (), cable () int64
    na, nb ()      int64  node rows
    l0 ()          m      length as created; lcur () m length at the last step
    prop (NPROP,)  young, cross-sectional-area, yield-tension, yield-compression, grout-stiffness,
                   grout-cohesion, grout-friction [rad], grout-perimeter, density, tensile-failure-strain
                   (0: never ruptures)
    fa ()          N      axial force, tension positive
    gf (2,)        N      grout force on the cable at the a and b ends, along the axis a → b
    state ()       int32  yield/slip/rupture bits (``kernels.cable``)
    tapp (), tact () applied tension and whether it is active (``structure cable apply tension``)
    group (1,)     int32
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.cable import NPROP

from .groups import group_field
from .hosts import NHOST, host_element, next_id, remap_node_hosts, widen, zone_hosted
from .model import KIND_RIGID, Model
from .store import Field, Store

_F = np.float64
_I = np.int64

NODES = "cable_nodes"
SEGMENTS = "cable_segments"

#: property names as 3DEC spells them, in ``prop`` column order
PROPS = ("young", "cross-sectional-area", "yield-tension", "yield-compression", "grout-stiffness",
         "grout-cohesion", "grout-friction", "grout-perimeter", "density", "tensile-failure-strain")
assert len(PROPS) == NPROP


def _node_fields() -> dict[str, Field]:
    v3 = Field((3,), _F, 0.0)
    return {"id": Field((), _I, 0), "cable": Field((), _I, 0), "pos": v3, "vel": v3, "disp": v3,
            "mass": Field((), _F, 0.0), "imass": Field((), _F, 0.0), "host": Field((), _I, -1), "hpos": v3,
            "fix": Field((), np.uint8, 0), "fapp": v3, "force": v3, "hforce": v3, "hmoment": v3,
            "group": group_field(), "hz": Field((), np.int8, 0), "hzone": Field((), _I, -1),
            "hgp": Field((NHOST,), _I, -1), "hw": Field((NHOST,), _F, 0.0)}


def _segment_fields() -> dict[str, Field]:
    return {"id": Field((), _I, 0), "cable": Field((), _I, 0), "na": Field((), _I, -1), "nb": Field((), _I, -1),
            "l0": Field((), _F, 0.0), "lcur": Field((), _F, 0.0), "prop": Field((NPROP,), _F, 0.0),
            "fa": Field((), _F, 0.0), "gf": Field((2,), _F, 0.0), "state": Field((), np.int32, 0),
            "tapp": Field((), _F, 0.0), "tact": Field((), np.uint8, 0), "group": group_field(),
            "pos": Field((3,), _F, 0.0)}     # segment midpoint as created (``range position``)


def cable_stores(model: Model) -> tuple[Store, Store]:
    """The node and segment stores, added to the model on first use (saved and restored with it)."""
    st = model.stores
    if NODES not in st:
        model.add_store(Store(NODES, _node_fields()))
    if SEGMENTS not in st:
        model.add_store(Store(SEGMENTS, _segment_fields()))
    st = model.stores
    for name, fields in ((NODES, _node_fields()), (SEGMENTS, _segment_fields())):
        for key, spec in fields.items():      # (a store restored from a file that had fewer fields)
            if key not in st[name]:
                st[name].add_field(key, spec)
    widen(st[NODES])        # (4 host-node slots in files written before quadratic hosts)
    if st[SEGMENTS].fields["prop"].shape != (NPROP,):
        # (restored from a file written before a property column was added: the new ones read 0, "none")
        st[SEGMENTS].resize_field("prop", (NPROP,))
    return st[NODES], st[SEGMENTS]


def has_cables(model: Model) -> bool:
    st = model.stores
    return SEGMENTS in st and st[SEGMENTS].n > 0


def host_blocks(model: Model, pts: np.ndarray, tol: float) -> np.ndarray:
    """Row of the visible rigid block each point lies in (on its boundary counts; the lowest row when
    several hold it), -1 for none. A point is in a convex block when it is behind every face plane
    by ``tol`` at most. Points in zoned or FE blocks are reported as -2 (the caller looks for their
    zone or FE element, ``hosts.host_element``)."""
    b, f = model.blocks, model.faces
    out = np.full(len(pts), -1, _I)
    if not b.n:
        return out
    fb = f["block"]
    for i, p in enumerate(pts):
        dist = np.einsum("fk,fk->f", p[None, :] - f["centroid"], f["normal"])
        outside = np.zeros(b.n, bool)
        np.logical_or.at(outside, fb[fb >= 0], dist[fb >= 0] > tol)
        inside = ~outside & ~b["hidden"] & (b["face_count"] > 0)
        rows = np.flatnonzero(inside)
        if rows.size:
            r = int(rows[0])
            out[i] = r if b["kind"][r] == KIND_RIGID else -2
    return out


def _first_block(model: Model, p: np.ndarray, tol: float) -> int:
    b, f = model.blocks, model.faces
    fb = f["block"]
    dist = np.einsum("fk,fk->f", p[None, :] - f["centroid"], f["normal"])
    outside = np.zeros(b.n, bool)
    np.logical_or.at(outside, fb[fb >= 0], dist[fb >= 0] > tol)
    rows = np.flatnonzero(~outside & ~b["hidden"] & (b["face_count"] > 0))
    return int(rows[0]) if rows.size else -1


def place_nodes(model: Model, nodes: Store, p1, p2, segments: int, tol: float):
    """Append the ``segments + 1`` nodes of a straight chain from p1 to p2 to ``nodes`` (cable or beam
    nodes: one id space), each hosted by the block it lies in (a deformable block: the zone or FE element
    holding it; -3 where none can host it). Returns (node rows, their points, host rows as ``host_blocks`` gives them,
    -2 turned into the block row or -3)."""
    from .beams import next_node_id      # (cable and beam nodes share one id space)

    t = np.linspace(0.0, 1.0, segments + 1)[:, None]
    pts = p1[None, :] * (1.0 - t) + p2[None, :] * t
    hosts = host_blocks(model, pts, tol)
    nid0 = next_node_id(model)
    sl = nodes.append(segments + 1)
    rn = np.arange(sl.start, sl.stop)
    nodes["id"][rn] = np.arange(nid0, nid0 + segments + 1)
    nodes["pos"][rn] = pts
    nodes["hpos"][rn] = pts
    for k in np.flatnonzero(hosts == -2):
        # a node in a deformable block follows the zone or FE element that holds it (-3: none)
        r = _first_block(model, pts[k], tol)
        z = host_element(model, r, pts[k], max(tol, 1e-9)) if r >= 0 else None
        if z is None:
            hosts[k] = -3
            continue
        hosts[k] = r
        nodes["hz"][rn[k]], nodes["hzone"][rn[k]], nodes["hgp"][rn[k]], nodes["hw"][rn[k]] = z
    nodes["host"][rn] = np.maximum(hosts, -1)
    return rn, pts, hosts


def add_cable(model: Model, p1, p2, segments: int, cable_id: int | None, group: str | None,
              tol: float) -> tuple[int, np.ndarray]:
    """Append a straight cable of ``segments`` equal elements from p1 to p2; returns (cable id,
    host rows of its nodes). The nodes take the block they lie in as host."""
    nodes, segs = cable_stores(model)
    p1, p2 = np.asarray(p1, _F), np.asarray(p2, _F)
    cid = int(cable_id) if cable_id is not None else next_id("cable", nodes["cable"], segs["cable"])
    sid0 = int(segs["id"].max(initial=0)) + 1
    rn, pts, hosts = place_nodes(model, nodes, p1, p2, segments, tol)
    nodes["cable"][rn] = cid
    sl = segs.append(segments)
    rs = np.arange(sl.start, sl.stop)
    segs["id"][rs] = np.arange(sid0, sid0 + segments)
    segs["cable"][rs] = cid
    segs["na"][rs] = rn[:-1]
    segs["nb"][rs] = rn[1:]
    length = float(np.linalg.norm(p2 - p1)) / segments
    segs["l0"][rs] = length
    segs["lcur"][rs] = length
    segs["pos"][rs] = 0.5 * (pts[:-1] + pts[1:])
    if group:
        model.groups.assign(nodes, rn, group)
        model.groups.assign(segs, rs, group)
    return cid, hosts


def update_masses(model: Model) -> None:
    """Real node masses: density × area × half of each adjacent segment's length."""
    nodes, segs = cable_stores(model)
    m = np.zeros(nodes.n)
    lm = segs["prop"][:, 8] * segs["prop"][:, 1] * segs["l0"] * 0.5
    np.add.at(m, segs["na"], lm)
    np.add.at(m, segs["nb"], lm)
    nodes["mass"][:] = m


def nodes_hosted_by(model: Model, mask) -> int:
    """How many cable nodes have their host among the blocks of ``mask`` (bool over block rows)."""
    st = model.stores
    if NODES not in st or not st[NODES].n:
        return 0
    h = st[NODES]["host"]
    on = h >= 0
    return int(np.asarray(mask, bool)[h[on]].sum())


def rehost(model: Model) -> None:
    """After blocks were zoned: structural nodes on them find the zone holding them (``remap_hosts`` with
    no block gone; ``hosts.zone_hosted``), and so do the dowels' sides (``dowels.rehost_dowels``). The reaction a node coupled to the block's rigid motion left in
    the block's applied loads is taken back: from the next step it goes to the zone's gridpoints."""
    from .beams import BNODES
    from .liners import LNODES

    b = model.blocks
    for name in (NODES, BNODES, LNODES):
        nodes = model.stores.get(name)
        if nodes is None or not nodes.n:
            continue
        h = nodes["host"]
        moved = zone_hosted(model, h, nodes["hz"])
        moved = moved[nodes["hz"][moved] == 0]          # (rigid hosts zoned since)
        np.add.at(b["fapp"], h[moved], -nodes["hforce"][moved])
        np.add.at(b["mapp"], h[moved], -nodes["hmoment"][moved])
        nodes["hforce"][moved] = 0.0
        nodes["hmoment"][moved] = 0.0
    from .dowels import rehost_dowels

    rehost_dowels(model)
    remap_hosts(model, np.arange(b.n, dtype=np.int64))


def remap_hosts(model: Model, remap: np.ndarray) -> None:
    """After blocks are deleted (old row -> new row, -1 gone): nodes whose block went lose their host."""
    st = model.stores
    from .dowels import remap_dowels     # dowels with a side deleted go (hybrid bolts)

    remap_dowels(model, remap)
    from .beams import remap_beam_hosts  # beam nodes linked to a deleted block are free

    remap_beam_hosts(model, remap)
    from .liners import remap_liner_hosts  # liner nodes coupled to a deleted block are free

    remap_liner_hosts(model, remap)
    if NODES in st and st[NODES].n:
        nodes = cable_stores(model)[0]
        h = nodes["host"]
        gone = (h >= 0) & (remap[np.maximum(h, 0)] < 0)
        lost = remap_node_hosts(model, nodes, remap)
        # (the grout force went with the deleted block's applied force; the node carries none from now on)
        nodes["hforce"][gone] = 0.0
        nodes["hmoment"][gone] = 0.0
        segs = st[SEGMENTS]
        gone = np.flatnonzero(lost)
        segs["gf"][np.isin(segs["na"], gone), 0] = 0.0
        segs["gf"][np.isin(segs["nb"], gone), 1] = 0.0


def release_hosts(model: Model, mask) -> tuple[int, int, int, int]:
    """Cut the structural links into the blocks of ``mask`` (bool over block rows), as `block excavate`
    does: cable and beam nodes hosted there become free (no grout or link force from now on) and the
    hybrid bolts' dowels with a side there are dropped. The reactions they had put into the hosts'
    applied loads (``physics.cables.pass_reactions``, ``physics.dowels.advance_dowels``) are taken back
    out, so a block filled again later starts without them. Liner nodes coupled there become free too.
    Returns (cable nodes, beam nodes, dowels, liner nodes) released."""
    from .dowels import DOWELS, has_dowels

    mask = np.asarray(mask, bool)
    st = model.stores
    b, v = model.blocks, model.vertices
    out = [0, 0, 0, 0]
    for k, name in ((0, NODES), (1, "beam_nodes"), (3, "liner_nodes")):
        if name not in st or not st[name].n:
            continue
        nodes = st[name]
        h = nodes["host"]
        lost = np.flatnonzero(h >= 0)
        lost = lost[mask[h[lost]]]
        if not lost.size:
            continue
        rig, zn = lost[nodes["hz"][lost] == 0], lost[nodes["hz"][lost] != 0]
        np.add.at(b["fapp"], h[rig], -nodes["hforce"][rig])
        np.add.at(b["mapp"], h[rig], -nodes["hmoment"][rig])
        np.add.at(v["fapp"], nodes["hgp"][zn].ravel(),
                  -(nodes["hw"][zn][:, :, None] * nodes["hforce"][zn][:, None, :]).reshape(-1, 3))
        h[lost] = -1
        nodes["hz"][lost] = 0
        for key in ("hforce", "hmoment", "lf", "lm", "fs", "fn"):
            if key in nodes:
                nodes[key][lost] = 0.0
        if name == NODES:
            segs = st[SEGMENTS]
            segs["gf"][np.isin(segs["na"], lost), 0] = 0.0
            segs["gf"][np.isin(segs["nb"], lost), 1] = 0.0
        out[k] = int(lost.size)
    if has_dowels(model):
        ds = st[DOWELS]
        gone = mask[ds["blk"]].any(axis=1)
        for i in np.flatnonzero(gone):
            for side, sg in ((0, -1.0), (1, 1.0)):
                r = int(ds["blk"][i, side])
                if ds["hz"][i, side] == 0:
                    b["fapp"][r] -= sg * ds["fs"][i]
                    b["mapp"][r] -= ds["moment"][i, side]
                else:
                    np.add.at(v["fapp"], ds["hgp"][i, side], -sg * ds["hw"][i, side][:, None] * ds["fs"][i][None, :])
        if gone.any():
            ds.compact(~gone)
        out[2] = int(gone.sum())
    return out[0], out[1], out[2], out[3]
