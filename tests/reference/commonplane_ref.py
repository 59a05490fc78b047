"""Slow reference for the common plane of two convex blocks (``kernels.commonplane``,
``kernels.contactmap.cp_batch``), written from its definition, not from the kernels' search.

3DEC theory ("A Scheme to Detect and Represent Contacts in 3D", Eqs. 6-10, ERRATA): the c-p of
blocks A and B is the plane that maximises the gap g(n) = min_B n·V − max_A n·V over unit
normals n (A → B); its reference point lies midway between the two blocks' nearest levels.
The maximum is found here without any search:

* the blocks overlap (max g ≤ 0): −max g is the penetration depth, and by the separating-axis
  theorem for convex polyhedra it is reached on a face normal of A or B or on the cross product
  of an edge of A with an edge of B, so the maximum over those axes is exact;
* the blocks are apart: max g is the Euclidean distance between them, reached along the line of
  their closest points, which is found by minimising |Σλᵢaᵢ − Σμⱼbⱼ| over the two weight
  simplices (SLSQP), as ``rigid_ref.hull_distance`` does.
"""
import itertools
import math

import numpy as np
from scipy.optimize import minimize
from scipy.spatial import ConvexHull

# ERRATA Table 1: contact type from the numbers of vertices of A and B touching the plane
# (1 a vertex, 2 an edge, 3 or more a face), the smaller count first
TYPE_NAMES = {(1, 1): "vertex-vertex", (1, 2): "vertex-edge", (1, 3): "vertex-face",
              (2, 2): "edge-edge", (2, 3): "edge-face", (3, 3): "face-face"}


def gap(va, vb, n):
    """g(n) = min over B of n·V − max over A of n·V [m]."""
    n = np.asarray(n, float)
    return float(min(v @ n for v in vb) - max(v @ n for v in va))


def _hull_faces_and_edges(v):
    h = ConvexHull(v)
    normals = [eq[:3] / np.linalg.norm(eq[:3]) for eq in h.equations]
    edges = set()
    for tri in h.simplices:                       # triangle edges: the polygon edges and some diagonals
        for i, j in itertools.combinations(sorted(tri), 2):
            edges.add((i, j))
    return normals, [v[j] - v[i] for i, j in edges]


def separating_axes(va, vb):
    """Face normals of both blocks and cross products of their edges, both signs, unit length."""
    na, ea = _hull_faces_and_edges(va)
    nb, eb = _hull_faces_and_edges(vb)
    axes = na + nb
    for a in ea:
        for b in eb:
            c = np.cross(a, b)
            s = np.linalg.norm(c)
            if s > 1e-12 * np.linalg.norm(a) * np.linalg.norm(b):
                axes.append(c / s)
    return axes + [-x for x in axes]


def closest_points(va, vb):
    """Closest points of the convex hulls of va and vb (SLSQP over the weight simplices)."""
    na, nb = len(va), len(vb)

    def f(x):
        d = x[:na] @ va - x[na:] @ vb
        return d @ d

    cons = [{"type": "eq", "fun": lambda x: x[:na].sum() - 1.0},
            {"type": "eq", "fun": lambda x: x[na:].sum() - 1.0}]
    x0 = np.concatenate([np.full(na, 1.0 / na), np.full(nb, 1.0 / nb)])
    r = minimize(f, x0, bounds=[(0, 1)] * (na + nb), constraints=cons, method="SLSQP",
                 options={"ftol": 1e-18, "maxiter": 1000})
    return r.x[:na] @ va, r.x[na:] @ vb


def best_plane(va, vb):
    """(largest gap over all unit normals, a normal reaching it) for vertex arrays va, vb."""
    va, vb = np.asarray(va, float), np.asarray(vb, float)
    best, bn = -math.inf, None
    for n in separating_axes(va, vb):
        g = gap(va, vb, n)
        if g > best:
            best, bn = g, n
    if best > 0:                                  # apart: the distance, along the closest points
        pa, pb = closest_points(va, vb)
        d = np.linalg.norm(pb - pa)
        if d > best:
            best, bn = d, (pb - pa) / d
    return best, bn


def touching(va, vb, n, tol):
    """Vertices of A within tol of A's highest level along n, and of B within tol of its lowest."""
    da = np.asarray(va) @ n
    db = np.asarray(vb) @ n
    return int((da >= da.max() - tol).sum()), int((db <= db.min() + tol).sum())


def type_name(na, nb):
    lo, hi = sorted((min(na, 3), min(nb, 3)))
    return "none" if lo == 0 else TYPE_NAMES[(lo, hi)]
