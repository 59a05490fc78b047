"""Where a liner's triangles come from (``structure liner create``): the outer faces of blocks
(``by-block-face``) or a quadrilateral split into a grid (``by-quadrilateral``).

Block faces: a face is on the surface when no face of another visible block lies on it (same
centroid within the tolerance or 10⁻³ of the face's size, opposite normal). A rigid block's face polygon is fanned about its
centroid (triangles counter-clockwise seen from outside: their normals point out of the block); a
zoned block's surface triangles (``model.face_loads.loadable_faces``: the boundary triangles of its
zones, not shared inside a joined continuum) are taken as they are, so the liner's nodes are its
gridpoints. FE blocks are not lined.
"""
from __future__ import annotations

import numpy as np

from .face_loads import loadable_faces
from .model import KIND_FE, KIND_RIGID


def _loop(model, r: int) -> np.ndarray:
    f, fv, v = model.faces, model.face_vertices, model.vertices
    s, n = int(f["vstart"][r]), int(f["nvert"][r])
    return v["pos"][fv["vertex"][s:s + n]]


def covered_faces(model, rows: np.ndarray, tol: float) -> np.ndarray:
    """Mask over ``rows`` (face rows): a face of another visible block lies on it (same centroid within
    ``tol`` or 10⁻³ of the face's size, opposite normal: blocks that have moved since they were cut no
    longer meet exactly)."""
    f, b = model.faces, model.blocks
    live = np.flatnonzero((f["block"][: f.n] >= 0))
    live = live[~b["hidden"][f["block"][live]]]
    from scipy.spatial import cKDTree

    cen, nrm, blk = f["centroid"][live], f["normal"][live], f["block"][live]
    out = np.zeros(len(rows), bool)
    if not len(rows) or not len(live):
        return out
    radius = np.maximum(tol, 1e-3 * np.sqrt(f["area"][rows]))
    near = cKDTree(cen).query_ball_point(f["centroid"][rows], radius)
    for k, r in enumerate(rows):
        j = np.asarray(near[k], np.int64)
        if j.size:
            out[k] = bool(((blk[j] != f["block"][r]) & (nrm[j] @ f["normal"][r] < -0.99)).any())
    return out


def surface_triangles(model, mask: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """(triangles (k, 3, 3), block row of each (k,)) on the block faces of ``mask`` (over face rows)
    that are on the surface of visible rigid or zoned blocks."""
    f, b = model.faces, model.blocks
    rows = np.flatnonzero(mask[: f.n] & (f["block"][: f.n] >= 0))
    rows = rows[~b["hidden"][f["block"][rows]]]
    kind = b["kind"][f["block"][rows]]
    rows, kind = rows[kind != KIND_FE], kind[kind != KIND_FE]
    if (kind != KIND_RIGID).any():
        outer = loadable_faces(model)
        keep = (kind == KIND_RIGID) | outer[rows]
        rows, kind = rows[keep], kind[keep]
    rows = rows[~covered_faces(model, rows, tol)]
    tris, blocks = [], []
    for r in rows:
        p = _loop(model, int(r))
        h = int(f["block"][r])
        if len(p) == 3:
            tris.append(p)
            blocks.append(h)
            continue
        c = p.mean(axis=0)
        for i in range(len(p)):
            tris.append(np.array([c, p[i], p[(i + 1) % len(p)]]))
            blocks.append(h)
    if not tris:
        return np.zeros((0, 3, 3)), np.zeros(0, np.int64)
    return np.array(tris), np.array(blocks, np.int64)


def quadrilateral_triangles(corners: np.ndarray, n1: int, n2: int, cross: bool) -> np.ndarray:
    """Triangles of the quadrilateral v1 v2 v3 v4 (bilinear) in n1 × n2 cells (n1 along v1 → v2), each
    cell two triangles on its diagonal from its first corner, or with ``cross`` four about its centre;
    counter-clockwise in the order v1 v2 v3 v4 (normal by the right-hand rule)."""
    v1, v2, v3, v4 = (np.asarray(c, np.float64) for c in corners)

    def at(s, t):
        return (1 - s) * (1 - t) * v1 + s * (1 - t) * v2 + s * t * v3 + (1 - s) * t * v4

    out = []
    for j in range(n2):
        for i in range(n1):
            s0, s1, t0, t1 = i / n1, (i + 1) / n1, j / n2, (j + 1) / n2
            a, bb, c, d = at(s0, t0), at(s1, t0), at(s1, t1), at(s0, t1)
            if cross:
                m = at(0.5 * (s0 + s1), 0.5 * (t0 + t1))
                out += [[a, bb, m], [bb, c, m], [c, d, m], [d, a, m]]
            else:
                out += [[a, bb, c], [a, c, d]]
    return np.array(out)
