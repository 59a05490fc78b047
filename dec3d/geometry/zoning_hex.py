"""Zoning of blocks (issue 10), the structured part: six-faced blocks into hexahedral
mixed-discretization zones, and 4-node meshes into 10-node tetrahedra (the tetrahedral mesher
is ``dec3d.geometry.zoning``).

Hexahedra (``mesh_hex``): the trilinear map of the block's eight corners, n1 x n2 x n3 cells,
each cell as two overlaid sets of five tetrahedra (3DEC theory text, "Mixed discretization":
"an 8-node zone with 2 overlays of 5 tetrahedra in each overlay"). The text's Figure 16 (which
would show the diagonal pattern) is missing from the extraction; dec3d uses the standard
alternating pattern: in overlay ``k`` the central tetrahedron of a cell joins the four corners
whose global lattice parity ``(i + j + k) % 2`` equals ``k``, so the face diagonals of
neighbouring cells meet in each overlay and the two overlays use the two opposite diagonals on
every face. The block surface takes one diagonal per boundary quadrilateral, the one through
its corner with the smallest position (lexicographic), so the surface triangles do not depend
on the overlay and two joined blocks choose alike on a shared face.

10-node tetrahedra (``to_high_order``): a node at the midpoint of every zone edge, shared by
the zones around the edge (3DEC theory text, "Higher-Order Tetrahedral Elements"); each
boundary triangle split in four."""
from __future__ import annotations

import numpy as np

from .errors import GeometryError
from .zoning import _five, _row_keys, face_planes


def hex_corners(verts: np.ndarray, ptr: np.ndarray, loops: np.ndarray, label: str = "the block") -> np.ndarray:
    """Local vertex index of the corners (8,) in the order c[i + 2j + 4k] = corner (i, j, k) of
    the unit cube. Corner (0,0,0) is the vertex with the smallest position; its three edges are
    given to the axes they point most along (x, y, z for divisions n1, n2, n3)."""
    nf = len(ptr) - 1
    sizes = np.diff(ptr)
    if nf != 6 or len(verts) != 8 or (sizes != 4).any():
        raise GeometryError(f"{label} is not hexahedral ({nf} faces, {len(verts)} vertices): "
                            "`block zone generate hexahedra` needs six four-sided faces")
    adj = {v: set() for v in range(8)}
    for f in range(nf):
        lp = [int(x) for x in loops[ptr[f]:ptr[f + 1]]]
        for i in range(4):
            a, b = lp[i], lp[(i + 1) % 4]
            adj[a].add(b)
            adj[b].add(a)
    if any(len(s) != 3 for s in adj.values()):
        raise GeometryError(f"{label} is not hexahedral (a vertex does not meet exactly three edges)")
    o = min(range(8), key=lambda v: tuple(verts[v]))
    nb = sorted(adj[o])
    d = np.array([verts[v] - verts[o] for v in nb])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    import itertools
    best = max(itertools.permutations(range(3)), key=lambda pm: sum(abs(d[pm[a], a]) for a in range(3)))
    ax = [nb[best[a]] for a in range(3)]
    c = [-1] * 8
    c[0], c[1], c[2], c[4] = o, ax[0], ax[1], ax[2]

    def common(a, b, exclude):
        s = (adj[a] & adj[b]) - {exclude}
        if len(s) != 1:
            raise GeometryError(f"{label} is not hexahedral (its faces do not close like a cube's)")
        return s.pop()
    c[3] = common(c[1], c[2], o)
    c[5] = common(c[1], c[4], o)
    c[6] = common(c[2], c[4], o)
    rest = set(range(8)) - set(c[:7])
    c[7] = rest.pop()
    if {c[3], c[5], c[6]} != adj[c[7]]:
        raise GeometryError(f"{label} is not hexahedral (its faces do not close like a cube's)")
    return np.array(c, np.int64)


