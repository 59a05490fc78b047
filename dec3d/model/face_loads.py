"""Applied face stresses on the boundary triangles of zoned blocks (``block face apply stress``).

Each loaded triangle keeps the stress applied to it (``faces.fstress``, 6 components xx yy zz xy
xz yz, tension positive); ``vertices.fface`` is recomputed from all of them: traction t = σ·n on
the triangle, force t·A shared equally (A/3) by its three gridpoints. Loads add (as 3DEC does);
``apply-remove`` clears the record of the faces in range and recomputes, so removal is exact.
A face of a 10-node zone is on the surface as four triangles (corner, corner, corner and the
middle one of its mid-edge nodes); when all four carry the same stress the face is loaded as
one 6-node triangle with the consistent loads of ``kernels.zones_ho.tri6_traction_loads`` (0 at
the corners, A/3 at the mid-edge nodes for a flat face), which a 10-node mesh needs to carry a
uniform stress exactly; thirds of the four triangles (A/12 and A/4) would not.
A face of a hexahedral zone (two overlaid 5-tetrahedron sets, ``zones.hex``) is on the surface as
two triangles split on one diagonal, while the other overlay splits it on the other diagonal;
when both triangles carry the same stress the face is loaded as the quadrilateral: the mean of
the thirds of the two splits (A/4 per corner of a flat parallelogram; thirds of one split alone
would give A/3 at the diagonal's ends and A/6 at the others, and zone stresses would spread).
The pairs are found from the zones: two loaded triangles of one block on one source face that
are faces of tetrahedra of the same hexahedral zone and share two gridpoints.
A face of a 20-node element of an FE block is on the surface as eight triangles fanned around its
mid-face slave node; when all eight carry the same stress the face is loaded as the 8-node
element face with the consistent loads of ``kernels.feblock_shape.face_stress_loads`` (the
integral of N_a sigma n over the face: -A/12 at each corner and A/3 at each mid-edge node of a
flat parallelogram face), which a 20-node mesh needs to carry a uniform stress exactly; thirds of
the eight triangles, the slave's share sent to the masters by the text's Eq. (9), give 0 at the
corners and A/4 at the mid-edge nodes: a bar of 4 x 1 x 1 elements pulled by a face stress
then ended 0.8 to 15 % beyond sigma L / E over its end face (exact with the consistent loads). Faces loaded in part (a range that cuts an element face) keep the thirds.
Only triangles on the outside of a joined continuum take loads: a triangle whose gridpoints
(resolved to their link masters; FE slave nodes to the lowest slave row at the same position) are
also a triangle of another block is interior.
"""
from __future__ import annotations

import numpy as np

from .store import Field
from .zones import zone_stores


def _ensure(model) -> None:
    zone_stores(model)
    if "fstress" not in model.faces:
        model.faces.add_field("fstress", Field((6,), np.float64, 0.0))


def _triangle_nodes(model, rows: np.ndarray) -> np.ndarray:
    f, fv = model.faces, model.face_vertices
    return fv["vertex"][f["vstart"][rows][:, None] + np.arange(3)[None, :]]


def loadable_faces(model) -> np.ndarray:
    """Mask over faces: triangles of zoned blocks on the outside of their (joined) continuum."""
    _ensure(model)
    f, v = model.faces, model.vertices
    out = np.zeros(f.n, bool)
    if not f.n:
        return out
    zoned_blk = np.zeros(model.blocks.n, bool)
    zoned_blk[v["block"][v["zoned"]]] = True
    cand = np.flatnonzero(zoned_blk[f["block"]] & (f["nvert"] == 3))
    if not len(cand):
        return out
    link = v["link"]
    master = np.where(link >= 0, link, np.arange(v.n))
    if "feslave" in v:
        # slave nodes are never linked (they follow their element): coincident ones are one point
        sr = np.flatnonzero(v["feslave"])
        if len(sr):
            _, inv = np.unique(v["pos"][sr], axis=0, return_inverse=True)
            inv = inv.ravel()
            low = np.full(int(inv.max()) + 1, np.iinfo(np.int64).max)
            np.minimum.at(low, inv, sr)
            master[sr] = low[inv]
    keys = np.sort(master[_triangle_nodes(model, cand)], axis=1)
    _, inv, cnt = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    out[cand[cnt[inv.ravel()] == 1]] = True
    return out


