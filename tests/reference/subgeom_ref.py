"""Slow, plain twin of ``dec3d.kernels.subgeom`` for one contact (same rule, written with
lists, dicts and scipy's convex hull; see the kernel's module docstring).

``subcontacts_ref(arrays, a, b, n, c, ctol, point_area)`` returns a list of
``(kind, key0, key1, pos (3,), area)`` in the kernel's order.
"""
import math

import numpy as np
from scipy.spatial import ConvexHull, QhullError

SHIFT = 2 ** 31


def edge_code(u, v):
    return min(u, v) * SHIFT + max(u, v)


def basis(n):
    t = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    p = np.cross(n, t)
    p = p / np.linalg.norm(p)
    return p, np.cross(n, p)


def shoelace(poly):
    s = 0.0
    for i in range(len(poly)):
        (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % len(poly)]
        s += x0 * y1 - x1 * y0
    return 0.5 * s


def clip(subject, window):
    """Sutherland–Hodgman: polygon ``subject`` clipped by the convex ccw polygon ``window``."""
    out = list(subject)
    for i in range(len(window)):
        (ax, ay), (bx, by) = window[i], window[(i + 1) % len(window)]

        def side(pt):
            return (bx - ax) * (pt[1] - ay) - (by - ay) * (pt[0] - ax)

        inp, out = out, []
        for j in range(len(inp)):
            prev, cur = inp[j - 1], inp[j]
            sp, sc = side(prev), side(cur)
            if sc >= 0:
                if sp < 0:
                    t = sp / (sp - sc)
                    out.append((prev[0] + (cur[0] - prev[0]) * t, prev[1] + (cur[1] - prev[1]) * t))
                out.append(cur)
            elif sp >= 0:
                t = sp / (sp - sc)
                out.append((prev[0] + (cur[0] - prev[0]) * t, prev[1] + (cur[1] - prev[1]) * t))
    return out


def overlap_area(subject, window):
    pts = clip(subject, window)
    return abs(shoelace(pts)) if len(pts) >= 3 else 0.0


def inside(pt, poly, tol):
    """pt within distance tol of the polygon (either orientation)."""
    sign = 1.0 if shoelace(poly) >= 0 else -1.0
    for i in range(len(poly)):
        (ax, ay), (bx, by) = poly[i], poly[(i + 1) % len(poly)]
        le = math.hypot(bx - ax, by - ay)
        if le > 0 and sign * ((bx - ax) * (pt[1] - ay) - (by - ay) * (pt[0] - ax)) < -tol * le:
            return False
    return True


def hull(points):
    """Counter-clockwise hull of 2-D points, or None when they span no area."""
    if len(points) < 3:
        return None
    try:
        h = ConvexHull(np.array(points))
    except QhullError:
        return None
    return [tuple(points[i]) for i in h.vertices]


def _side(arrays, blk, is_a, n, c, p, q, ctol):
    """Touching vertices, touching faces (loops of rows), 2-D coords of one block."""
    vpos, bvstart, bvcount, bfstart, bfcount, fvstart, fnvert, fverts = arrays
    rows = list(range(bvstart[blk], bvstart[blk] + bvcount[blk]))
    d = {r: float(n @ (vpos[r] - c)) for r in rows}
    ext = max(d.values()) if is_a else min(d.values())
    touching = [r for r in rows if (d[r] >= ext - ctol if is_a else d[r] <= ext + ctol)]
    xy = {r: (float(p @ (vpos[r] - c)), float(q @ (vpos[r] - c))) for r in rows}
    faces = []
    for f in range(bfstart[blk], bfstart[blk] + bfcount[blk]):
        loop = [int(r) for r in fverts[fvstart[f]:fvstart[f] + fnvert[f]]]
        if all(r in touching for r in loop):
            faces.append((f, loop))
    return touching, faces, xy


def _face_under(pt, faces, xy, tol):
    for f, loop in faces:
        if inside(pt, [xy[r] for r in loop], tol):
            return f
    return -1


def subcontacts_ref(arrays, a, b, n, c, ctol, point_area):
    n = np.asarray(n, float)
    c = np.asarray(c, float)
    p, q = basis(n)

    def lift(pt):
        return c + pt[0] * p + pt[1] * q

    sides = [_side(arrays, a, True, n, c, p, q, ctol), _side(arrays, b, False, n, c, p, q, ctol)]
    hulls = [hull([s[2][r] for r in s[0]]) for s in sides]
    isface = [len(sides[s][1]) > 0 and hulls[s] is not None for s in range(2)]
    if all(isface):
        return _face_face(sides, hulls, ctol, lift)
    return _points(sides, hulls, isface, ctol, point_area, lift)


