"""Zoning blocks of the model (``block zone generate``): the mesher of ``dec3d.geometry.zoning``
applied block by block, conformingly across joined blocks.

Joined blocks (same ``blocks.leader``) are one continuum: when a block is zoned after a joined
neighbour, the neighbour's gridpoints on the common boundary are taken over (tetrahedra: the
regular triangulation then gives the same facet triangles; hexahedra: coinciding points snap to
the neighbour's exact coordinates), and after each command ``relink`` points every duplicate
gridpoint row of a joined set at its master, the lowest row at that position
(``vertices.link``, the contract of ``dec3d.model.zones``). ``conformity`` checks the result:
every surface triangle of a block lying on a joined neighbour must be a triangle of that
neighbour too (same master gridpoints)."""
from __future__ import annotations

import numpy as np

from dec3d.geometry.assemble import block_poly
from dec3d.geometry.errors import GeometryError
from dec3d.geometry.zoning import face_planes, imprint_segments, inside, mesh_convex
from dec3d.geometry.zoning_hex import hex_corners, mesh_hex, to_high_order
from .model import KIND_FE
from .store import Field
from .zones import install_block_mesh, zone_stores


def _ensure(model):
    zs = zone_stores(model)
    if "zlength" not in model.blocks:
        # edge length a block was zoned with (its regular-triangulation weights scale with it)
        model.blocks.add_field("zlength", Field((), np.float64, 0.0))
    return zs


def zoned_blocks(model) -> np.ndarray:
    """Mask over blocks: blocks that have zones."""
    out = np.zeros(model.blocks.n, bool)
    if "zones" in model.stores:
        zs = model.store("zones")
        out[zs["block"][: zs.n]] = True
    return out


def _bid(model, row: int) -> str:
    b = model.blocks
    return f"block {int(b['id'][row])}" if "id" in b else f"block row {row}"


def _hull(model, row: int):
    """Face planes (unique) and gridpoints of a block."""
    b = model.blocks
    poly = block_poly(model, row)
    N, D = face_planes(poly.vertices, poly.face_ptr, poly.face_idx)
    key = np.round(np.c_[N, D] * 1e9)
    _, first = np.unique(key, axis=0, return_index=True)
    v0, nv = int(b["vert_start"][row]), int(b["vert_count"][row])
    return N[first], D[first], model.vertices["pos"][v0:v0 + nv].copy()


def _zoned_partners(model, row: int, boxes=None, zoned=None) -> list[int]:
    zoned = zoned_blocks(model) if zoned is None else zoned
    return [p for p in _joined_near(model, row, boxes) if zoned[p]]


def _boxes(model):
    """Lower and upper corners (n, 3) of every block's vertices."""
    b, v = model.blocks, model.vertices
    st, ct = b["vert_start"][: b.n], b["vert_count"][: b.n]
    order = np.argsort(st)
    pos = v["pos"]
    lo = np.empty((b.n, 3))
    hi = np.empty((b.n, 3))
    idx = np.concatenate([np.arange(st[r], st[r] + ct[r]) for r in order]) if b.n else np.zeros(0, np.int64)
    starts = np.concatenate(([0], np.cumsum(ct[order])[:-1])) if b.n else np.zeros(0, np.int64)
    if b.n:
        lo[order] = np.minimum.reduceat(pos[idx], starts, axis=0)
        hi[order] = np.maximum.reduceat(pos[idx], starts, axis=0)
    return lo, hi


def _joined_near(model, row: int, boxes=None) -> list[int]:
    """Blocks joined to ``row`` whose extents touch its own (``boxes``: ``_boxes`` when known)."""
    b = model.blocks
    lead = b["leader"][: b.n]
    cand = np.flatnonzero(lead == lead[row])
    cand = cand[cand != row]
    if not len(cand):
        return []
    lo, hi = boxes if boxes is not None else _boxes(model)
    pad = 1e-6 * float(np.linalg.norm(hi[row] - lo[row]))
    ok = (lo[cand] <= hi[row] + pad).all(axis=1) & (hi[cand] >= lo[row] - pad).all(axis=1)
    return [int(r) for r in cand[ok]]


