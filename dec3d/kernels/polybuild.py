"""Many convex polyhedra from their faces in one call: the compiled form of
``dec3d.geometry.polyhedron.polyhedron_from_faces`` for `block create` runs of thousands of lines.

Input, polyhedron after polyhedron: ``pts`` (N, 3) the corners of every face, face after face;
``face_n`` (F,) corners per face; ``poly_nf`` (k,) faces per polyhedron; ``tol`` the model tolerance.

Each polyhedron is built and checked as ``polyhedron_from_faces`` does, with the same decisions:
corners within ``tol`` (max-norm) of an earlier corner are merged into it (vertices numbered in
order of first appearance); repeated corners in a loop are dropped; every face needs three distinct
corners, a non-zero area (Newell's area vector about the loop's mean) and must be planar; every
edge belongs to exactly two faces; not all corners in one plane; faces turned outward as seen from
the mean of the corners; no corner in front of any face's plane (convex); each directed edge once;
a volume above ``tol`` times the total face area. The output is what ``polys_to_batch`` makes of
the accepted ``Poly`` objects: ``out_pos`` (V, 3) vertices, ``out_piece_nv`` (k,) vertices per
polyhedron, ``out_fn`` (F,) corners per face, ``out_fv`` face loops (indices local to their
polyhedron), counter-clockwise seen from outside.

The call stops at the first polyhedron refused and returns how many were built before it (the
caller asks ``polyhedron_from_faces`` for the reason, worded for the user), and the lengths of
``out_pos`` and ``out_fv`` used. The twin is ``polyhedron_from_faces`` itself
(tests/geometry/test_polybuild.py).
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _build_one(pts, q0, nq, face_n, f0, nf, tol, out_pos, v0, out_fn, out_fv, w0):
    """Polyhedron with corners pts[q0:q0+nq] and faces f0..f0+nf-1. Returns (vertices, loop
    entries) written at out_pos[v0:], out_fv[w0:], out_fn[f0:], or (-1, -1) when refused."""
    for i in range(q0, q0 + nq):
        for k in range(3):
            if not np.isfinite(pts[i, k]):
                return -1, -1
    if nf < 4:
        return -1, -1
    # merge corners: each joins the earliest earlier corner within tol (max-norm)
    vid = np.empty(nq, np.int64)
    nv = 0
    for i in range(nq):
        vid[i] = -1
        for j in range(i):
            d = 0.0
            for k in range(3):
                d = max(d, abs(pts[q0 + i, k] - pts[q0 + j, k]))
            if d <= tol:
                vid[i] = vid[j]
                break
        if vid[i] < 0:
            for k in range(3):
                out_pos[v0 + nv, k] = pts[q0 + i, k]
            vid[i] = nv
            nv += 1
    v = out_pos[v0:v0 + nv]
    # loops without repeated corners
    lstart = np.empty(nf + 1, np.int64)
    loops = np.empty(nq, np.int64)
    n_l = 0
    q = 0
    for f in range(nf):
        lstart[f] = n_l
        first = n_l
        for _ in range(face_n[f0 + f]):
            idx = vid[q]
            q += 1
            if n_l == first or loops[n_l - 1] != idx:
                loops[n_l] = idx
                n_l += 1
        if n_l - first > 1 and loops[first] == loops[n_l - 1]:
            n_l -= 1
        if n_l - first < 3:
            return -1, -1
        for a in range(first, n_l):
            for b in range(a + 1, n_l):
                if loops[a] == loops[b]:
                    return -1, -1
    lstart[nf] = n_l
    # Newell area vectors, planarity
    normal = np.empty((nf, 3))
    centre = np.empty((nf, 3))
    area_sum = 0.0
    for f in range(nf):
        s, e = lstart[f], lstart[f + 1]
        m = e - s
        cx = cy = cz = 0.0
        for a in range(s, e):
            cx += v[loops[a], 0]
            cy += v[loops[a], 1]
            cz += v[loops[a], 2]
        cx /= m
        cy /= m
        cz /= m
        ax = ay = az = 0.0
        for a in range(s, e):
            b = a + 1 if a + 1 < e else s
            px, py, pz = v[loops[a], 0] - cx, v[loops[a], 1] - cy, v[loops[a], 2] - cz
            qx, qy, qz = v[loops[b], 0] - cx, v[loops[b], 1] - cy, v[loops[b], 2] - cz
            ax += py * qz - pz * qy
            ay += pz * qx - px * qz
            az += px * qy - py * qx
        ax *= 0.5
        ay *= 0.5
        az *= 0.5
        area = np.sqrt(ax * ax + ay * ay + az * az)
        if area <= tol * tol:
            return -1, -1
        normal[f, 0], normal[f, 1], normal[f, 2] = ax / area, ay / area, az / area
        centre[f, 0], centre[f, 1], centre[f, 2] = cx, cy, cz
        for a in range(s, e):
            d = ((v[loops[a], 0] - cx) * normal[f, 0] + (v[loops[a], 1] - cy) * normal[f, 1]
                 + (v[loops[a], 2] - cz) * normal[f, 2])
            if abs(d) > tol:
                return -1, -1
        area_sum += area
    # closed: every undirected edge in exactly two faces
    ea = np.empty(n_l, np.int64)
    eb = np.empty(n_l, np.int64)
    for f in range(nf):
        s, e = lstart[f], lstart[f + 1]
        for a in range(s, e):
            b = a + 1 if a + 1 < e else s
            ea[a] = min(loops[a], loops[b])
            eb[a] = max(loops[a], loops[b])
    for a in range(n_l):
        owners = 0
        for b in range(n_l):
            if ea[b] == ea[a] and eb[b] == eb[a]:
                owners += 1
        if owners != 2:
            return -1, -1
    # all corners in one plane
    flat = True
    for i in range(nv):
        d = ((v[i, 0] - centre[0, 0]) * normal[0, 0] + (v[i, 1] - centre[0, 1]) * normal[0, 1]
             + (v[i, 2] - centre[0, 2]) * normal[0, 2])
        if abs(d) > tol:
            flat = False
            break
    if flat:
        return -1, -1
    # outward, seen from the mean of the corners
    ix = iy = iz = 0.0
    for i in range(nv):
        ix += v[i, 0]
        iy += v[i, 1]
        iz += v[i, 2]
    ix /= nv
    iy /= nv
    iz /= nv
    for f in range(nf):
        if (normal[f, 0] * (centre[f, 0] - ix) + normal[f, 1] * (centre[f, 1] - iy)
                + normal[f, 2] * (centre[f, 2] - iz)) < 0.0:
            for k in range(3):
                normal[f, k] = -normal[f, k]
            s, e = lstart[f], lstart[f + 1] - 1
            while s < e:
                loops[s], loops[e] = loops[e], loops[s]
                s += 1
                e -= 1
    # convex: no corner in front of a face's plane
    for f in range(nf):
        for i in range(nv):
            d = ((v[i, 0] - centre[f, 0]) * normal[f, 0] + (v[i, 1] - centre[f, 1]) * normal[f, 1]
                 + (v[i, 2] - centre[f, 2]) * normal[f, 2])
            if d > tol:
                return -1, -1
    # consistent orientation: each directed edge once
    for f in range(nf):
        s, e = lstart[f], lstart[f + 1]
        for a in range(s, e):
            b = a + 1 if a + 1 < e else s
            ea[a] = loops[a]
            eb[a] = loops[b]
    for a in range(n_l):
        for b in range(a + 1, n_l):
            if ea[b] == ea[a] and eb[b] == eb[a]:
                return -1, -1
    # volume by the divergence theorem, faces fanned from their mean, about the corners' mean
    vol = 0.0
    for f in range(nf):
        s, e = lstart[f], lstart[f + 1]
        mx, my, mz = centre[f, 0] - ix, centre[f, 1] - iy, centre[f, 2] - iz
        for a in range(s, e):
            b = a + 1 if a + 1 < e else s
            px, py, pz = v[loops[a], 0] - ix, v[loops[a], 1] - iy, v[loops[a], 2] - iz
            qx, qy, qz = v[loops[b], 0] - ix, v[loops[b], 1] - iy, v[loops[b], 2] - iz
            vol += (py * qz - pz * qy) * mx + (pz * qx - px * qz) * my + (px * qy - py * qx) * mz
    vol /= 6.0
    if vol <= tol * area_sum:
        return -1, -1
    for f in range(nf):
        out_fn[f0 + f] = lstart[f + 1] - lstart[f]
    for a in range(n_l):
        out_fv[w0 + a] = loops[a]
    return nv, n_l


@njit(cache=True)
def build_polyhedra(pts, face_n, poly_nf, tol, out_pos, out_piece_nv, out_fn, out_fv):
    """Build polyhedra until the first refused one; returns (built, vertices used, loop entries used).
    ``out_pos`` needs len(pts) rows, ``out_fn`` len(face_n), ``out_fv`` len(pts) entries."""
    q0 = 0
    f0 = 0
    v0 = 0
    w0 = 0
    for p in range(len(poly_nf)):
        nf = poly_nf[p]
        nq = 0
        for f in range(f0, f0 + nf):
            nq += face_n[f]
        nv, nl = _build_one(pts, q0, nq, face_n, f0, nf, tol, out_pos, v0, out_fn, out_fv, w0)
        if nv < 0:
            return p, v0, w0
        out_piece_nv[p] = nv
        q0 += nq
        f0 += nf
        v0 += nv
        w0 += nl
    return len(poly_nf), v0, w0
