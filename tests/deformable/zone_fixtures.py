"""A 10-node zone by hand, for tests that need one before the mesher makes them: a tetrahedral
block becomes one quadratic tetrahedron (corners, then the mid-points of edges 01 12 20 03 13 23),
each face split into four triangles at the mid-points."""
from __future__ import annotations

import numpy as np

from dec3d.geometry.assemble import block_poly
from dec3d.model.zones import install_block_mesh

_EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))


def zone_tet10(model, row: int):
    poly = block_poly(model, row)
    c = np.array(poly.vertices, float)
    assert len(c) == 4, "a tetrahedral block"
    if np.dot(np.cross(c[1] - c[0], c[2] - c[0]), c[3] - c[0]) < 0:
        order = [0, 2, 1, 3]
    else:
        order = [0, 1, 2, 3]
    mids = np.array([(c[order[i]] + c[order[j]]) / 2 for i, j in _EDGES])
    pts = np.vstack([c, mids])
    node = {frozenset((order[i], order[j])): 4 + k for k, (i, j) in enumerate(_EDGES)}
    tet = np.array(order + list(range(4, 10)))[None, :]
    cen = c.mean(axis=0)
    tris, src = [], []
    for f in range(poly.nfaces):
        loop = [int(x) for x in poly.face_idx[poly.face_ptr[f]:poly.face_ptr[f + 1]]]
        a, b, d = loop
        mab, mbd, mda = node[frozenset((a, b))], node[frozenset((b, d))], node[frozenset((d, a))]
        for t in ((a, mab, mda), (mab, b, mbd), (mda, mbd, d), (mab, mbd, mda)):
            p = pts[list(t)]
            if np.dot(np.cross(p[1] - p[0], p[2] - p[0]), p[0] - cen) < 0:
                t = (t[0], t[2], t[1])
            tris.append(t)
            src.append(f)
    return install_block_mesh(model, row, pts, tet, np.array(tris), np.array(src))


def zone_convex_tet10(model, row: int, edge: float):
    """Zone a convex block into 10-node tetrahedra: the mesher's 4-node tetrahedra of about
    ``edge`` with a node added at the middle of every edge, each surface triangle split in four
    at its mid-edge nodes (what `block zone generate high-order-tetra` is to make)."""
    from dec3d.geometry.zoning import mesh_convex
    poly = block_poly(model, row)
    pts, tets, tris, src = mesh_convex(poly.vertices, poly.face_ptr, poly.face_idx, edge)
    pts = [np.asarray(p, float) for p in pts]
    mid = {}

    def m(i, j):
        key = (min(i, j), max(i, j))
        if key not in mid:
            mid[key] = len(pts)
            pts.append((pts[i] + pts[j]) / 2)
        return mid[key]

    t10 = [list(t) + [m(t[i], t[j]) for i, j in _EDGES] for t in np.asarray(tets).tolist()]
    tri4, src4 = [], []
    for (a, b, c), s in zip(np.asarray(tris).tolist(), np.asarray(src).tolist()):
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        tri4 += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]      # counter-clockwise as (a, b, c)
        src4 += [s] * 4
    return install_block_mesh(model, row, np.array(pts), np.array(t10), np.array(tri4), np.array(src4))