def zone_tetra(model, rows, L: float) -> int:
    """4-node tetrahedral zoning at edge length L of the unzoned blocks ``rows``; returns zones made."""
    _ensure(model)
    made = 0
    boxes = _boxes(model)
    zoned = zoned_blocks(model)
    for r in rows:
        neigh = []
        for p in _zoned_partners(model, r, boxes, zoned):
            N, D, pts = _hull(model, p)
            neigh.append((N, D, pts, float(model.blocks["zlength"][p]) or float(np.ptp(pts, axis=0).max())))
        poly = block_poly(model, r)
        # an edge length beyond the block's size zones it as if it were the size (same points)
        Lr = min(L, float(np.linalg.norm(poly.vertices.max(axis=0) - poly.vertices.min(axis=0))))
        segs = []
        for p in _joined_near(model, r, boxes):
            if not zoned[p]:
                o = block_poly(model, p)
                segs.append(imprint_segments(poly.vertices, poly.face_ptr, poly.face_idx, o.vertices, o.face_ptr,
                                             o.face_idx, 1e-6 * Lr))
        segs = np.concatenate(segs) if segs else np.zeros((0, 2, 3))
        pts, tets, tris, src = mesh_convex(poly.vertices, poly.face_ptr, poly.face_idx, Lr, neighbours=neigh,
                                           imprint=segs)
        install_block_mesh(model, r, pts, tets, tris, src, compact=False)
        zoned[r] = True
        model.blocks["zlength"][r] = Lr
        made += len(tets)
    _compact(model)
    relink(model)
    return made


def zone_hexahedra(model, rows, divisions) -> int:
    """Hexahedral mixed zoning (n1 n2 n3 cells) of the unzoned blocks ``rows``."""
    _ensure(model)
    for r in rows:  # check every block before zoning any
        poly = block_poly(model, r)
        hex_corners(poly.vertices, poly.face_ptr, poly.face_idx, _bid(model, r))
    made = 0
    boxes = _boxes(model)
    zoned = zoned_blocks(model)
    for r in rows:
        snap = [_hull(model, p)[2] for p in _zoned_partners(model, r, boxes, zoned)]
        poly = block_poly(model, r)
        pts, tets, hexid, overlay, tris, src = mesh_hex(poly.vertices, poly.face_ptr, poly.face_idx, divisions,
                                                        _bid(model, r), np.concatenate(snap) if snap else None)
        install_block_mesh(model, r, pts, tets, tris, src, hexid, overlay, compact=False)
        zoned[r] = True
        ext = poly.vertices.max(axis=0) - poly.vertices.min(axis=0)
        model.blocks["zlength"][r] = float(np.mean(ext / np.asarray(divisions, float)))
        made += len(tets)
    _compact(model)
    relink(model)
    return made


def convert_high_order(model, rows) -> int:
    """Make the 4-node tetrahedral zones of blocks ``rows`` 10-node ones (blocks already of
    10-node zones are left as they are); returns the number of zones converted."""
    zs = _ensure(model)
    b, f = model.blocks, model.faces
    done = 0
    old_rows = []
    for r in rows:
        zrow = np.flatnonzero(zs["block"][: zs.n] == r)
        if not len(zrow) or (zs["nnode"][zrow] == 10).all():
            continue
        if (zs["hex"][zrow] >= 0).any():
            raise GeometryError(f"{_bid(model, r)} has hexahedral zones: high-order-tetra converts "
                                "4-node tetrahedral zones only")
        v0, nv = int(b["vert_start"][r]), int(b["vert_count"][r])
        pts = model.vertices["pos"][v0:v0 + nv].copy()
        tets = zs["gp"][zrow, :4] - v0
        f0, fc = int(b["face_start"][r]), int(b["face_count"][r])
        tris = model.face_vertices["vertex"][f["vstart"][f0:f0 + fc][:, None] + np.arange(3)[None, :]] - v0
        source = f["source"][f0:f0 + fc].copy()
        keep_fields = {k: zs[k][zrow].copy() for k in ("cmodel", "prop", "stress", "state", "group")}
        p10, t10, sub, parent = to_high_order(pts, tets, tris)
        old_rows.append(zrow)
        sl = install_block_mesh(model, r, p10, t10, sub, source[parent], face_rows=f0 + parent, compact=False)
        for k, val in keep_fields.items():
            zs[k][sl] = val
        zs["gstress"][sl] = zs["stress"][sl][:, None, :]
        done += len(zrow)
    if old_rows:
        keep = np.ones(zs.n, bool)
        keep[np.concatenate(old_rows)] = False
        zs.compact(keep)
    _compact(model)
    relink(model)
    return done


def _compact(model) -> None:
    """Drop the vertex and face rows the zoned blocks no longer use (once per command)."""
    from dec3d.geometry.assemble import compact_geometry
    from .zones import follow_geometry
    follow_geometry(model, compact_geometry(model))


