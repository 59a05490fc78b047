"""Measures of a disk DFN: P10 on a scanline, P21 on a plane, P32 in a box, connectivity clusters.

- P10 = (disks a segment crosses) / (its length). A disk (c, n, r) is crossed by p0 + t d, t ∈ [0, 1],
  when n·d ≠ 0, t = n·(c − p0) / n·d ∈ [0, 1] and |p0 + t d − c| ≤ r.
- P21 = (trace length inside the box) / (area of the plane's section of the box). The trace of a disk
  on the plane m·(x − o) = 0 is its chord along the planes' common line: at distance δ = |h| / |g|
  from the centre (h = m·(c − o), g = m − (m·n) n), half-length √(r² − δ²); it is clipped to the box
  by the slab method.
- P32 = (disk area inside the box) / (box volume), the area clipped *exactly*: the disk's plane cuts
  the box in a convex polygon (the disk's bounding square clipped by the six faces, Sutherland–Hodgman),
  and the area of a disk ∩ a convex polygon is the sum over the polygon's edges of the signed area of
  the disk ∩ the triangle (centre, edge): straight (triangle) parts inside the circle, circular sectors
  r² Δφ / 2 outside. Disks wholly inside (their extent r √(1 − n_k²) along every axis within the box)
  count π r², wholly outside 0.
- Clusters: two disks intersect when their chords on the line common to their planes overlap
  (|s1 − s2| ≤ a1 + a2, a = half-chord); coplanar disks when their centres are closer than r1 + r2.
  Candidate pairs from a k-d tree of the centres (radius r_i + r_max); the components of the
  intersection graph are the clusters (scipy.sparse.csgraph, the union-find of the graph).
"""
from __future__ import annotations

import math

import numpy as np

_F = np.float64


def scanline_hits(c, n, r, p0, p1) -> np.ndarray:
    """Which disks the segment p0 → p1 crosses (bool per disk)."""
    c, n, r = np.asarray(c, _F).reshape(-1, 3), np.asarray(n, _F).reshape(-1, 3), np.asarray(r, _F)
    p0, d = np.asarray(p0, _F), np.asarray(p1, _F) - np.asarray(p0, _F)
    den = n @ d
    num = np.einsum("ij,ij->i", n, c - p0)
    ok = np.abs(den) > 1e-300
    t = np.where(ok, num / np.where(ok, den, 1.0), -1.0)
    q = p0 + t[:, None] * d
    return ok & (t >= 0) & (t <= 1) & (np.einsum("ij,ij->i", q - c, q - c) <= r * r)


def p10(c, n, r, p0, p1) -> float:
    length = float(np.linalg.norm(np.asarray(p1, _F) - np.asarray(p0, _F)))
    return float(scanline_hits(c, n, r, p0, p1).sum()) / length


