"""Twin of dec3d.kernels.polycut: the piece on one side of a plane as a convex hull.

The piece below n·x = d of a convex polyhedron is the convex hull of its vertices with
n·x ≤ d and of the points where its edges cross the plane (scipy's Qhull does the rest).
"""
import numpy as np
from scipy.spatial import ConvexHull


def clip_below_ref(vertices, faces, normal, d):
    """Vertices (k, 3) and volume of {x in P : n·x ≤ d}; (None, 0.0) when empty."""
    v = np.asarray(vertices, dtype=float)
    n = np.asarray(normal, dtype=float)
    s = v @ n - d
    pts = [v[i] for i in range(len(v)) if s[i] <= 0]
    edges = set()
    for loop in faces:
        for a, b in zip(loop, list(loop[1:]) + [loop[0]]):
            edges.add((min(a, b), max(a, b)))
    for a, b in sorted(edges):
        if s[a] * s[b] < 0:
            t = s[a] / (s[a] - s[b])
            pts.append(v[a] + t * (v[b] - v[a]))
    if len(pts) < 4:
        return None, 0.0
    pts = np.array(pts)
    hull = ConvexHull(pts)
    return pts[hull.vertices], hull.volume
