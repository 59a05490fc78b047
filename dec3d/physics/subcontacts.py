"""Sub-contacts of one contact on its common plane (3DEC theory, "Interaction between Blocks").

dec3d's construction (a documented simplification of 3DEC's vertex-face + edge-edge scheme):
the vertices of A and of B touching the c-p are projected onto it (2-D basis p, q) and their
convex hulls PA, PB are intersected.

- face-face (both hulls are polygons): the sub-contacts are the vertices of PA ∩ PB, i.e. the
  vertices of A inside B's face (vertex-face), those of B inside A's face, and the crossings
  of their edges (edge-edge). Each owns its median-dual share of the overlap polygon
  (vertex, the two edge midpoints and the centroid), so the areas sum exactly to the
  contact area. Coincident A/B vertices are merged into one sub-contact, which replaces
  3DEC's halving of two parallel spring sets.
- lower contact types: points (the touching vertex, the clipped segment ends, the edge
  crossing) with a nominal area ``point_area`` each.
"""
from __future__ import annotations

import numpy as np


def _hull2(pts: np.ndarray, tol: float) -> np.ndarray:
    """Counter-clockwise convex hull (monotone chain) of 2-D points; duplicates merged."""
    pts = np.unique(np.round(pts / tol) * tol, axis=0) if len(pts) else pts
    if len(pts) <= 2:
        return pts
    order = np.lexsort((pts[:, 1], pts[:, 0]))
    pts = pts[order]

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= tol * tol:
            lower.pop()
        lower.append(p)
    for p in pts[::-1]:
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= tol * tol:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def clip_convex(subject: np.ndarray, clip: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman: polygon ``subject`` clipped by the convex ccw polygon ``clip``."""
    out = subject
    n = len(clip)
    for i in range(n):
        a, b = clip[i], clip[(i + 1) % n]
        inp, out = out, []
        if len(inp) == 0:
            break
        e = b - a
        for j in range(len(inp)):
            p, q = inp[j - 1], inp[j]
            sp = e[0] * (p[1] - a[1]) - e[1] * (p[0] - a[0])
            sq = e[0] * (q[1] - a[1]) - e[1] * (q[0] - a[0])
            if sq >= 0:
                if sp < 0:
                    out.append(p + (q - p) * (sp / (sp - sq)))
                out.append(q)
            elif sp >= 0:
                out.append(p + (q - p) * (sp / (sp - sq)))
        out = np.array(out) if out else np.zeros((0, 2))
    return np.asarray(out, dtype=float).reshape(-1, 2)


def polygon_area(poly: np.ndarray) -> float:
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def median_dual_areas(poly: np.ndarray) -> np.ndarray:
    """Area owned by each vertex of a convex polygon: the quadrilateral vertex - next-edge
    midpoint - centroid - previous-edge midpoint. Sums to the polygon's area."""
    m = len(poly)
    cen = poly.mean(axis=0)
    out = np.empty(m)
    for i in range(m):
        quad = np.array([poly[i], 0.5 * (poly[i] + poly[(i + 1) % m]), cen, 0.5 * (poly[i] + poly[i - 1])])
        out[i] = abs(polygon_area(quad))
    tot = abs(polygon_area(poly))
    return out * (tot / out.sum()) if out.sum() > 0 else out


def make_subcontacts(va: np.ndarray, vb: np.ndarray, n: np.ndarray, c: np.ndarray, ctol: float,
                     point_area: float) -> tuple[np.ndarray, np.ndarray]:
    """Sub-contact points (k, 3) on the c-p and their areas (k,) [m²] for one contact.

    va, vb: vertex positions of blocks A and B; n: unit normal A → B; c: reference point.
    """
    da = (va - c) @ n
    db = (vb - c) @ n
    ta = va[da >= da.max() - ctol]
    tb = vb[db <= db.min() + ctol]
    ax = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    p = np.cross(n, ax)
    p /= np.linalg.norm(p)
    q = np.cross(n, p)
    tol = max(ctol * 1e-3, 1e-12)
    pa = _hull2(np.column_stack([(ta - c) @ p, (ta - c) @ q]), tol)
    pb = _hull2(np.column_stack([(tb - c) @ p, (tb - c) @ q]), tol)

    def lift(pts2):
        return c + np.outer(pts2[:, 0], p) + np.outer(pts2[:, 1], q)

    if len(pa) >= 3 and len(pb) >= 3:
        ov = clip_convex(pa, pb)
        ov = _hull2(ov, tol) if len(ov) else ov
        if len(ov) >= 3 and abs(polygon_area(ov)) > 0:
            return lift(ov), median_dual_areas(ov)
        pts = ov
    elif len(pa) >= 3 or len(pb) >= 3:
        poly, other = (pa, pb) if len(pa) >= 3 else (pb, pa)
        if len(other) == 2:      # edge-face: the edge clipped by the face
            pts = _clip_segment(other, poly)
        else:                    # vertex-face
            pts = other
    elif len(pa) == 2 and len(pb) == 2:   # edge-edge: the crossing (or nearest point)
        pts = _segment_cross(pa, pb)[None]
    else:                         # vertex-vertex, vertex-edge: the single vertex
        pts = pa if len(pa) == 1 else pb
    if len(pts) == 0:
        return np.zeros((0, 3)), np.zeros(0)
    return lift(np.asarray(pts)), np.full(len(pts), point_area)


def _clip_segment(seg: np.ndarray, poly: np.ndarray) -> np.ndarray:
    a, b = seg
    t0, t1 = 0.0, 1.0
    m = len(poly)
    for i in range(m):
        e0, e1 = poly[i], poly[(i + 1) % m]
        e = e1 - e0
        fa = e[0] * (a[1] - e0[1]) - e[1] * (a[0] - e0[0])
        fb = e[0] * (b[1] - e0[1]) - e[1] * (b[0] - e0[0])
        if fa < 0 and fb < 0:
            return np.zeros((0, 2))
        if fa < 0:
            t0 = max(t0, fa / (fa - fb))
        elif fb < 0:
            t1 = min(t1, fa / (fa - fb))
    if t1 < t0:
        return np.zeros((0, 2))
    return np.array([a + (b - a) * t0, a + (b - a) * t1])


def _segment_cross(s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
    d1, d2 = s1[1] - s1[0], s2[1] - s2[0]
    den = d1[0] * d2[1] - d1[1] * d2[0]
    if abs(den) < 1e-300:
        return 0.5 * (s1.mean(axis=0) + s2.mean(axis=0))
    w = s2[0] - s1[0]
    t = (w[0] * d2[1] - w[1] * d2[0]) / den
    return s1[0] + np.clip(t, 0.0, 1.0) * d1