# ------------------------------------------------------------------ exact disk ∩ box
def _basis(n):
    a = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(a, n)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def _clip(poly, a, b, lim):
    """Keep the part of the 2D polygon where a·s + b·t ≤ lim (Sutherland–Hodgman, one half-plane)."""
    out = []
    k = len(poly)
    for i in range(k):
        p, q = poly[i], poly[(i + 1) % k]
        fp, fq = a * p[0] + b * p[1] - lim, a * q[0] + b * q[1] - lim
        if fp <= 0:
            out.append(p)
        if (fp < 0 < fq) or (fq < 0 < fp):
            t = fp / (fp - fq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def section(center, normal, box, half: float):
    """The plane through ``center`` with ``normal`` cut by ``box``, within the square of half-side
    ``half`` about the centre: the convex polygon (list of (s, t) in the plane's basis) and the basis."""
    u, w = _basis(np.asarray(normal, _F))
    poly = [(-half, -half), (half, -half), (half, half), (-half, half)]
    c = np.asarray(center, _F)
    for k in range(3):
        lo, hi = box[2 * k], box[2 * k + 1]
        poly = _clip(poly, u[k], w[k], hi - c[k])          # c_k + s u_k + t w_k ≤ hi
        if not poly:
            break
        poly = _clip(poly, -u[k], -w[k], c[k] - lo)        # ... ≥ lo
        if not poly:
            break
    return poly, u, w


def _circle_tri(ax, ay, bx, by, r):
    """Signed area of the disk (0, r) ∩ the triangle (0, a, b): the part of the edge a → b inside the
    open disk (between the roots t1 < t2 of |a + t (b − a)| = r) counts its triangle, the rest its
    circular sector. A line that only touches the circle (no two roots) is outside."""
    dx, dy = bx - ax, by - ay
    A = dx * dx + dy * dy
    lo_in, hi_in = 1.0, 0.0                 # the inside interval of t, empty by default
    if A > 0:
        B = 2 * (ax * dx + ay * dy)
        C = ax * ax + ay * ay - r * r
        disc = B * B - 4 * A * C
        if disc > 0:
            s = math.sqrt(disc)
            lo_in, hi_in = max((-B - s) / (2 * A), 0.0), min((-B + s) / (2 * A), 1.0)
    pieces = [(0.0, 1.0, False)] if lo_in >= hi_in else \
        [(0.0, lo_in, False), (lo_in, hi_in, True), (hi_in, 1.0, False)]
    total = 0.0
    for t0, t1, inside in pieces:
        if t1 <= t0:
            continue
        px, py = ax + t0 * dx, ay + t0 * dy
        qx, qy = ax + t1 * dx, ay + t1 * dy
        cr = px * qy - py * qx
        total += 0.5 * cr if inside else 0.5 * r * r * math.atan2(cr, px * qx + py * qy)
    return total


def disk_polygon_area(poly, r: float) -> float:
    """Area of the disk of radius r about (0, 0) inside the convex polygon ``poly``."""
    k = len(poly)
    if k < 3:
        return 0.0
    s = 0.0
    for i in range(k):
        (ax, ay), (bx, by) = poly[i], poly[(i + 1) % k]
        s += _circle_tri(ax, ay, bx, by, r)
    return abs(s)


def clipped_areas(c, n, r, box) -> np.ndarray:
    """Area of each disk inside the box (xmin xmax ymin ymax zmin zmax), exact."""
    c, n, r = np.asarray(c, _F).reshape(-1, 3), np.asarray(n, _F).reshape(-1, 3), np.asarray(r, _F)
    b = np.asarray(box, _F)
    lo, hi = b[0::2], b[1::2]
    ext = r[:, None] * np.sqrt(np.clip(1.0 - n * n, 0.0, None))
    inside = ((c - ext >= lo) & (c + ext <= hi)).all(axis=1)
    outside = ((c + ext <= lo) | (c - ext >= hi)).any(axis=1)
    out = np.where(inside, math.pi * r * r, 0.0)
    for i in np.flatnonzero(~inside & ~outside):
        poly, _, _ = section(c[i], n[i], b, float(r[i]))
        out[i] = disk_polygon_area(poly, float(r[i]))
    return out


def p32(c, n, r, box) -> float:
    b = np.asarray(box, _F)
    vol = float((b[1] - b[0]) * (b[3] - b[2]) * (b[5] - b[4]))
    return float(clipped_areas(c, n, r, b).sum()) / vol


# ------------------------------------------------------------------ P21
def traces(c, n, r, origin, m):
    """Chords of the disks on the plane m·(x − origin) = 0: (ends a (k, 3), ends b (k, 3), rows)."""
    c, n, r = np.asarray(c, _F).reshape(-1, 3), np.asarray(n, _F).reshape(-1, 3), np.asarray(r, _F)
    m = np.asarray(m, _F) / np.linalg.norm(m)
    h = (c - np.asarray(origin, _F)) @ m
    g = m[None, :] - (n @ m)[:, None] * n
    g2 = np.einsum("ij,ij->i", g, g)
    ok = g2 > 1e-24
    delta2 = np.where(ok, h * h / np.where(ok, g2, 1.0), np.inf)
    ok &= delta2 < r * r
    rows = np.flatnonzero(ok)
    x0 = c[rows] - (h[rows] / g2[rows])[:, None] * g[rows]
    e = np.cross(n[rows], m)
    e /= np.linalg.norm(e, axis=1)[:, None]
    half = np.sqrt(r[rows] ** 2 - delta2[rows])
    return x0 - half[:, None] * e, x0 + half[:, None] * e, rows


def clip_segments(a, b, box) -> np.ndarray:
    """Length of each segment a → b inside the box (slab method)."""
    d = b - a
    bx = np.asarray(box, _F)
    t0, t1 = np.zeros(len(a)), np.ones(len(a))
    for k in range(3):
        lo, hi = bx[2 * k], bx[2 * k + 1]
        dk = d[:, k]
        par = np.abs(dk) < 1e-300
        out = par & ((a[:, k] < lo) | (a[:, k] > hi))
        with np.errstate(divide="ignore", invalid="ignore"):
            ta, tb = (lo - a[:, k]) / dk, (hi - a[:, k]) / dk
        tmin, tmax = np.where(par, -np.inf, np.minimum(ta, tb)), np.where(par, np.inf, np.maximum(ta, tb))
        t0, t1 = np.maximum(t0, tmin), np.minimum(t1, tmax)
        t1 = np.where(out, t0 - 1, t1)
    return np.clip(t1 - t0, 0, None) * np.linalg.norm(d, axis=1)


def p21(c, n, r, origin, m, box) -> tuple[float, float, float]:
    """(P21, trace length, window area) of the plane through ``origin`` with normal ``m`` in ``box``."""
    a, b, _ = traces(c, n, r, origin, m)
    length = float(clip_segments(a, b, box).sum()) if len(a) else 0.0
    bx = np.asarray(box, _F)
    diag = float(np.linalg.norm(bx[1::2] - bx[0::2]))
    poly, _, _ = section(np.asarray(origin, _F), m, bx, 2 * diag + float(np.abs(origin).max()))
    k = len(poly)
    area = abs(sum(poly[i][0] * poly[(i + 1) % k][1] - poly[(i + 1) % k][0] * poly[i][1] for i in range(k))) / 2
    if not area > 0:
        raise ValueError("the plane does not cut the box")
    return length / area, length, area


# ------------------------------------------------------------------ intersections and clusters
def intersecting_pairs(c, n, r, tol: float = 1e-9) -> np.ndarray:
    """Pairs (i, j), i < j, of disks that intersect (touching counts)."""
    from scipy.spatial import cKDTree

    c, n, r = np.asarray(c, _F).reshape(-1, 3), np.asarray(n, _F).reshape(-1, 3), np.asarray(r, _F)
    if len(c) < 2:
        return np.zeros((0, 2), np.int64)
    tree = cKDTree(c)
    rmax = float(r.max())
    # pairs within r_i + r_max, kept when within r_i + r_j
    order = np.argsort(-r, kind="stable")
    cand = []
    for i in order:
        js = np.asarray(tree.query_ball_point(c[i], float(r[i]) + rmax), np.int64)
        js = js[js > i]
        if js.size:
            cand.append(np.column_stack([np.full(js.size, i, np.int64), js]))
    if not cand:
        return np.zeros((0, 2), np.int64)
    p = np.concatenate(cand)
    i, j = p[:, 0], p[:, 1]
    dc = c[j] - c[i]
    near = np.einsum("ij,ij->i", dc, dc) <= (r[i] + r[j]) ** 2 * (1 + 1e-12)
    p, i, j = p[near], i[near], j[near]
    return p[disks_intersect(c[i], n[i], r[i], c[j], n[j], r[j], tol)]


def disks_intersect(c1, n1, r1, c2, n2, r2, tol: float = 1e-9) -> np.ndarray:
    e = np.cross(n1, n2)
    ee = np.einsum("ij,ij->i", e, e)
    par = ee < 1e-20
    d12 = c2 - c1
    coplanar = par & (np.abs(np.einsum("ij,ij->i", n1, d12)) <= tol) & \
        (np.einsum("ij,ij->i", d12, d12) <= (r1 + r2) ** 2)
    k = np.flatnonzero(~par)
    res = coplanar.copy()
    if k.size == 0:
        return res
    c1, n1, r1, c2, n2, r2, e = c1[k], n1[k], r1[k], c2[k], n2[k], r2[k], e[k]
    eh = e / np.sqrt(ee[k])[:, None]

    def chord(ca, na, ra, cb, nb):
        h = np.einsum("ij,ij->i", nb, ca - cb)
        g = nb - np.einsum("ij,ij->i", nb, na)[:, None] * na
        g2 = np.einsum("ij,ij->i", g, g)
        d2 = h * h / g2
        x0 = ca - (h / g2)[:, None] * g
        return np.einsum("ij,ij->i", x0, eh), np.sqrt(np.clip(ra * ra - d2, 0, None)), d2 <= ra * ra * (1 + 1e-12)

    s1, a1, ok1 = chord(c1, n1, r1, c2, n2)
    s2, a2, ok2 = chord(c2, n2, r2, c1, n1)
    res[k] = ok1 & ok2 & (np.abs(s1 - s2) <= a1 + a2 + tol)
    return res


def clusters(c, n, r) -> tuple[np.ndarray, np.ndarray]:
    """(label per disk, intersecting pairs): disks connected through intersections share a label
    (0 .. k−1, numbered by their first disk)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    k = len(np.asarray(r))
    pairs = intersecting_pairs(c, n, r)
    if k == 0:
        return np.zeros(0, np.int64), pairs
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(k, k))
    _, lab = connected_components(g, directed=False)
    # renumber by first appearance: independent of scipy's numbering
    _, first = np.unique(lab, return_index=True)
    order = np.argsort(first)
    remap = np.empty(len(order), np.int64)
    remap[order] = np.arange(len(order))
    return remap[lab], pairs


# ------------------------------------------------------------------ estimators
def fisher_stats(normals) -> tuple[float, float, float]:
    """(mean dip, mean dip direction [rad], κ̂) of axial unit normals: each normal is turned to the side
    of the first estimate of the mean (the principal axis of Σ n nᵀ), R = |Σ n|, κ̂ = (N − 1) / (N − R)
    (Fisher 1953's estimator)."""
    n = np.asarray(normals, _F).reshape(-1, 3)
    w, v = np.linalg.eigh(n.T @ n)
    axis = v[:, -1]
    s = n * np.where(n @ axis < 0, -1.0, 1.0)[:, None]
    res = s.sum(axis=0)
    big_r = float(np.linalg.norm(res))
    mu = res / big_r
    if mu[2] < 0:
        mu = -mu
    k = len(n)
    kappa = (k - 1) / (k - big_r) if k > big_r else math.inf
    return math.acos(min(1.0, mu[2])), math.atan2(mu[0], mu[1]) % (2 * math.pi), kappa


def powerlaw_mle(sizes, lo: float, hi: float | None) -> float:
    """Maximum-likelihood exponent a of n(l) ∝ l^−a on [lo, hi] (hi None: unbounded) from the sizes:
    the root of d lnL/da = N/(a − 1) + N (lo^{1−a} ln lo − hi^{1−a} ln hi)/(lo^{1−a} − hi^{1−a}) − Σ ln l."""
    from scipy.optimize import brentq

    x = np.asarray(sizes, _F)
    k, sl = len(x), float(np.log(x).sum())
    if hi is None:
        return 1.0 + k / float(np.log(x / lo).sum())

    def dlnl(a):
        if abs(a - 1) < 1e-9:
            a = 1 + 1e-9
        e = 1 - a
        tlo, thi = lo ** e, hi ** e
        return k / (a - 1) + k * (tlo * math.log(lo) - thi * math.log(hi)) / (tlo - thi) - sl

    return float(brentq(dlnl, 1.0 + 1e-6, 50.0))