def _face_face(sides, hulls, ctol, lift):
    small = min(abs(shoelace(hulls[0])), abs(shoelace(hulls[1])))
    if overlap_area(hulls[0], hulls[1]) <= 1e-6 * small:     # faces touching along an edge or corner
        return []
    order, edges, share, isin = [], [], [], []
    for s in range(2):
        touching, faces, xy = sides[s]
        other = hulls[1 - s]
        vorder, vedges, vshare = [], [], {}
        for f, loop in faces:
            for i, r in enumerate(loop):
                if r not in vorder:
                    vorder.append(r)
                e = (r, loop[(i + 1) % len(loop)])
                if e not in vedges and e[::-1] not in vedges:
                    vedges.append(e)
            # fan from the first loop vertex; 1/3 of each triangle to each corner
            for i in range(1, len(loop) - 1):
                tri = [loop[0], loop[i], loop[i + 1]]
                g = tuple(sum(xy[r][k] for r in tri) / 3.0 for k in range(2))
                for j in range(3):
                    v, vn, vp = tri[j], tri[(j + 1) % 3], tri[(j + 2) % 3]
                    mid_n = tuple(0.5 * (xy[v][k] + xy[vn][k]) for k in range(2))
                    mid_p = tuple(0.5 * (xy[v][k] + xy[vp][k]) for k in range(2))
                    quad = [xy[v], mid_n, g, mid_p]
                    vshare[v] = vshare.get(v, 0.0) + overlap_area(quad, other)
        order.append(vorder)
        edges.append(vedges)
        share.append(vshare)
        isin.append({r: inside(xy[r], other, ctol) for r in vorder})
    xa, xb = sides[0][2], sides[1][2]
    crossings = []   # [edge of A, edge of B, point, collected share]
    for ea in edges[0]:
        p0, p1 = np.array(xa[ea[0]]), np.array(xa[ea[1]])
        for eb in edges[1]:
            r0, r1 = np.array(xb[eb[0]]), np.array(xb[eb[1]])
            d1, d2, w = p1 - p0, r1 - r0, r0 - p0
            l1, l2 = np.hypot(*d1), np.hypot(*d2)
            den = d1[0] * d2[1] - d1[1] * d2[0]
            if l1 == 0 or l2 == 0 or abs(den) <= 1e-12 * l1 * l2:
                continue
            t = (w[0] * d2[1] - w[1] * d2[0]) / den
            u = (w[0] * d1[1] - w[1] * d1[0]) / den
            if min(t * l1, (1 - t) * l1, u * l2, (1 - u) * l2) <= ctol:
                continue
            crossings.append([ea, eb, tuple(p0 + t * d1), 0.0])
    for s in range(2):
        for r in order[s]:
            if isin[s][r]:
                continue
            mine = [x for x in crossings if r in x[s]]
            for x in mine:
                x[3] += share[s][r] / len(mine)
    total = sum(share[s][r] for s in range(2) for r in order[s] if isin[s][r])
    total += sum(x[3] for x in crossings)
    area = overlap_area(hulls[0], hulls[1])
    scale = area / total if total > 0 else 0.0
    out = []
    for s in range(2):
        o_faces, o_xy = sides[1 - s][1], sides[1 - s][2]
        for r in order[s]:
            if isin[s][r]:
                pt = sides[s][2][r]
                out.append((s, r, _face_under(pt, o_faces, o_xy, ctol), lift(pt), share[s][r] * scale))
    for ea, eb, pt, sh in crossings:
        out.append((2, edge_code(*ea), edge_code(*eb), lift(pt), sh * scale))
    return out


def _points(sides, hulls, isface, ctol, point_area, lift):
    what = []
    for s in range(2):
        touching, faces, xy = sides[s]
        if isface[s]:
            what.append(("face",))
        elif len(touching) == 1:
            what.append(("vertex", touching[0]))
        else:
            best = max(((xy[u][0] - xy[v][0]) ** 2 + (xy[u][1] - xy[v][1]) ** 2, min(u, v), max(u, v))
                       for i, u in enumerate(touching) for v in touching[i + 1:])
            pairs = [(min(u, v), max(u, v)) for i, u in enumerate(touching) for v in touching[i + 1:]
                     if (xy[u][0] - xy[v][0]) ** 2 + (xy[u][1] - xy[v][1]) ** 2 == best[0]]
            what.append(("edge",) + pairs[0])      # the first farthest pair met
    kinds = [w[0] for w in what]
    if "vertex" in kinds:
        s = kinds.index("vertex")
        o = 1 - s
        r = what[s][1]
        pt = sides[s][2][r]
        if kinds[o] == "face":
            key1 = _face_under(pt, sides[o][1], sides[o][2], ctol)
        elif kinds[o] == "edge":
            key1 = edge_code(what[o][1], what[o][2])
        else:
            key1 = what[o][1]
        return [(3, r, key1, lift(pt), point_area)]
    if kinds == ["edge", "edge"]:
        a0, a1 = (np.array(sides[0][2][r]) for r in what[0][1:])
        b0, b1 = (np.array(sides[1][2][r]) for r in what[1][1:])
        d1, d2 = a1 - a0, b1 - b0
        den = d1[0] * d2[1] - d1[1] * d2[0]
        if abs(den) < 1e-300:
            pt = 0.25 * (a0 + a1 + b0 + b1)
        else:
            w = b0 - a0
            t = min(max((w[0] * d2[1] - w[1] * d2[0]) / den, 0.0), 1.0)
            pt = a0 + t * d1
        return [(3, edge_code(*what[0][1:]), edge_code(*what[1][1:]), lift(pt), point_area)]
    s = kinds.index("edge")
    o = 1 - s
    lo, hi = what[s][1:]
    pa, pb = np.array(sides[s][2][lo]), np.array(sides[s][2][hi])
    t0, t1 = 0.0, 1.0
    poly = hulls[o]
    for i in range(len(poly)):
        e0, e1 = np.array(poly[i]), np.array(poly[(i + 1) % len(poly)])
        e = e1 - e0
        fa = e[0] * (pa[1] - e0[1]) - e[1] * (pa[0] - e0[0])
        fb = e[0] * (pb[1] - e0[1]) - e[1] * (pb[0] - e0[0])
        if fa < 0 and fb < 0:
            return []
        if fa < 0:
            t0 = max(t0, fa / (fa - fb))
        elif fb < 0:
            t1 = min(t1, fa / (fa - fb))
    if t1 < t0:
        return []
    out = []
    for r, t in ((lo, t0), (hi, t1)):
        pt = pa + (pb - pa) * t
        out.append((3, r, _face_under(pt, sides[o][1], sides[o][2], ctol), lift(pt), point_area))
    return out
