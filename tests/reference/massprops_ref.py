"""Twin of dec3d.kernels.massprops: plain Python loops, a different decomposition.

Every face is fanned from its first vertex (faces are planar) and every triangle makes a
tetrahedron with the global origin; volume, first and second moments are summed with the
closed-form tetrahedron integrals (Tonon 2004), then shifted to the centroid.
"""
import numpy as np


def tet_integrals(p0, p1, p2, p3):
    """Volume, ∫x dV (3,), ∫x xᵀ dV (3, 3) of a tetrahedron (signed by orientation)."""
    p = [np.asarray(x, dtype=float) for x in (p0, p1, p2, p3)]
    v = np.linalg.det(np.array([p[1] - p[0], p[2] - p[0], p[3] - p[0]])) / 6.0
    s = sum(p)
    first = v * s / 4.0
    second = v / 20.0 * (sum(np.outer(q, q) for q in p) + np.outer(s, s))
    return v, first, second


def block_mass_properties_ref(vertices, faces):
    """vertices (nv, 3); faces: list of index loops, counter-clockwise from outside.

    Returns volume, centroid (3,), J = ∫(x−c)(x−c)ᵀ dV (3, 3)."""
    vol = 0.0
    m1 = np.zeros(3)
    m2 = np.zeros((3, 3))
    origin = np.zeros(3)
    for loop in faces:
        for i in range(1, len(loop) - 1):
            v, f, s = tet_integrals(origin, vertices[loop[0]], vertices[loop[i]], vertices[loop[i + 1]])
            vol += v
            m1 += f
            m2 += s
    c = m1 / vol
    return vol, c, m2 - vol * np.outer(c, c)


def face_geometry_ref(points):
    """Unit normal, area and area centroid of one planar polygon (k, 3)."""
    pts = np.asarray(points, dtype=float)
    av = np.zeros(3)
    cen = np.zeros(3)
    total = 0.0
    for i in range(1, len(pts) - 1):
        cr = np.cross(pts[i] - pts[0], pts[i + 1] - pts[0]) / 2.0
        a = np.linalg.norm(cr)
        av += cr
        total += a
        cen += a * (pts[0] + pts[i] + pts[i + 1]) / 3.0
    return av / np.linalg.norm(av), np.linalg.norm(av), cen / total