def mesh_hex(verts: np.ndarray, ptr: np.ndarray, loops: np.ndarray, divisions, label: str = "the block",
             snap: np.ndarray | None = None):
    """Hexahedral zoning of a six-faced block: points (n,3), tets (10 n1 n2 n3, 4) positive,
    hexid and overlay per tetrahedron, boundary tris (k,3) and their face index.

    ``snap``: gridpoints of zoned joined neighbours; a boundary point within round-off of one
    takes its exact coordinates (so linked gridpoints coincide exactly)."""
    verts = np.asarray(verts, float)
    n1, n2, n3 = (int(x) for x in divisions)
    if min(n1, n2, n3) < 1:
        raise GeometryError("hexahedra divisions must be at least 1")
    c = hex_corners(verts, ptr, loops, label)
    X = verts[c].reshape(2, 2, 2, 3)          # X[k, j, i]
    s = np.arange(n1 + 1) / n1
    t = np.arange(n2 + 1) / n2
    u = np.arange(n3 + 1) / n3
    S, T, U = np.meshgrid(s, t, u, indexing="ij")
    S, T, U = S[..., None], T[..., None], U[..., None]
    P = ((1 - S) * (1 - T) * (1 - U) * X[0, 0, 0] + S * (1 - T) * (1 - U) * X[0, 0, 1]
         + (1 - S) * T * (1 - U) * X[0, 1, 0] + S * T * (1 - U) * X[0, 1, 1]
         + (1 - S) * (1 - T) * U * X[1, 0, 0] + S * (1 - T) * U * X[1, 0, 1]
         + (1 - S) * T * U * X[1, 1, 0] + S * T * U * X[1, 1, 1])
    # corners exactly the block's vertices
    for k in range(2):
        for j in range(2):
            for i in range(2):
                P[i * n1, j * n2, k * n3] = X[k, j, i]
    pts = P.reshape(-1, 3).copy()
    size = float(np.linalg.norm(verts.max(axis=0) - verts.min(axis=0)))
    if snap is not None and len(snap):
        from scipy.spatial import cKDTree
        dist, idx = cKDTree(snap).query(pts, distance_upper_bound=1e-9 * size)
        hit = np.isfinite(dist)
        pts[hit] = snap[idx[hit]]

    def gid(i, j, k):
        return (i * (n2 + 1) + j) * (n3 + 1) + k

    tets, hexid, overlay = [], [], []
    patterns = {p: _five(p) for p in (0, 1)}
    I, J, K = np.meshgrid(np.arange(n1), np.arange(n2), np.arange(n3), indexing="ij")
    I, J, K = I.ravel(), J.ravel(), K.ravel()
    cellpar = (I + J + K) % 2
    for ov in (0, 1):
        for par in (0, 1):
            # local central parity p with (cell parity + p) % 2 == ov
            sel = np.flatnonzero(cellpar == (ov - par) % 2)
            for tet in patterns[par]:
                rows = np.stack([gid(I[sel] + a, J[sel] + b, K[sel] + cc) for a, b, cc in tet], axis=1)
                tets.append(rows)
                hexid.append(sel)
                overlay.append(np.full(len(sel), ov))
    tets = np.concatenate(tets).astype(np.int64)
    hexid = np.concatenate(hexid).astype(np.int64)
    overlay = np.concatenate(overlay).astype(np.int8)
    order = np.lexsort((overlay, hexid))
    tets, hexid, overlay = tets[order], hexid[order], overlay[order]
    # orientation in the reference lattice and in space must agree (up to the map's handedness)
    R = np.stack(np.meshgrid(np.arange(n1 + 1), np.arange(n2 + 1), np.arange(n3 + 1), indexing="ij"),
                 axis=-1).reshape(-1, 3).astype(float)
    ra, rb, rc, rd = (R[tets[:, k]] for k in range(4))
    sref = np.sign(np.einsum("ij,ij->i", np.cross(rb - ra, rc - ra), rd - ra))
    a, b, cc, d = (pts[tets[:, k]] for k in range(4))
    vol = np.einsum("ij,ij->i", np.cross(b - a, cc - a), d - a) / 6.0
    cell = float(np.linalg.norm(verts.max(axis=0) - verts.min(axis=0))) / max(n1, n2, n3)
    rel = vol * sref
    if not ((rel > 1e-12 * cell ** 3).all() or (rel < -1e-12 * cell ** 3).all()):
        raise GeometryError(f"{label} is too distorted for hexahedral zoning (a tetrahedron of its "
                            "trilinear map is flat or inverted)")
    neg = vol < 0
    tets[neg] = tets[neg][:, [0, 2, 1, 3]]
    # boundary quadrilaterals of the cell grid, two triangles each
    tris = _hex_surface(pts, n1, n2, n3, gid)
    N, D = face_planes(verts, ptr, loops)
    cen = pts[tris].mean(axis=1)
    src = np.argmin(np.abs(cen @ N.T - D), axis=1)
    # counter-clockwise from outside: the normal along the face's outward normal
    nrm = np.cross(pts[tris[:, 1]] - pts[tris[:, 0]], pts[tris[:, 2]] - pts[tris[:, 0]])
    flip = np.einsum("ij,ij->i", nrm, N[src]) < 0
    tris[flip] = tris[flip][:, [0, 2, 1]]
    return pts, tets, hexid, overlay, tris, src


