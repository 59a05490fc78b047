"""Plane geometry of the block mesh: polygon properties, checks, shared edges.

Blocks are convex polygons (quadrilaterals and triangles in practice) stored as
one vertex array plus CSR offsets, vertices counter-clockwise.  Two blocks
interact where an edge of one lies on an edge of the other with opposite
orientation; the interface is the overlap of the two edges.  Overlaps are found
by grouping edges by their supporting line, so meshes with hanging vertices
(non-conforming rows, as the grid mesher makes) work as well as conforming ones.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def polygon_area_centroid(verts: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed area (n,) and centroid (n, 2) of every polygon (shoelace formula)."""
    n = len(offsets) - 1
    counts = np.diff(offsets)
    owner = np.repeat(np.arange(n), counts)
    nxt = np.arange(len(verts)) + 1
    nxt[offsets[1:] - 1] = offsets[:-1]          # wrap the last vertex to the first
    p, q = verts, verts[nxt]
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    area = 0.5 * np.bincount(owner, cross, minlength=n)
    cx = np.bincount(owner, (p[:, 0] + q[:, 0]) * cross, minlength=n)
    cy = np.bincount(owner, (p[:, 1] + q[:, 1]) * cross, minlength=n)
    with np.errstate(divide="ignore", invalid="ignore"):
        cen = np.column_stack([cx, cy]) / (6.0 * area[:, None])
    return area, cen


