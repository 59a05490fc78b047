"""A `poly … face …` block of a 3DEC 4/5 deck that is not convex (an arch voussoir whose intrados is
given as a concave polyline): 3DEC 7+ and dec3d build convex blocks only, so the translator writes
the convex hull of the block's corners instead (its faces: the hull's facets merged by plane) and
says so on the line with the volume it adds."""
from __future__ import annotations

import numpy as np


def _newell(p: np.ndarray) -> np.ndarray:
    n = np.zeros(3)
    for a, b in zip(p, np.roll(p, -1, axis=0)):
        n += np.array([(a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]), (a[0] - b[0]) * (a[1] + b[1])])
    return n


def convex_excess(faces: list[np.ndarray]) -> float:
    """The largest distance of a corner outside the plane of a face (0 for a convex block), in units of
    the coordinates; faces may wind either way (the outward side is the one away from the centroid)."""
    pts = np.vstack(faces)
    c = pts.mean(axis=0)
    worst = 0.0
    for f in faces:
        n = _newell(f)
        if not np.linalg.norm(n) > 0:
            continue
        n = n / np.linalg.norm(n)
        o = f.mean(axis=0)
        if np.dot(c - o, n) > 0:
            n = -n
        worst = max(worst, float(np.max((pts - o) @ n)))
    return worst


def hull_faces(points: np.ndarray, tol: float) -> tuple[list[np.ndarray], float]:
    """(faces of the convex hull, its volume). Facets whose planes
    agree within ``tol`` are merged into one face, its corners ordered around it."""
    from scipy.spatial import ConvexHull

    pts = np.unique(np.round(points, 12), axis=0)
    hull = ConvexHull(pts)
    extreme = np.zeros(len(pts), dtype=bool)
    extreme[hull.vertices] = True
    groups: list[tuple[np.ndarray, float, set]] = []
    for eq, simplex in zip(hull.equations, hull.simplices):
        n, d = eq[:3], eq[3]
        for gn, gd, members in groups:
            if np.dot(gn, n) > 1 - 1e-9 and abs(gd - d) <= tol:
                members.update(int(i) for i in simplex)
                break
        else:
            groups.append((n, d, {int(i) for i in simplex}))
    faces = []
    for n, d, members in groups:
        on = (np.abs(pts @ n + d) <= tol) & extreme       # corners inside a hull face are not its corners
        p = pts[on]
        c = p.mean(axis=0)
        u = p[0] - c
        u = u / np.linalg.norm(u)
        v = np.cross(n, u)
        ang = np.arctan2((p - c) @ v, (p - c) @ u)
        faces.append(p[np.argsort(-ang)])           # clockwise seen from outside
    return faces, float(hull.volume)


def solid_volume(faces: list[np.ndarray]) -> float:
    """Volume enclosed by the faces as given: each face turned outward (away from the centroid), fanned
    from its mean point, tetrahedra to the centroid summed."""
    c = np.vstack(faces).mean(axis=0)
    vol = 0.0
    for f in faces:
        o = f.mean(axis=0)
        if np.dot(_newell(f), o - c) < 0:
            f = f[::-1]
        for a, b in zip(f, np.roll(f, -1, axis=0)):
            vol += float(np.dot(np.cross(a - o, b - o), o - c)) / 6.0
    return vol