def relink(model) -> int:
    """Point each duplicate gridpoint of a joined set (same coordinates, another zoned block of
    the same leader) at its master, the lowest row; returns the number of links."""
    v, b = model.vertices, model.blocks
    fe = b["kind"][: b.n] == KIND_FE
    if "zones" not in model.stores and not fe.any():
        return 0
    link = v["link"]
    zoned = zoned_blocks(model) | fe
    link[v["zoned"]] = -1
    lead = b["leader"][: b.n]
    # FE slave nodes (mid-face) follow their own element's masters: never linked
    free = ~v["feslave"] if "feslave" in v else np.ones(v.n, bool)
    n = 0
    for ld in np.unique(lead[zoned]):
        rows = np.flatnonzero(zoned & (lead == ld))
        if len(rows) < 2:
            continue
        gp = np.concatenate([np.arange(b["vert_start"][r], b["vert_start"][r] + b["vert_count"][r]) for r in rows])
        gp = gp[free[gp]]
        pos = v["pos"][gp] + 0.0
        if fe[rows].any():
            # FE blocks are meshed one by one, not snapped to their neighbours: nodes that coincide
            # can differ by round-off (1e-15 m at the joints of a ring of FE liner blocks)
            h = 1e-9 * max(float(np.ptp(pos, axis=0).max()), 1e-12)
            pos = np.round(pos / h) * h + 0.0
        _, inv = np.unique(pos, axis=0, return_inverse=True)
        inv = inv.ravel()
        master = np.full(inv.max() + 1, np.iinfo(np.int64).max)
        np.minimum.at(master, inv, gp)
        m = master[inv]
        dup = m != gp
        link[gp[dup]] = m[dup]
        n += int(dup.sum())
    return n


def conformity(model) -> dict:
    """Check joined zoned blocks: for every pair of joined zoned blocks, the surface triangles of
    one lying on the other (centroid on its boundary) must be triangles of the other with the
    same master gridpoints. Returns {"pairs": pairs in contact, "triangles": triangles checked,
    "unmatched": [(block id, neighbour id, count)], "link_gap": largest distance between a
    linked gridpoint and its master}."""
    v, b, f = model.vertices, model.blocks, model.faces
    out = {"pairs": 0, "triangles": 0, "unmatched": [], "link_gap": 0.0}
    if "zones" not in model.stores:
        return out
    link = v["link"]
    lk = np.flatnonzero(link >= 0)
    if len(lk):
        out["link_gap"] = float(np.linalg.norm(v["pos"][lk] - v["pos"][link[lk]], axis=1).max())
    master = np.where(link >= 0, link, np.arange(v.n))
    zoned = np.flatnonzero(zoned_blocks(model))
    tri, keys = {}, {}
    for r in zoned:
        f0, fc = int(b["face_start"][r]), int(b["face_count"][r])
        nodes = model.face_vertices["vertex"][f["vstart"][f0:f0 + fc][:, None] + np.arange(3)[None, :]]
        tri[r] = nodes
        keys[r] = set(map(tuple, np.sort(master[nodes], axis=1).tolist()))
    boxes, zmask = _boxes(model), zoned_blocks(model)
    hulls = {}
    for r in zoned:
        for p in _zoned_partners(model, int(r), boxes, zmask):
            if p not in hulls:
                hulls[p] = _hull(model, p)
            N, D, pts = hulls[p]
            ext = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
            cen = v["pos"][tri[r]].mean(axis=1)
            on = inside(cen, N, D, 1e-9 * ext)
            if not on.any():
                continue
            out["pairs"] += 1
            k = np.sort(master[tri[r][on]], axis=1)
            out["triangles"] += int(on.sum())
            miss = sum(1 for t in map(tuple, k.tolist()) if t not in keys[p])
            if miss:
                out["unmatched"].append((_bid(model, int(r)), _bid(model, p), miss))
    return out


def mesh_quality(model, block_rows=None) -> dict:
    """Figures of the zoning over the blocks ``block_rows`` (all zoned blocks when None): those of
    ``zone_quality.mesh_information`` (the one implementation, used by ``block zone list
    information``), with ``zones`` counting a hexahedral zone once and ``tetrahedra`` the zone rows."""
    from .zone_quality import mesh_information
    out = {"zones": 0, "tetrahedra": 0, "gridpoints": 0, "edge_min": None, "edge_max": None,
           "dihedral_min": None, "volume_min": None}
    if "zones" not in model.stores or model.store("zones").n == 0:
        return out
    zs = model.store("zones")
    sel = np.ones(zs.n, bool) if block_rows is None else np.isin(zs["block"][: zs.n], block_rows)
    rows = np.flatnonzero(sel)
    if rows.size == 0:
        return out
    out.update(mesh_information(model, rows))
    hexid = zs["hex"][rows]
    out["tetrahedra"] = int(rows.size)
    out["zones"] = int((hexid < 0).sum() + len(np.unique(hexid[hexid >= 0])))
    return out