def recompute_fface(model) -> None:
    """``vertices.fface`` from the stresses recorded on the faces (current positions)."""
    _ensure(model)
    f, v = model.faces, model.vertices
    v["fface"][:] = 0.0
    rows = np.flatnonzero(np.any(f["fstress"] != 0.0, axis=1))
    if not len(rows):
        return
    nodes = _triangle_nodes(model, rows)
    p = v["pos"][nodes]
    an = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])      # outward normal times area
    s = f["fstress"][rows]
    sig = np.empty((len(rows), 3, 3))
    sig[:, 0, 0], sig[:, 1, 1], sig[:, 2, 2] = s[:, 0], s[:, 1], s[:, 2]
    sig[:, 0, 1] = sig[:, 1, 0] = s[:, 3]
    sig[:, 0, 2] = sig[:, 2, 0] = s[:, 4]
    sig[:, 1, 2] = sig[:, 2, 1] = s[:, 5]
    tri6, members = _tri6_faces(model, nodes, s)
    thirds = np.ones(len(rows), bool)
    if len(tri6):
        from dec3d.kernels.zones_ho import tri6_traction_loads
        thirds[members.ravel()] = False
        a6 = an[members].sum(axis=1)                                # the 6-node face's area vector
        unit = a6 / np.linalg.norm(a6, axis=1)[:, None]
        trac = np.ascontiguousarray(np.einsum("kij,kj->ki", sig[members[:, 0]], unit))
        tri6_traction_loads(v["pos"], np.ascontiguousarray(tri6), trac, v["fface"])
    quads, fmem = _fe_faces(model, nodes, s)
    if len(quads):
        from dec3d.kernels.feblock_shape import face_stress_loads
        thirds[fmem.ravel()] = False
        face_stress_loads(v["pos"], quads, np.ascontiguousarray(s[fmem[:, 0]]), v["fface"])
    rest = np.flatnonzero(thirds)
    pairs = _hex_quads(model, rows[rest], nodes[rest], s[rest])
    weight = np.ones(len(rows))
    if len(pairs):
        pairs = rest[pairs]                                         # (q, 2) indices into rows
        weight[pairs.ravel()] = 0.5                                 # half from this split …
        t1, t2 = nodes[pairs[:, 0]], nodes[pairs[:, 1]]
        in2 = (t1[:, :, None] == t2[:, None, :]).any(axis=2)        # (q, 3) nodes of t1 also in t2
        o1 = t1[~in2]                                               # corner of t1 off the diagonal
        o2 = t2[~(t2[:, :, None] == t1[:, None, :]).any(axis=2)]
        d = t1[in2].reshape(-1, 2)                                  # the diagonal's two corners
        up = an[pairs[:, 0]] + an[pairs[:, 1]]
        sq = sig[pairs[:, 0]]
        for k in range(2):                                          # … half from the other split
            tri = np.column_stack([o1, o2, d[:, k]])
            q = v["pos"][tri]
            a2 = 0.5 * np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0])
            a2 *= np.where(np.einsum("ij,ij->i", a2, up) < 0.0, -1.0, 1.0)[:, None]
            f2 = 0.5 * np.einsum("kij,kj->ki", sq, a2) / 3.0
            for c in range(3):
                np.add.at(v["fface"], tri[:, c], f2)
    force = weight[thirds, None] * np.einsum("kij,kj->ki", sig[thirds], an[thirds]) / 3.0
    for k in range(3):
        np.add.at(v["fface"], nodes[thirds, k], force)


