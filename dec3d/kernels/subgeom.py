"""Sub-contact geometry of contacts on their common plane (3DEC theory, "Interaction between
Blocks" and "Sub-contact Force Update", the paragraph after Eq. 25).

A face of a block touches the c-p when every vertex of its loop does (A: n·(v−c) ≥ d_A − ctol,
B: n·(v−c) ≤ d_B + ctol, ERRATA Eqs. 6-8). Touching faces are triangulated as fans from
their first loop vertex. All geometry is done in the c-p's 2-D basis (p, q), p × q = n.

Face-face contacts (both sides have a touching face):

- P_s = convex hull of the projected touching vertices of side s; P_o the other side's.
- Region R_v of a vertex v of a touching face: in each fan triangle containing v the
  quadrilateral v – edge midpoint – triangle centroid – other edge midpoint (1/3 of the
  triangle). Its share a_v = area(R_v ∩ P_o).
- v inside P_o (within ctol): a vertex-face sub-contact (kind 0 for A, 1 for B) with a_v.
- v outside P_o: a_v is split equally among the edge-edge crossings lying on the touching
  face edges incident to v; with none it is orphaned.
- Edge-edge crossings (kind 2): proper crossings, farther than ctol from every edge end, of
  an edge of A's touching faces with one of B's; parallel edges give none.
- Every area is then scaled by S / T, S = area(P_A ∩ P_B), T = sum of the non-orphaned
  shares. With both sides complete this is the text's one-half (two spring sets in
  parallel); with one polygon inside the other the inner side carries the whole area; the
  total is always S. Coincident vertices of A and B stay two sub-contacts. Faces whose
  polygons only touch along an edge or at a corner (S no more than SLIVER = 1e-6 of the
  smaller polygon: the faces of diagonal neighbours in a settling stack) give none.

Lower contact types (ERRATA Table 1; a side without a touching face is a vertex when one
vertex touches, else an edge: its two touching vertices, or the two farthest apart in the
plane): kind 3 points with area ``point_area`` —
vertex-face / vertex-edge / vertex-vertex: the vertex; edge-face: the edge clipped by the
face polygon (two ends); edge-edge: the crossing of the lines clamped to A's edge (mean of
the midpoints when parallel).

Identity keys (used to carry forces across re-detection):
kind 0/1: key0 = vertex row, key1 = opposing face row whose projected loop holds the point
(-1 if none); kind 2: key0, key1 = edge codes of A's and B's edge, code = lo·2³¹ + hi of its
vertex rows (lo < hi); kind 3: vertex-face (key0 vertex, key1 face), edge-face (key0 the
edge end's vertex row, key1 face), vertex-edge (key0 vertex, key1 edge code), edge-edge
(A's edge code, B's), vertex-vertex (A's vertex, B's vertex).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .polygon2d import basis, clip_area, convex_hull, inside, shoelace

K_VA = 0
K_VB = 1
K_EE = 2
K_PT = 3
EDGE_SHIFT = 2147483648  # 2**31


#: overlap areas at most this fraction of the smaller touching polygon are no contact area
SLIVER = 1e-6


@njit(cache=True)
def edge_code(a, b):
    """Key of the edge between vertex rows a and b: lo·2³¹ + hi."""
    if a < b:
        return a * EDGE_SHIFT + b
    return b * EDGE_SHIFT + a


@njit(cache=True)
def _face_under(x, y, s, nsf, sfaces, fvstart, fnvert, fverts, vs, sxy, loop, tol):
    """Row of the first touching face of side s whose projected loop holds (x, y), or -1."""
    for t in range(nsf[s]):
        f = sfaces[s, t]
        m = fnvert[f]
        for i in range(m):
            lv = fverts[fvstart[f] + i] - vs[s]
            loop[i, 0] = sxy[s, lv, 0]
            loop[i, 1] = sxy[s, lv, 1]
        a = shoelace(loop, m)
        if inside(x, y, loop, m, 1.0 if a >= 0.0 else -1.0, tol):
            return f
    return -1


@njit(cache=True)
def _emit(k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area,
          ci, kind, key0, key1, x, y, c, p, q, area):
    """Write sub-contact k (when it fits) at the c-p point c + x p + y q; return k + 1."""
    if k < out_contact.shape[0]:
        out_contact[k] = ci
        out_kind[k] = kind
        out_key0[k] = key0
        out_key1[k] = key1
        for i in range(3):
            out_pos[k, i] = c[i] + x * p[i] + y * q[i]
        out_area[k] = area
    return k + 1


@njit(cache=True)
def _scratch(maxv, maxf, maxfv, ncr):
    """ncr: room for edge-edge crossings, at most the product of the two blocks' face-loop
    entries of a contact (each side has at most that many distinct edges)."""
    ncr = max(ncr, 1)
    nbuf = 2 * max(maxv, maxfv) + 8
    return (np.zeros((2, maxv, 2)),            # 0 sxy: 2-D coords of each block vertex
            np.zeros((2, maxv), np.int64),     # 1 tv: touching vertices (local index)
            np.zeros((2, maxf), np.int64),     # 2 sfaces: touching face rows
            np.zeros((2, maxv), np.int64),     # 3 sord: touching-face vertices, loop order
            np.zeros((2, maxv), np.int64),     # 4 smark: 1 when the vertex is in sord
            np.zeros((2, maxv + 1, 2)),        # 5 hull: P_A, P_B (ccw)
            np.zeros((2, maxv)),               # 6 share: a_v
            np.zeros((2, maxv), np.int64),     # 7 sin: 1 inside the opposing polygon
            np.zeros((2, maxv), np.int64),     # 8 vcnt: crossings on edges at v
            np.zeros((2, maxfv, 2), np.int64),  # 9 edges: local end vertices
            np.zeros((ncr, 2)),                # 10 crossing points
            np.zeros((ncr, 2), np.int64),      # 11 crossing edges (A's, B's)
            np.zeros(ncr),                     # 12 crossing shares
            np.zeros((nbuf, 2)),               # 13 clip buffer
            np.zeros((nbuf, 2)),               # 14 clip buffer
            np.zeros((max(maxfv, 4), 2)),      # 15 a face loop / a quadrilateral
            np.zeros(maxv, np.int64),          # 16 sort order
            np.zeros(16, np.int64),            # 17 small ints: nt, nsf, nord, ne, vs, what, e0, e1
            np.zeros((3, 3)),                  # 18 p, q
            np.zeros((2, maxv), np.int64))     # 19 touching flag


@njit(cache=True)
def _face_face(ci, n, c, p, q, ctol, vs, fvstart, fnvert, fverts, scratch, nh0, nh1,
               k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area):
    """Face-face: vertex-face and edge-edge sub-contacts with the scaled shares (module doc)."""
    (sxy, tv, sfaces, sord, smark, hull, share, sin, vcnt, edges, cxy, cedge, cshare,
     b1, b2, loop, order, ints, pqv, touch) = scratch
    nsf = ints[2:4]
    nord = ints[4:6]
    ne = ints[6:8]
    nh = (nh0, nh1)
    four = np.int64(4)
    area = clip_area(hull[0], nh0, hull[1], nh1, b1, b2)
    if area <= SLIVER * min(abs(shoelace(hull[0], nh0)), abs(shoelace(hull[1], nh1))):
        return k      # faces touching along an edge or at a corner (a sliver of round-off): none
    # shares a_v = area(R_v ∩ P_o): 1/3-triangle quadrilaterals of the fans
    for s in range(2):
        o = 1 - s
        for t in range(nsf[s]):
            f = sfaces[s, t]
            l0 = fverts[fvstart[f]] - vs[s]
            for i in range(1, fnvert[f] - 1):
                l1 = fverts[fvstart[f] + i] - vs[s]
                l2 = fverts[fvstart[f] + i + 1] - vs[s]
                gx = (sxy[s, l0, 0] + sxy[s, l1, 0] + sxy[s, l2, 0]) / 3.0
                gy = (sxy[s, l0, 1] + sxy[s, l1, 1] + sxy[s, l2, 1]) / 3.0
                for corner in range(3):
                    if corner == 0:
                        v, vn, vp = l0, l1, l2
                    elif corner == 1:
                        v, vn, vp = l1, l2, l0
                    else:
                        v, vn, vp = l2, l0, l1
                    loop[0, 0] = sxy[s, v, 0]
                    loop[0, 1] = sxy[s, v, 1]
                    loop[1, 0] = 0.5 * (sxy[s, v, 0] + sxy[s, vn, 0])
                    loop[1, 1] = 0.5 * (sxy[s, v, 1] + sxy[s, vn, 1])
                    loop[2, 0] = gx
                    loop[2, 1] = gy
                    loop[3, 0] = 0.5 * (sxy[s, v, 0] + sxy[s, vp, 0])
                    loop[3, 1] = 0.5 * (sxy[s, v, 1] + sxy[s, vp, 1])
                    share[s, v] += clip_area(loop, four, hull[o], nh[o], b1, b2)
        for i in range(nord[s]):
            v = sord[s, i]
            if inside(sxy[s, v, 0], sxy[s, v, 1], hull[o], nh[o], 1.0, ctol):
                sin[s, v] = 1
    # proper edge-edge crossings, A's edges outer, B's inner (loop order)
    nc = 0
    for ea in range(ne[0]):
        a0 = edges[0, ea, 0]
        a1 = edges[0, ea, 1]
        ax = sxy[0, a0, 0]
        ay = sxy[0, a0, 1]
        dx1 = sxy[0, a1, 0] - ax
        dy1 = sxy[0, a1, 1] - ay
        l1 = math.sqrt(dx1 * dx1 + dy1 * dy1)
        for eb in range(ne[1]):
            b0 = edges[1, eb, 0]
            bb = edges[1, eb, 1]
            dx2 = sxy[1, bb, 0] - sxy[1, b0, 0]
            dy2 = sxy[1, bb, 1] - sxy[1, b0, 1]
            l2 = math.sqrt(dx2 * dx2 + dy2 * dy2)
            den = dx1 * dy2 - dy1 * dx2
            if abs(den) <= 1e-12 * l1 * l2 or l1 == 0.0 or l2 == 0.0:
                continue
            wx = sxy[1, b0, 0] - ax
            wy = sxy[1, b0, 1] - ay
            t = (wx * dy2 - wy * dx2) / den
            u = (wx * dy1 - wy * dx1) / den
            if t * l1 <= ctol or (1.0 - t) * l1 <= ctol or u * l2 <= ctol or (1.0 - u) * l2 <= ctol:
                continue
            if nc < cxy.shape[0]:
                cxy[nc, 0] = ax + t * dx1
                cxy[nc, 1] = ay + t * dy1
                cedge[nc, 0] = ea
                cedge[nc, 1] = eb
                cshare[nc] = 0.0
                nc += 1
    # outside vertices hand their shares to the crossings on their edges
    for i in range(nc):
        for s in range(2):
            e = cedge[i, s]
            vcnt[s, edges[s, e, 0]] += 1
            vcnt[s, edges[s, e, 1]] += 1
    for i in range(nc):
        for s in range(2):
            e = cedge[i, s]
            for end in range(2):
                v = edges[s, e, end]
                if sin[s, v] == 0:
                    cshare[i] += share[s, v] / vcnt[s, v]
    tot = 0.0
    for s in range(2):
        for i in range(nord[s]):
            v = sord[s, i]
            if sin[s, v] == 1:
                tot += share[s, v]
    for i in range(nc):
        tot += cshare[i]
    scale = area / tot if tot > 0.0 else 0.0
    # emit: kind 0 (A's vertices on B), kind 1 (B's on A), kind 2 (crossings)
    for s in range(2):
        o = 1 - s
        for i in range(nord[s]):
            v = sord[s, i]
            if sin[s, v] == 0:
                continue
            x = sxy[s, v, 0]
            y = sxy[s, v, 1]
            fo = _face_under(x, y, o, nsf, sfaces, fvstart, fnvert, fverts, vs, sxy, loop, ctol)
            k = _emit(k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area,
                      ci, s, vs[s] + v, fo, x, y, c, p, q, share[s, v] * scale)
    for i in range(nc):
        ea = cedge[i, 0]
        eb = cedge[i, 1]
        k = _emit(k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area, ci, np.int64(K_EE),
                  edge_code(vs[0] + edges[0, ea, 0], vs[0] + edges[0, ea, 1]),
                  edge_code(vs[1] + edges[1, eb, 0], vs[1] + edges[1, eb, 1]),
                  cxy[i, 0], cxy[i, 1], c, p, q, cshare[i] * scale)
    return k


@njit(cache=True)
def _points(ci, c, p, q, ctol, point_area, vs, fvstart, fnvert, fverts, scratch, nh0, nh1,
            k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area):
    """Lower contact types: kind 3 points of area point_area (module doc)."""
    (sxy, tv, sfaces, sord, smark, hull, share, sin, vcnt, edges, cxy, cedge, cshare,
     b1, b2, loop, order, ints, pqv, touch) = scratch
    nt = ints[0:2]
    nsf = ints[2:4]
    nh = (nh0, nh1)
    # what each side is: 2 face, 1 edge (ends e0 < e1 by row), 0 vertex (e0)
    what = ints[10:12]
    e0 = ints[12:14]
    e1 = ints[14:16]
    for s in range(2):
        if nsf[s] > 0 and nh[s] >= 3:
            what[s] = 2
        elif nt[s] == 1:
            what[s] = 0
            e0[s] = tv[s, 0]
        else:
            what[s] = 1
            best = -1.0
            for i in range(nt[s]):
                for j in range(i + 1, nt[s]):
                    vi = tv[s, i]
                    vj = tv[s, j]
                    d = (sxy[s, vi, 0] - sxy[s, vj, 0]) ** 2 + (sxy[s, vi, 1] - sxy[s, vj, 1]) ** 2
                    if d > best:
                        best = d
                        e0[s] = min(vi, vj)
                        e1[s] = max(vi, vj)
    wa = what[0]
    wb = what[1]
    if wa == 0 or wb == 0:
        # vertex-face, vertex-edge, vertex-vertex: the vertex (A's for vertex-vertex)
        s = 0 if wa == 0 else 1
        o = 1 - s
        v = e0[s]
        x = sxy[s, v, 0]
        y = sxy[s, v, 1]
        if what[o] == 2:
            k1 = _face_under(x, y, o, nsf, sfaces, fvstart, fnvert, fverts, vs, sxy, loop, ctol)
        elif what[o] == 1:
            k1 = edge_code(vs[o] + e0[o], vs[o] + e1[o])
        else:
            k1 = vs[o] + e0[o]
        return _emit(k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area,
                     ci, np.int64(K_PT), vs[s] + v, k1, x, y, c, p, q, point_area)
    if wa == 1 and wb == 1:
        # edge-edge: crossing of the lines, clamped to A's edge; parallel: mean of midpoints
        ax = sxy[0, e0[0], 0]
        ay = sxy[0, e0[0], 1]
        dx1 = sxy[0, e1[0], 0] - ax
        dy1 = sxy[0, e1[0], 1] - ay
        dx2 = sxy[1, e1[1], 0] - sxy[1, e0[1], 0]
        dy2 = sxy[1, e1[1], 1] - sxy[1, e0[1], 1]
        den = dx1 * dy2 - dy1 * dx2
        if abs(den) < 1e-300:
            x = 0.25 * (sxy[0, e0[0], 0] + sxy[0, e1[0], 0] + sxy[1, e0[1], 0] + sxy[1, e1[1], 0])
            y = 0.25 * (sxy[0, e0[0], 1] + sxy[0, e1[0], 1] + sxy[1, e0[1], 1] + sxy[1, e1[1], 1])
        else:
            t = ((sxy[1, e0[1], 0] - ax) * dy2 - (sxy[1, e0[1], 1] - ay) * dx2) / den
            t = min(max(t, 0.0), 1.0)
            x = ax + t * dx1
            y = ay + t * dy1
        return _emit(k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area, ci, np.int64(K_PT),
                     edge_code(vs[0] + e0[0], vs[0] + e1[0]),
                     edge_code(vs[1] + e0[1], vs[1] + e1[1]), x, y, c, p, q, point_area)
    # edge-face: the edge (from its lower row to its higher) clipped by the face polygon
    s = 0 if wa == 1 else 1
    o = 1 - s
    ax = sxy[s, e0[s], 0]
    ay = sxy[s, e0[s], 1]
    bx = sxy[s, e1[s], 0]
    by = sxy[s, e1[s], 1]
    t0 = 0.0
    t1 = 1.0
    poly = hull[o]
    for i in range(nh[o]):
        j = i + 1 if i + 1 < nh[o] else 0
        ex = poly[j, 0] - poly[i, 0]
        ey = poly[j, 1] - poly[i, 1]
        fa = ex * (ay - poly[i, 1]) - ey * (ax - poly[i, 0])
        fb = ex * (by - poly[i, 1]) - ey * (bx - poly[i, 0])
        if fa < 0.0 and fb < 0.0:
            return k
        if fa < 0.0:
            t0 = max(t0, fa / (fa - fb))
        elif fb < 0.0:
            t1 = min(t1, fa / (fa - fb))
    if t1 < t0:
        return k
    for end in range(2):
        t = t0 if end == 0 else t1
        x = ax + (bx - ax) * t
        y = ay + (by - ay) * t
        fo = _face_under(x, y, o, nsf, sfaces, fvstart, fnvert, fverts, vs, sxy, loop, ctol)
        k = _emit(k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area, ci, np.int64(K_PT),
                  vs[s] + (e0[s] if end == 0 else e1[s]), fo, x, y, c, p, q, point_area)
    return k


@njit(cache=True, nogil=True)
def subcontacts_batch(vpos, bvstart, bvcount, bfstart, bfcount, fvstart, fnvert, fverts,
                      ca, cb, cn, cc, ctol, point_area,
                      out_contact, out_kind, out_key0, out_key1, out_pos, out_area):
    """Sub-contacts of every contact (module doc; 3DEC theory, text after Eq. 25).

    vpos (nv, 3) m; bvstart, bvcount, bfstart, bfcount (nb,) vertex and face ranges per block
    row; fvstart, fnvert (nf,) ranges into fverts (face loops, vertex rows, ccw from outside);
    ca, cb (nc,) block rows A, B; cn (nc, 3) unit c-p normal A → B; cc (nc, 3) c-p point [m];
    ctol [m] touching tolerance (also the in-plane tolerance); point_area [m²].
    Writes out_contact, out_kind, out_key0, out_key1 (cap,) int64, out_pos (cap, 3) m (on
    the c-p), out_area (cap,) m², ordered by contact row then kind then loop order, and
    nothing beyond cap = len(out_contact). Returns the number of sub-contacts needed.
    """
    # scratch sized by the blocks of the contacts only, the crossings by the largest product of
    # the two sides' face-loop entries: sizing them by the largest block of the model squared
    # asked for 10^10 crossing rows once a block was zoned into 10^5 tetrahedra
    maxv = np.int64(1)
    maxf = np.int64(1)
    maxfv = np.int64(1)
    ncr = np.int64(1)
    nfv = np.zeros(bvstart.shape[0], np.int64)
    for b in range(bvstart.shape[0]):
        m = 0
        for f in range(bfstart[b], bfstart[b] + bfcount[b]):
            m += fnvert[f]
        nfv[b] = m
    for i in range(ca.shape[0]):
        for b in (ca[i], cb[i]):
            maxv = max(maxv, bvcount[b])
            maxf = max(maxf, bfcount[b])
            maxfv = max(maxfv, nfv[b])
        ncr = max(ncr, nfv[ca[i]] * nfv[cb[i]])
    scratch = _scratch(maxv, maxf, maxfv, ncr)
    (sxy, tv, sfaces, sord, smark, hull, share, sin, vcnt, edges, cxy, cedge, cshare,
     b1, b2, loop, order, ints, pqv, touch) = scratch
    p = pqv[0]
    q = pqv[1]
    k = np.int64(0)
    # (one loop: a kernel per contact called from here had its code compiled twice, in its own
    # right and again inside this one, a second more of a cold start)
    for ci in range(ca.shape[0]):
        # contact ci: block rows ca[ci] (A), cb[ci] (B), c-p unit normal n A → B, point c
        n = cn[ci]
        c = cc[ci]
        basis(n, p, q)
        nt = ints[0:2]
        nsf = ints[2:4]
        nord = ints[4:6]
        ne = ints[6:8]
        vs = ints[8:10]
        vs[0] = bvstart[ca[ci]]
        vs[1] = bvstart[cb[ci]]
        blk = (ca[ci], cb[ci])
        nh0 = np.int64(0)   # np.int64, not a literal: a literal argument compiles a callee twice
        nh1 = np.int64(0)
        for s in range(2):
            b = blk[s]
            nv = bvcount[b]
            # touching vertices (ERRATA Eqs. 6-8) and their c-p coordinates
            ext = -1e300 if s == 0 else 1e300
            for i in range(nv):
                r = vs[s] + i
                d = n[0] * (vpos[r, 0] - c[0]) + n[1] * (vpos[r, 1] - c[1]) + n[2] * (vpos[r, 2] - c[2])
                if (s == 0 and d > ext) or (s == 1 and d < ext):
                    ext = d
                sxy[s, i, 0] = (p[0] * (vpos[r, 0] - c[0]) + p[1] * (vpos[r, 1] - c[1]) +
                                p[2] * (vpos[r, 2] - c[2]))
                sxy[s, i, 1] = (q[0] * (vpos[r, 0] - c[0]) + q[1] * (vpos[r, 1] - c[1]) +
                                q[2] * (vpos[r, 2] - c[2]))
                smark[s, i] = 0
                share[s, i] = 0.0
                vcnt[s, i] = 0
                sin[s, i] = 0
            m = 0
            for i in range(nv):
                r = vs[s] + i
                d = n[0] * (vpos[r, 0] - c[0]) + n[1] * (vpos[r, 1] - c[1]) + n[2] * (vpos[r, 2] - c[2])
                touch[s, i] = 0
                if (s == 0 and d >= ext - ctol) or (s == 1 and d <= ext + ctol):
                    touch[s, i] = 1
                    tv[s, m] = i
                    m += 1
            nt[s] = m
            # touching faces, their vertices in loop order and their distinct edges
            nsf[s] = 0
            nord[s] = 0
            ne[s] = 0
            for f in range(bfstart[b], bfstart[b] + bfcount[b]):
                ok = True
                for j in range(fvstart[f], fvstart[f] + fnvert[f]):
                    if touch[s, fverts[j] - vs[s]] == 0:
                        ok = False
                        break
                if not ok:
                    continue
                sfaces[s, nsf[s]] = f
                nsf[s] += 1
                mf = fnvert[f]
                for j in range(mf):
                    v0 = fverts[fvstart[f] + j] - vs[s]
                    v1 = fverts[fvstart[f] + (j + 1) % mf] - vs[s]
                    if smark[s, v0] == 0:
                        smark[s, v0] = 1
                        sord[s, nord[s]] = v0
                        nord[s] += 1
                    dup = False
                    for e in range(ne[s]):
                        if ((edges[s, e, 0] == v0 and edges[s, e, 1] == v1) or
                                (edges[s, e, 0] == v1 and edges[s, e, 1] == v0)):
                            dup = True
                            break
                    if not dup:
                        edges[s, ne[s], 0] = v0
                        edges[s, ne[s], 1] = v1
                        ne[s] += 1
            h = convex_hull(sxy[s], tv[s], nt[s], order, hull[s])
            if s == 0:
                nh0 = h
            else:
                nh1 = h
        if nsf[0] > 0 and nsf[1] > 0 and nh0 >= 3 and nh1 >= 3:
            k = _face_face(ci, n, c, p, q, ctol, vs, fvstart, fnvert, fverts, scratch, nh0, nh1,
                           k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area)
        else:
            k = _points(ci, c, p, q, ctol, point_area, vs, fvstart, fnvert, fverts, scratch, nh0, nh1,
                        k, out_contact, out_kind, out_key0, out_key1, out_pos, out_area)
    return k


def subcontacts_one(ci, ca, cb, n, c, ctol, point_area, vpos, bvstart, bvcount, bfstart,
                    bfcount, fvstart, fnvert, fverts, k,
                    out_contact, out_kind, out_key0, out_key1, out_pos, out_area):
    """Sub-contacts of contact ci alone, between block rows ca (A) and cb (B), c-p unit normal n
    (3,) A → B and reference point c (3,) [m]: ``subcontacts_batch`` on that one contact (plain
    Python), written from out row k on (nothing beyond the capacity). Returns k + their number."""
    one = lambda x: np.array([x], np.int64)  # noqa: E731
    outs = tuple(o[k:] for o in (out_contact, out_kind, out_key0, out_key1, out_pos, out_area))
    m = subcontacts_batch(vpos, bvstart, bvcount, bfstart, bfcount, fvstart, fnvert, fverts, one(ca), one(cb),
                          np.array(n, float).reshape(1, 3), np.array(c, float).reshape(1, 3), float(ctol),
                          float(point_area), *outs)
    outs[0][:m] = ci
    return k + int(m)
