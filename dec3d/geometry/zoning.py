"""Zoning of a convex polyhedron into 4-node tetrahedra at a target edge length (first step of
issue 10's mesher: boundary points, an interior lattice kept off the boundary, a Delaunay
tetrahedralization, flat tetrahedra dropped, every tetrahedron oriented positive).

Not yet here: conformity with zoned joined neighbours, hexahedral mixed zones, 10-node
tetrahedra, sliver repair (see the helper report on branch h-mesh)."""
from __future__ import annotations

import numpy as np


def _face_frame(p: np.ndarray):
    n = np.zeros(3)
    for i in range(len(p)):
        a, b = p[i], p[(i + 1) % len(p)]
        n += np.cross(a, b)
    n /= np.linalg.norm(n)
    u = p[1] - p[0]
    u -= n * np.dot(u, n)
    u /= np.linalg.norm(u)
    return n, u, np.cross(n, u)


def boundary_points(verts: np.ndarray, ptr: np.ndarray, loops: np.ndarray, L: float) -> np.ndarray:
    """Vertices, edge subdivisions at about L, and face interior points on a square grid of
    step L kept at least L/2 from the face's edges."""
    pts = [verts]
    seen = set()
    for f in range(len(ptr) - 1):
        loop = loops[ptr[f]:ptr[f + 1]]
        p = verts[loop]
        for i in range(len(loop)):
            a, b = int(loop[i]), int(loop[(i + 1) % len(loop)])
            key = (min(a, b), max(a, b))
            if key in seen:
                continue
            seen.add(key)
            n = int(np.ceil(np.linalg.norm(verts[b] - verts[a]) / L - 1e-9))
            if n > 1:
                t = np.arange(1, n)[:, None] / n
                pa, pb = verts[key[0]], verts[key[1]]
                pts.append(pa + t * (pb - pa))
        n, u, v = _face_frame(p)
        q = np.c_[(p - p[0]) @ u, (p - p[0]) @ v]
        lo, hi = q.min(axis=0), q.max(axis=0)
        gu = np.arange(lo[0] + L, hi[0] - 0.5 * L + 1e-12, L)
        gv = np.arange(lo[1] + L, hi[1] - 0.5 * L + 1e-12, L)
        if len(gu) == 0 or len(gv) == 0:
            continue
        G = np.array(np.meshgrid(gu, gv, indexing="ij")).reshape(2, -1).T
        keep = np.ones(len(G), bool)
        m = len(q)
        for i in range(m):
            e = q[(i + 1) % m] - q[i]
            en = np.array([e[1], -e[0]]) / np.linalg.norm(e)
            d = (G - q[i]) @ en  # outward normal for counterclockwise loops
            keep &= d < -0.5 * L
        G = G[keep]
        pts.append(p[0] + G[:, :1] * u + G[:, 1:] * v)
    return np.concatenate(pts)


def regular_tets(pts: np.ndarray, L: float) -> np.ndarray:
    """A weighted (regular) triangulation as the lower hull of lifted points: lattice input is
    cospherical everywhere, so tiny deterministic weights from the coordinates (a hash, not a
    random stream) break the ties without moving any point; coplanar points then never form a
    tetrahedron (their lifted facet would be vertical, not lower)."""
    from scipy.spatial import ConvexHull
    c = pts.mean(axis=0)
    q = (pts - c) / L
    h = np.sin(q @ np.array([12.9898, 78.233, 37.719]) + 0.5) * 43758.5453
    w = (h - np.floor(h)) * 1e-3
    lifted = np.c_[q, np.einsum("ij,ij->i", q, q) + w]
    hull = ConvexHull(lifted, qhull_options="Qt Qbb")
    return hull.simplices[hull.equations[:, 3] < 0].astype(np.int64)


def mesh_convex(verts: np.ndarray, ptr: np.ndarray, loops: np.ndarray, L: float):
    """points (n,3), tets (m,4) positive, boundary tris (k,3), tri_source (k,) face index."""
    verts = np.asarray(verts, float)
    bp = boundary_points(verts, ptr, loops, L)
    normals, offs = [], []
    for f in range(len(ptr) - 1):
        p = verts[loops[ptr[f]:ptr[f + 1]]]
        n, _, _ = _face_frame(p)
        normals.append(n)
        offs.append(np.dot(n, p[0]))
    N, D = np.array(normals), np.array(offs)
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    axes = [np.arange(lo[d] + 0.5 * L, hi[d], L) for d in range(3)]
    G = np.array(np.meshgrid(*axes, indexing="ij")).reshape(3, -1).T
    G = G[np.all(G @ N.T - D < -0.5 * L, axis=1)]
    pts = np.concatenate([bp, G])
    _, first = np.unique(np.round(pts / (1e-9 * L)).astype(np.int64), axis=0, return_index=True)
    pts = pts[np.sort(first)]
    tets = regular_tets(pts, L)
    a, b, c, d = (pts[tets[:, k]] for k in range(4))
    vol = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6.0
    keep = np.abs(vol) > 1e-10 * L ** 3
    tets, vol = tets[keep], vol[keep]
    neg = vol < 0
    tets[neg] = tets[neg][:, [0, 2, 1, 3]]
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]])
    key = np.sort(faces, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    tris = faces[cnt[inv.ravel()] == 1]
    cen = pts[tris].mean(axis=1)
    src = np.argmin(np.abs(cen @ N.T - D), axis=1)
    return pts, tets, tris, src


def min_dihedral_deg(pts: np.ndarray, tets: np.ndarray) -> float:
    """Smallest dihedral angle (degrees) over all tetrahedra: the angle between the two faces at
    each of the six edges, from the outward face normals n_i, n_j as pi - angle(n_i, n_j)."""
    p = pts[tets]
    opp = [(1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1)]
    n = np.stack([np.cross(p[:, b] - p[:, a], p[:, c] - p[:, a]) for a, b, c in opp], axis=1)
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    best = np.pi
    for i in range(4):
        for j in range(i + 1, 4):
            cosang = np.clip(np.einsum("ij,ij->i", n[:, i], n[:, j]), -1, 1)
            best = min(best, float((np.pi - np.arccos(cosang)).min()))
    return np.degrees(best)