def _hex_surface(pts, n1, n2, n3, gid):
    quads = []
    ns = (n1, n2, n3)
    for axis in range(3):
        o1, o2 = [a for a in range(3) if a != axis]
        for side in (0, ns[axis]):
            A, B = np.meshgrid(np.arange(ns[o1]), np.arange(ns[o2]), indexing="ij")
            A, B = A.ravel(), B.ravel()
            corners = []
            for da, db in ((0, 0), (1, 0), (1, 1), (0, 1)):
                idx = [None, None, None]
                idx[axis] = np.full(len(A), side)
                idx[o1] = A + da
                idx[o2] = B + db
                corners.append(gid(*idx))
            quads.append(np.stack(corners, axis=1))
    quads = np.concatenate(quads)
    # the diagonal through the corner with the smallest position
    key = pts[quads]                                   # (q, 4, 3)
    first = np.array([min(range(4), key=lambda m: tuple(key[r, m])) for r in range(len(quads))])
    tris = []
    for r, f in enumerate(first):
        q = np.roll(quads[r], -f)
        tris.append((q[0], q[1], q[2]))
        tris.append((q[0], q[2], q[3]))
    return np.array(tris, np.int64)


# ---------------------------------------------------------------------------------------------
# 10-node tetrahedra

#: corner pairs of the mid-edge nodes 4..9 of a 10-node tetrahedron (dec3d.model.zones)
HO_EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))


def to_high_order(pts: np.ndarray, tets: np.ndarray, tris: np.ndarray):
    """10-node tetrahedra from 4-node ones: points (n + e, 3) with a node at the midpoint of
    every edge (shared by the zones around it), tets (m, 10), and each boundary triangle split
    in four (k*4, 3) with ``parent`` (k*4,) the triangle it came from."""
    pts = np.asarray(pts, float)
    tets = np.asarray(tets, np.int64)[:, :4]
    e = np.concatenate([tets[:, list(p)] for p in HO_EDGES])
    e = np.sort(e, axis=1)
    _, first, inv = np.unique(_row_keys(e), return_index=True, return_inverse=True)
    uniq = e[first]
    inv = inv.ravel()
    mid = 0.5 * (pts[uniq[:, 0]] + pts[uniq[:, 1]])
    n = len(pts)
    m = len(tets)
    t10 = np.concatenate([tets, (n + inv).reshape(6, m).T], axis=1)
    # mid node of a boundary edge, by the same edge table
    ekey = uniq[:, 0] * (n + 1) + uniq[:, 1]

    def mid_of(a, b):
        k = np.minimum(a, b) * (n + 1) + np.maximum(a, b)
        return n + np.searchsorted(ekey, k)
    tris = np.asarray(tris, np.int64)
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    ab, bc, ca = mid_of(a, b), mid_of(b, c), mid_of(c, a)
    sub = np.stack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1),
                    np.stack([ab, bc, ca], 1)], axis=1).reshape(-1, 3)
    parent = np.repeat(np.arange(len(tris)), 4)
    return np.concatenate([pts, mid]), t10, sub, parent
