"""Small 2-D polygon kernels on a plane (used by ``subgeom`` on the common plane): an
in-plane basis, signed area, convex clipping area, point-in-convex-polygon, convex hull.
Arrays of points are (m, 2) float64 with the live count passed beside them.
"""
from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def basis(n, p, q):
    """Unit p, q with p × q = n: p = n × x (n × y when n is near x), q = n × p."""
    if abs(n[0]) < 0.9:
        t0, t1, t2 = 1.0, 0.0, 0.0
    else:
        t0, t1, t2 = 0.0, 1.0, 0.0
    p[0] = n[1] * t2 - n[2] * t1
    p[1] = n[2] * t0 - n[0] * t2
    p[2] = n[0] * t1 - n[1] * t0
    s = math.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
    p[0] /= s
    p[1] /= s
    p[2] /= s
    q[0] = n[1] * p[2] - n[2] * p[1]
    q[1] = n[2] * p[0] - n[0] * p[2]
    q[2] = n[0] * p[1] - n[1] * p[0]


@njit(cache=True)
def shoelace(poly, m):
    """Signed area of the 2-D polygon poly[:m] [m²] (> 0 counter-clockwise)."""
    s = 0.0
    for i in range(m):
        j = i + 1 if i + 1 < m else 0
        s += poly[i, 0] * poly[j, 1] - poly[j, 0] * poly[i, 1]
    return 0.5 * s


@njit(cache=True)
def clip_area(subj, ns, clip, nc, b1, b2):
    """|area| of polygon subj[:ns] ∩ convex ccw polygon clip[:nc] (Sutherland–Hodgman);
    b1, b2: scratch (≥ ns + nc, 2)."""
    m = ns
    for i in range(ns):
        b1[i, 0] = subj[i, 0]
        b1[i, 1] = subj[i, 1]
    src = b1
    dst = b2
    for e in range(nc):
        if m == 0:
            break
        ax = clip[e, 0]
        ay = clip[e, 1]
        f = e + 1 if e + 1 < nc else 0
        ex = clip[f, 0] - ax
        ey = clip[f, 1] - ay
        k = 0
        for j in range(m):
            i = j - 1 if j > 0 else m - 1
            sp = ex * (src[i, 1] - ay) - ey * (src[i, 0] - ax)
            sq = ex * (src[j, 1] - ay) - ey * (src[j, 0] - ax)
            if sq >= 0.0:
                if sp < 0.0:
                    t = sp / (sp - sq)
                    dst[k, 0] = src[i, 0] + (src[j, 0] - src[i, 0]) * t
                    dst[k, 1] = src[i, 1] + (src[j, 1] - src[i, 1]) * t
                    k += 1
                dst[k, 0] = src[j, 0]
                dst[k, 1] = src[j, 1]
                k += 1
            elif sp >= 0.0:
                t = sp / (sp - sq)
                dst[k, 0] = src[i, 0] + (src[j, 0] - src[i, 0]) * t
                dst[k, 1] = src[i, 1] + (src[j, 1] - src[i, 1]) * t
                k += 1
        m = k
        tmp = src
        src = dst
        dst = tmp
    if m < 3:
        return 0.0
    return abs(shoelace(src, m))


@njit(cache=True)
def inside(x, y, poly, m, sign, tol):
    """True when (x, y) lies in polygon poly[:m] (orientation sign ±1) within distance tol."""
    for i in range(m):
        j = i + 1 if i + 1 < m else 0
        ex = poly[j, 0] - poly[i, 0]
        ey = poly[j, 1] - poly[i, 1]
        le = math.sqrt(ex * ex + ey * ey)
        if le == 0.0:
            continue
        if sign * (ex * (y - poly[i, 1]) - ey * (x - poly[i, 0])) < -tol * le:
            return False
    return True


@njit(cache=True)
def convex_hull(xy, idx, m, order, out):
    """Counter-clockwise convex hull (monotone chain, collinear points dropped) of the points
    xy[idx[:m]] into out; returns its vertex count. order: scratch (≥ m,)."""
    for i in range(m):
        order[i] = idx[i]
    for i in range(1, m):           # insertion sort by (x, y): m is a face's size
        v = order[i]
        j = i - 1
        while j >= 0 and (xy[order[j], 0] > xy[v, 0] or
                          (xy[order[j], 0] == xy[v, 0] and xy[order[j], 1] > xy[v, 1])):
            order[j + 1] = order[j]
            j -= 1
        order[j + 1] = v
    if m < 3:
        for i in range(m):
            out[i, 0] = xy[order[i], 0]
            out[i, 1] = xy[order[i], 1]
        if m == 2 and out[0, 0] == out[1, 0] and out[0, 1] == out[1, 1]:
            return 1
        return m
    k = 0
    for rep in range(2):
        lo = k
        for ii in range(m):
            v = order[ii] if rep == 0 else order[m - 1 - ii]
            while k >= lo + 2:
                cr = ((out[k - 1, 0] - out[k - 2, 0]) * (xy[v, 1] - out[k - 2, 1]) -
                      (out[k - 1, 1] - out[k - 2, 1]) * (xy[v, 0] - out[k - 2, 0]))
                if cr > 0.0:
                    break
                k -= 1
            out[k, 0] = xy[v, 0]
            out[k, 1] = xy[v, 1]
            k += 1
        k -= 1                      # the last point starts the other chain
    return k