def _fe_faces(model, nodes: np.ndarray, fstress: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 8-node faces of FE elements whose eight surface triangles (fanned around the face's
    slave node) are all among the loaded ones (``nodes`` (k, 3), their stresses ``fstress``) with
    one stress: (g, 8) node rows in the layout of ``kernels.feblock_shape.FACES`` and (g, 8)
    indices into ``nodes`` of their triangles."""
    v = model.vertices
    empty = (np.zeros((0, 8), np.int64), np.zeros((0, 8), np.int64))
    if "feslave" not in v or "feblocks" not in model.stores or not len(nodes):
        return empty
    from dec3d.kernels.feblock_shape import FACES
    es = model.store("feblocks")
    sl = v["feslave"][nodes]
    tri = np.flatnonzero(sl.sum(axis=1) == 1)
    if not len(tri):
        return empty
    slave = nodes[tri][sl[tri]]
    # element face of each slave row: 6 e + s
    e, s = np.nonzero(es["slaves"][:, :6] >= 0)
    owner = np.full(v.n, -1, np.int64)
    owner[es["slaves"][e, s]] = 6 * e + s
    order = np.lexsort((tri, slave))
    slave, tri = slave[order], tri[order]
    uniq, start, cnt = np.unique(slave, return_index=True, return_counts=True)
    full = (cnt == 8) & (owner[uniq] >= 0)
    mem = tri[start[full][:, None] + np.arange(8)[None, :]]
    same = np.all(fstress[mem] == fstress[mem[:, :1]], axis=(1, 2))
    ef = owner[uniq[full][same]]
    quads = es["nodes"][(ef // 6)[:, None], FACES[ef % 6]]
    return np.ascontiguousarray(quads, np.int64), mem[same]


def _hex_quads(model, frows: np.ndarray, nodes: np.ndarray, fstress: np.ndarray) -> np.ndarray:
    """Pairs (q, 2) of indices into ``frows`` (face rows, triangle ``nodes`` (k, 3), stresses
    ``fstress``) that are the two surface triangles of one face of one hexahedral zone with one
    stress."""
    zs = model.store("zones")
    empty = np.zeros((0, 2), np.int64)
    if not len(frows):
        return empty
    f = model.faces
    blk = f["block"][frows]
    # only tetrahedra with three loaded gridpoints can have a loaded triangle as a face (and both
    # tetrahedra on any such face are kept, so the count of a face below is not changed)
    loaded = np.zeros(model.vertices.n, bool)
    loaded[nodes.ravel()] = True
    g = zs["gp"][:, :4]
    hx = np.flatnonzero((zs["hex"] >= 0) & (loaded[np.maximum(g, 0)].sum(axis=1) >= 3)
                        & np.isin(zs["block"], np.unique(blk)))
    if not len(hx):
        return empty
    g = g[hx]
    tri = np.sort(np.concatenate([g[:, [0, 1, 2]], g[:, [0, 1, 3]], g[:, [0, 2, 3]], g[:, [1, 2, 3]]]), axis=1)
    owner = np.tile(hx, 4)
    # a surface triangle is a face of one tetrahedron only; faces inside the mesh appear twice
    _, first, cnt = np.unique(tri, axis=0, return_index=True, return_counts=True)
    keep = first[cnt == 1]
    at = _lookup(tri[keep], np.sort(nodes, axis=1))
    found = np.flatnonzero(at >= 0)
    if len(found) < 2:
        return empty
    z = owner[keep[at[found]]]
    key = np.column_stack([zs["block"][z], zs["hex"][z], f["source"][frows[found]]])
    order = np.lexsort(key.T[::-1])
    key, found = key[order], found[order]
    same = np.all(key[1:] == key[:-1], axis=1)
    # exactly two triangles per (block, hexahedron, source face)
    start = np.flatnonzero(same & ~np.r_[False, same[:-1]] & ~np.r_[same[1:], False])
    i, j = found[start], found[start + 1]
    shared = (nodes[i][:, :, None] == nodes[j][:, None, :]).any(axis=2).sum(axis=1)
    ok = (shared == 2) & np.all(fstress[i] == fstress[j], axis=1)
    return np.column_stack([i[ok], j[ok]])


#: the faces of a 10-node zone as 6-node triangles (zone node columns: corners 0-3, then the
#: mid-edge nodes of edges 01 12 20 03 13 23): corners a b c, then the mid-points of ab bc ca
_TRI6 = ((0, 1, 2, 4, 5, 6), (1, 2, 3, 5, 9, 8), (0, 2, 3, 6, 9, 7), (0, 1, 3, 4, 8, 7))


def _lookup(table: np.ndarray, queries: np.ndarray) -> np.ndarray:
    """Row of ``table`` (k, 3 sorted, rows distinct) equal to each query row, −1 for none."""
    if not len(table) or not len(queries):
        return np.full(len(queries), -1, np.int64)
    _, inv = np.unique(np.vstack([table, queries]), axis=0, return_inverse=True)
    inv = inv.ravel()
    at = np.full(int(inv.max()) + 1, -1, np.int64)
    at[inv[: len(table)]] = np.arange(len(table))
    return at[inv[len(table):]]


def _tri6_faces(model, nodes: np.ndarray, fstress: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 6-node faces of 10-node zones whose four surface triangles are all among the loaded
    ones (``nodes`` (k, 3), their stresses ``fstress``) with one stress: (g, 6) node rows and
    (g, 4) indices into ``nodes`` of their triangles."""
    zs = model.store("zones")
    ten = np.flatnonzero(zs["nnode"] == 10)
    empty = (np.zeros((0, 6), np.int64), np.zeros((0, 4), np.int64))
    if not len(ten):
        return empty
    g = zs["gp"][ten]
    faces = np.concatenate([g[:, list(c)] for c in _TRI6])                     # (4 m, 6)
    c0, c1, c2, m01, m12, m20 = faces.T
    subs = [np.column_stack(t) for t in ((c0, m01, m20), (m01, c1, m12), (m20, m12, c2), (m01, m12, m20))]
    table = np.sort(nodes, axis=1)
    idx = np.column_stack([_lookup(table, np.sort(t, axis=1)) for t in subs])  # (4 m, 4)
    ok = (idx >= 0).all(axis=1)
    idx, faces = idx[ok], faces[ok]
    same = np.all(fstress[idx] == fstress[idx[:, :1]], axis=(1, 2))
    return faces[same], idx[same]


def apply_face_stress(model, mask: np.ndarray, stress6: np.ndarray) -> int:
    """Add ``stress6`` to the loadable faces in ``mask``; returns how many faces took it."""
    _ensure(model)
    rows = np.flatnonzero(mask & loadable_faces(model))
    model.faces["fstress"][rows] += np.asarray(stress6, np.float64)
    recompute_fface(model)
    return len(rows)


def remove_face_stress(model, mask: np.ndarray) -> int:
    _ensure(model)
    rows = np.flatnonzero(mask & (np.any(model.faces["fstress"] != 0.0, axis=1)))
    model.faces["fstress"][rows] = 0.0
    recompute_fface(model)
    return len(rows)