def edges(verts: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """All polygon edges: owner block (E,), local side index (E,), start (E,2), end (E,2)."""
    n = len(offsets) - 1
    counts = np.diff(offsets)
    owner = np.repeat(np.arange(n), counts)
    side = np.arange(len(verts)) - np.repeat(offsets[:-1], counts)
    nxt = np.arange(len(verts)) + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    return owner, side, verts, verts[nxt]


def convexity_defect(verts: np.ndarray, offsets: np.ndarray, tol: float) -> np.ndarray:
    """True for polygons with a reflex corner (cross product of consecutive edges < -tol)."""
    owner, _, p, q = edges(verts, offsets)
    e = q - p
    nxt = np.arange(len(verts)) + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    e2 = e[nxt]
    cross = e[:, 0] * e2[:, 1] - e[:, 1] * e2[:, 0]
    lens = np.hypot(e[:, 0], e[:, 1]) * np.hypot(e2[:, 0], e2[:, 1])
    bad = (cross < -tol * np.maximum(lens, 1e-300)) & (lens > 0)
    return np.bincount(owner, bad, minlength=len(offsets) - 1) > 0


def overlapping_pairs(verts: np.ndarray, offsets: np.ndarray, tol: float) -> list[tuple[int, int]]:
    """Pairs of convex polygons whose interiors overlap (separating-axis test).

    Candidates come from a sweep over bounding boxes sorted by x, so the cost is
    near linear for a mesh.  Touching along an edge or at a corner is not overlap.
    """
    n = len(offsets) - 1
    lo = np.minimum.reduceat(verts, offsets[:-1], axis=0)
    hi = np.maximum.reduceat(verts, offsets[:-1], axis=0)
    order = np.argsort(lo[:, 0], kind="stable")
    out: list[tuple[int, int]] = []
    active: list[int] = []
    for i in order:
        active = [j for j in active if hi[j, 0] > lo[i, 0] + tol]
        for j in active:
            if lo[i, 1] < hi[j, 1] - tol and lo[j, 1] < hi[i, 1] - tol:
                if _sat_overlap(verts[offsets[i]:offsets[i + 1]], verts[offsets[j]:offsets[j + 1]], tol):
                    out.append((int(min(i, j)), int(max(i, j))))
        active.append(i)
    return sorted(out)


def _sat_overlap(p: np.ndarray, q: np.ndarray, tol: float) -> bool:
    for poly in (p, q):
        e = np.roll(poly, -1, axis=0) - poly
        keep = np.hypot(e[:, 0], e[:, 1]) > 0
        normals = np.column_stack([e[keep, 1], -e[keep, 0]])
        normals /= np.hypot(normals[:, 0], normals[:, 1])[:, None]
        pp, qq = p @ normals.T, q @ normals.T
        if np.any((pp.max(0) <= qq.min(0) + tol) | (qq.max(0) <= pp.min(0) + tol)):
            return False
    return True


@dataclass(frozen=True)
class SharedEdges:
    """Interfaces found between blocks.

    a, b   : (m,) blocks; the unit normal points from a to b (a's outward normal)
    p0, p1 : (m, 2) ends of the shared segment
    side_a, side_b : (m,) local side index of the edge in a and in b
    same_side : list of (block, block) pairs whose edges overlap with the same
        orientation, i.e. blocks lying on top of each other (an input error)
    """

    a: np.ndarray
    b: np.ndarray
    p0: np.ndarray
    p1: np.ndarray
    side_a: np.ndarray
    side_b: np.ndarray
    same_side: list


def shared_edges(verts: np.ndarray, offsets: np.ndarray, tol: float) -> SharedEdges:
    """Find every overlap of two collinear, oppositely oriented block edges.

    `tol` is a length: edges whose supporting lines differ by less than it are
    taken as one line, and overlaps shorter than it are ignored.
    """
    owner, side, p, q = edges(verts, offsets)
    d = q - p
    length = np.hypot(d[:, 0], d[:, 1])
    keep = length > tol                       # a repeated vertex (triangle as quad) gives no edge
    owner, side, p, q, d, length = owner[keep], side[keep], p[keep], q[keep], d[keep], length[keep]
    theta = np.mod(np.arctan2(d[:, 1], d[:, 0]), np.pi)
    span = max(float(np.ptp(verts[:, 0])), float(np.ptp(verts[:, 1])), tol)
    ang_tol = tol / span
    theta[theta > np.pi - ang_tol] -= np.pi   # directions near 180 deg join those near 0
    # cluster directions, then offsets of the supporting lines within a direction
    order = np.argsort(theta, kind="stable")
    dir_id = np.empty(len(theta), dtype=np.int64)
    dir_id[order] = np.concatenate([[0], np.cumsum(np.diff(theta[order]) > ang_tol)])
    ndir = int(dir_id.max()) + 1 if len(theta) else 0
    mean_t = np.bincount(dir_id, theta, ndir) / np.maximum(np.bincount(dir_id, minlength=ndir), 1)
    dc = np.column_stack([np.cos(mean_t), np.sin(mean_t)])[dir_id]
    nc = np.column_stack([-dc[:, 1], dc[:, 0]])
    sign = np.where(np.einsum("ij,ij->i", d, dc) > 0, 1, -1)
    offset = np.einsum("ij,ij->i", p, nc)
    s0, s1 = np.einsum("ij,ij->i", p, dc), np.einsum("ij,ij->i", q, dc)
    start, end = np.minimum(s0, s1), np.maximum(s0, s1)
    order = np.lexsort((offset, dir_id))
    brk = (np.diff(dir_id[order]) != 0) | (np.diff(offset[order]) > tol)
    line_id = np.empty(len(order), dtype=np.int64)
    line_id[order] = np.concatenate([[0], np.cumsum(brk)])

    out = {k: [] for k in ("i", "j", "s", "e")}
    same: list[tuple[int, int]] = []
    order = np.lexsort((start, sign, line_id))
    bounds = np.flatnonzero(np.diff(line_id[order])) + 1
    for grp in np.split(order, bounds):
        if len(grp) < 2:
            continue
        pos, neg = grp[sign[grp] > 0], grp[sign[grp] < 0]
        for half in (pos, neg):               # same orientation overlapping = blocks on top of each other
            if len(half) > 1:
                ov = np.flatnonzero(start[half[1:]] < end[half[:-1]] - tol)
                same.extend((int(owner[half[k]]), int(owner[half[k + 1]])) for k in ov)
        if len(pos) == 0 or len(neg) == 0:
            continue
        # neg intervals are disjoint and sorted, so their ends are sorted too
        lo = np.searchsorted(end[neg], start[pos] + tol, side="right")
        hi = np.searchsorted(start[neg], end[pos] - tol, side="left")
        cnt = np.maximum(hi - lo, 0)
        if cnt.sum() == 0:
            continue
        ii = np.repeat(pos, cnt)
        jj = neg[np.concatenate([np.arange(l, l + c) for l, c in zip(lo, cnt) if c > 0])]
        s = np.maximum(start[ii], start[jj])
        e = np.minimum(end[ii], end[jj])
        ok = e - s > tol
        for key, val in zip(("i", "j", "s", "e"), (ii[ok], jj[ok], s[ok], e[ok])):
            out[key].append(val)
    if not out["i"]:
        z = np.zeros(0, dtype=np.int64)
        return SharedEdges(z, z, np.zeros((0, 2)), np.zeros((0, 2)), z, z, sorted(set(same)))
    i, j = np.concatenate(out["i"]), np.concatenate(out["j"])
    s, e = np.concatenate(out["s"]), np.concatenate(out["e"])
    # points on the line: foot of the line + parameter along it; exact vertices when the overlap is whole
    foot = offset[i][:, None] * nc[i]
    p0 = foot + s[:, None] * dc[i]
    p1 = foot + e[:, None] * dc[i]
    keep_order = np.lexsort((owner[j], owner[i]))
    i, j, p0, p1 = i[keep_order], j[keep_order], p0[keep_order], p1[keep_order]
    return SharedEdges(owner[i], owner[j], p0, p1, side[i], side[j], sorted(set(same)))
