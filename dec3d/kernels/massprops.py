"""Volume, centroid and second moment of convex polyhedral blocks, and face geometry.

Divergence theorem, done as a sum of signed tetrahedra: every face is fanned from the
mean of its vertices into triangles, and every triangle makes a tetrahedron with the
block's reference point r (mean of its vertices). For a tetrahedron with vertices
0, a, b, c (relative to r) of signed volume V = det[a, b, c] / 6,

    ∫ x dV     = V (a + b + c) / 4
    ∫ x xᵀ dV  = V / 20 · (a aᵀ + b bᵀ + c cᵀ + s sᵀ),   s = a + b + c

(F. Tonon, "Explicit exact formulas for the 3-D tetrahedron inertia tensor in terms of
its vertex coordinates", J. Math. Stat. 1(1), 2004, Eqs. 2-5 with one vertex at the origin).
Fanning from the face mean is symmetric in the face's winding, so two blocks sharing a
(slightly non-planar, snapped) face see the same surface and their volumes add exactly.

Faces are CSR: face f has vertices ``fv[f_vstart[f] : f_vstart[f] + f_nvert[f]]`` (global
vertex rows), counter-clockwise seen from outside. Block b owns faces
``b_fstart[b] .. b_fstart[b] + b_fcount[b] - 1`` and vertices ``b_vstart[b] ..``.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def block_mass_properties(pos, fv, f_vstart, f_nvert, b_fstart, b_fcount, b_vstart, b_vcount,
                          rows, out_vol, out_cen, out_j):
    """Geometric mass properties of blocks ``rows``.

    pos (nv, 3) m; fv (m,) int64; f_vstart, f_nvert (nf,) int64; b_* (nb,) int64;
    rows (k,) int64 block rows to compute.
    Writes, per entry i of ``rows``: out_vol[i] volume [m³]; out_cen[i] (3,) centroid [m];
    out_j[i] (3, 3) second moment ∫(x−c)(x−c)ᵀ dV about the centroid [m⁵].
    """
    m1 = np.empty(3)
    j = np.empty((3, 3))
    a = np.empty(3)
    bb = np.empty(3)
    cc = np.empty(3)
    ss = np.empty(3)
    r = np.empty(3)
    for i in range(rows.shape[0]):
        b = rows[i]
        vs = b_vstart[b]
        vc = b_vcount[b]
        r[:] = 0.0
        for v in range(vs, vs + vc):
            for x in range(3):
                r[x] += pos[v, x]
        for x in range(3):
            r[x] /= vc
        vol = 0.0
        m1[:] = 0.0
        j[:, :] = 0.0
        for f in range(b_fstart[b], b_fstart[b] + b_fcount[b]):
            s = f_vstart[f]
            k = f_nvert[f]
            # face mean, relative to the reference point
            a[:] = 0.0
            for q in range(s, s + k):
                for x in range(3):
                    a[x] += pos[fv[q], x]
            for x in range(3):
                a[x] = a[x] / k - r[x]
            for q in range(k):
                p = fv[s + q]
                n = fv[s + (q + 1) % k]
                for x in range(3):
                    bb[x] = pos[p, x] - r[x]
                    cc[x] = pos[n, x] - r[x]
                v6 = (a[0] * (bb[1] * cc[2] - bb[2] * cc[1])
                      - a[1] * (bb[0] * cc[2] - bb[2] * cc[0])
                      + a[2] * (bb[0] * cc[1] - bb[1] * cc[0]))
                vt = v6 / 6.0
                vol += vt
                for x in range(3):
                    ss[x] = a[x] + bb[x] + cc[x]
                for x in range(3):
                    m1[x] += vt * ss[x] / 4.0
                    for y in range(3):
                        j[x, y] += vt / 20.0 * (a[x] * a[y] + bb[x] * bb[y] + cc[x] * cc[y]
                                                + ss[x] * ss[y])
        out_vol[i] = vol
        for x in range(3):
            out_cen[i, x] = r[x] + m1[x] / vol
        # parallel-axis shift from the reference point to the centroid
        for x in range(3):
            for y in range(3):
                out_j[i, x, y] = j[x, y] - m1[x] * m1[y] / vol


@njit(cache=True)
def face_geometry(pos, fv, f_vstart, f_nvert, rows, out_normal, out_area, out_centroid):
    """Unit outward normal (Newell's area vector), area [m²] and area centroid [m] of faces.

    pos (nv, 3); fv, f_vstart, f_nvert as in the module docstring; rows (k,) face rows.
    Writes out_normal[f] (3,), out_area[f], out_centroid[f] (3,) for each f in ``rows``
    (indexed by face row, not by position in ``rows``).
    """
    m = np.empty(3)
    av = np.empty(3)
    cen = np.empty(3)
    e1 = np.empty(3)
    e2 = np.empty(3)
    for i in range(rows.shape[0]):
        f = rows[i]
        s = f_vstart[f]
        k = f_nvert[f]
        m[:] = 0.0
        for q in range(s, s + k):
            for x in range(3):
                m[x] += pos[fv[q], x]
        for x in range(3):
            m[x] /= k
        av[:] = 0.0
        cen[:] = 0.0
        total = 0.0
        for q in range(k):
            p = fv[s + q]
            n = fv[s + (q + 1) % k]
            for x in range(3):
                e1[x] = pos[p, x] - m[x]
                e2[x] = pos[n, x] - m[x]
            c0 = e1[1] * e2[2] - e1[2] * e2[1]
            c1 = e1[2] * e2[0] - e1[0] * e2[2]
            c2 = e1[0] * e2[1] - e1[1] * e2[0]
            av[0] += 0.5 * c0
            av[1] += 0.5 * c1
            av[2] += 0.5 * c2
            ta = 0.5 * np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
            total += ta
            for x in range(3):
                cen[x] += ta * (m[x] + pos[p, x] + pos[n, x]) / 3.0
        a = np.sqrt(av[0] ** 2 + av[1] ** 2 + av[2] ** 2)
        out_area[f] = a
        for x in range(3):
            out_normal[f, x] = av[x] / a if a > 0.0 else 0.0
            out_centroid[f, x] = cen[x] / total if total > 0.0 else m[x]
