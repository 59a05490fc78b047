"""Common-plane (c-p) detection between two convex vertex sets (3DEC theory, Cundall 1988).

Conventions (ERRATA, Eqs. 6-8): the unit normal ``n`` points from block A to block B;
signed distances are measured from the c-p through its reference point C:

    d_A = max over vertices of A of n·(V − C)      (Eq. 7, corrected)
    d_B = min over vertices of B of n·(V − C)      (Eq. 6)
    gap = d_B − d_A                                (> 0: apart, < 0: overlap), metres

The gap does not depend on C, only on n, so the rotation search (Eq. 10) is a
hill-climb of g(n) = min_B n·V − max_A n·V over the unit sphere: four perturbations
n := (n ± k p)/z, (n ± k q)/z with z² = 1 + k², k from tan 5° down to tan 0.01°; the
perturbation axes p, q are turned by 45° on alternate iterations (saddle points); the
search stops early when the gap exceeds CTOL (no contact).

Contact types (ERRATA, Table 1) from the number of vertices of A / B touching the c-p:
1/1 vertex-vertex, 1/2 vertex-edge, 1/≥3 vertex-face, 2/2 edge-edge, 2/≥3 edge-face,
≥3/≥3 face-face (and the symmetric cases).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

CT_NONE = 0
CT_VV = 1
CT_VE = 2
CT_VF = 3
CT_EE = 4
CT_EF = 5
CT_FF = 6
CONTACT_TYPE_NAMES = ("none", "vertex-vertex", "vertex-edge", "vertex-face", "edge-edge",
                      "edge-face", "face-face")

KMAX_DEG = 5.0
KMIN_DEG = 0.01
ORIENT = (0.0, math.pi / 4, math.pi / 8, 3 * math.pi / 8, math.pi / 16, 5 * math.pi / 16, 3 * math.pi / 16, 7 * math.pi / 16)
NORIENT = 8
#: iterations of one fast-path search; a plane not settled by then (ridges of degenerate
#: edge-edge and vertex-vertex contacts) continues from where it stopped at the next detection
MAX_IT_EXISTING = 48


@njit(cache=True)
def contact_type(na, nb):
    """Contact type code (CT_*) from touching-vertex counts na of A and nb of B (ERRATA Table 1)."""
    lo = min(na, nb)
    hi = max(na, nb)
    if lo <= 0:
        return CT_NONE
    if lo == 1:
        if hi == 1:
            return CT_VV
        if hi == 2:
            return CT_VE
        return CT_VF
    if lo == 2:
        if hi == 2:
            return CT_EE
        return CT_EF
    return CT_FF


@njit(cache=True)
def _gap3(va, vb, n0, n1, n2):
    """g(n) = min_B n·V − max_A n·V for vertex arrays va (na, 3), vb (nb, 3) [m], n = (n0, n1, n2)."""
    da = -1e300
    for i in range(va.shape[0]):
        d = n0 * va[i, 0] + n1 * va[i, 1] + n2 * va[i, 2]
        if d > da:
            da = d
    db = 1e300
    for i in range(vb.shape[0]):
        d = n0 * vb[i, 0] + n1 * vb[i, 1] + n2 * vb[i, 2]
        if d < db:
            db = d
    return db - da


@njit(cache=True)
def _perp(n0, n1, n2):
    """A unit vector p orthogonal to n (n × the coordinate axis least aligned with n, normalised)
    and q = n × p."""
    ax = abs(n0)
    ay = abs(n1)
    az = abs(n2)
    if ax <= ay and ax <= az:
        t0, t1, t2 = 1.0, 0.0, 0.0
    elif ay <= az:
        t0, t1, t2 = 0.0, 1.0, 0.0
    else:
        t0, t1, t2 = 0.0, 0.0, 1.0
    p0 = n1 * t2 - n2 * t1
    p1 = n2 * t0 - n0 * t2
    p2 = n0 * t1 - n1 * t0
    s = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
    p0 /= s
    p1 /= s
    p2 /= s
    return p0, p1, p2, n1 * p2 - n2 * p1, n2 * p0 - n0 * p2, n0 * p1 - n1 * p0


@njit(cache=True)
def _face_normal(v, n0, n1, n2, ctol, is_a):
    """Unit normal (oriented like n) of the plane through the vertices of ``v`` that touch
    the c-p (within ctol of the block's level nearest it), or zeros if fewer than three
    touch or they are collinear. Three well-spread touching vertices define it."""
    sg = 1.0 if is_a else -1.0
    lev = -1e300
    for i in range(v.shape[0]):
        d = sg * (n0 * v[i, 0] + n1 * v[i, 1] + n2 * v[i, 2])
        if d > lev:
            lev = d
    i0 = -1
    for i in range(v.shape[0]):
        if sg * (n0 * v[i, 0] + n1 * v[i, 1] + n2 * v[i, 2]) >= lev - ctol:
            i0 = i
            break
    i1 = -1
    far = 0.0
    for i in range(v.shape[0]):
        if sg * (n0 * v[i, 0] + n1 * v[i, 1] + n2 * v[i, 2]) >= lev - ctol:
            d = (v[i, 0] - v[i0, 0]) ** 2 + (v[i, 1] - v[i0, 1]) ** 2 + (v[i, 2] - v[i0, 2]) ** 2
            if d > far:
                far = d
                i1 = i
    if i1 < 0:
        return 0.0, 0.0, 0.0
    e0 = v[i1, 0] - v[i0, 0]
    e1 = v[i1, 1] - v[i0, 1]
    e2 = v[i1, 2] - v[i0, 2]
    best = 0.0
    c0 = 0.0
    c1 = 0.0
    c2 = 0.0
    for i in range(v.shape[0]):
        if sg * (n0 * v[i, 0] + n1 * v[i, 1] + n2 * v[i, 2]) >= lev - ctol:
            r0 = v[i, 0] - v[i0, 0]
            r1 = v[i, 1] - v[i0, 1]
            r2 = v[i, 2] - v[i0, 2]
            x0 = e1 * r2 - e2 * r1
            x1 = e2 * r0 - e0 * r2
            x2 = e0 * r1 - e1 * r0
            a = x0 * x0 + x1 * x1 + x2 * x2
            if a > best:
                best = a
                c0 = x0
                c1 = x1
                c2 = x2
    if best <= 1e-18 * far * far:
        return 0.0, 0.0, 0.0
    s = math.sqrt(best)
    if c0 * n0 + c1 * n1 + c2 * n2 < 0.0:
        s = -s
    return c0 / s, c1 / s, c2 / s


@njit(cache=True)
def common_plane(va, vb, n0, ctol, existing, out_n, out_c):
    """Position the c-p between convex vertex sets va (na, 3) and vb (nb, 3) [m].

    n0 (3,): starting unit normal (A → B); for a new contact pass B − A centroids (Eq. 5).
    existing: True for a contact that already has a c-p (fast path, below).
    Writes the unit normal into out_n (3,) and the reference point (Eqs. 8-9) into out_c (3,).
    Returns (gap [m], touching vertices of A, touching vertices of B, iterations).
    A vertex touches when it lies within ctol of its block's nearest level on the c-p.
    When the gap exceeds ctol the search stops early (counts are 0).

    New contact: k starts at tan 5° and is halved once the four perturbations have failed
    in every axis orientation (0°, 45°, and the 22.5° family for ridges), down to tan 0.01°.
    Existing contact: the plane moves little between detections, so k starts at tan 0.01°;
    one iteration in the 0° and 45° orientations confirms the plane (the text: "only one
    rotation iteration is usually needed"); while perturbations succeed k doubles (up to
    tan 5°), when both orientations fail it halves; at most MAX_IT_EXISTING iterations.
    """
    s = math.sqrt(n0[0] ** 2 + n0[1] ** 2 + n0[2] ** 2)
    m0 = n0[0] / s
    m1 = n0[1] / s
    m2 = n0[2] / s
    kmax = math.tan(math.radians(KMAX_DEG))
    kmin = math.tan(math.radians(KMIN_DEG))
    k = kmin if existing else kmax
    nfail = 2 if existing else NORIENT
    best = _gap3(va, vb, m0, m1, m2)
    # an improvement must beat round-off: on the plateaus of edge-edge and vertex-vertex
    # contacts (many normals give the same gap) gains of 1e-17 m would go on for ever
    size = 0.0
    for i in range(va.shape[0]):
        for d in range(3):
            size = max(size, abs(va[i, d] - va[0, d]), abs(vb[0, d] - va[0, d]))
    eps = 1e-12 * size
    it = 0
    fails = 0
    while True:
        it += 1
        p0, p1, p2, q0, q1, q2 = _perp(m0, m1, m2)
        # axes turned about n on successive iterations: 45° on alternate ones (as the text
        # says), and, while a step size keeps failing, by 22.5° and 67.5° too (ridges)
        ang = ORIENT[(it - 1) % nfail] if existing else ORIENT[(it - 1) % NORIENT]
        ca = math.cos(ang)
        sa = math.sin(ang)
        a0 = ca * p0 + sa * q0
        a1 = ca * p1 + sa * q1
        a2 = ca * p2 + sa * q2
        b0 = ca * q0 - sa * p0
        b1 = ca * q1 - sa * p1
        b2 = ca * q2 - sa * p2
        z = math.sqrt(1.0 + k * k)
        improved = False
        c0 = m0
        c1 = m1
        c2 = m2
        for j in range(4):
            sg = k if j % 2 == 0 else -k
            if j < 2:
                t0 = (m0 + sg * a0) / z
                t1 = (m1 + sg * a1) / z
                t2 = (m2 + sg * a2) / z
            else:
                t0 = (m0 + sg * b0) / z
                t1 = (m1 + sg * b1) / z
                t2 = (m2 + sg * b2) / z
            g = _gap3(va, vb, t0, t1, t2)
            if g > best + eps:
                best = g
                improved = True
                c0 = t0
                c1 = t1
                c2 = t2
        if improved:
            fails = 0
            m0 = c0
            m1 = c1
            m2 = c2
            if existing:
                k = min(2.0 * k, kmax)
        else:
            fails += 1          # a step size is given up only when every orientation fails
            if fails >= nfail:
                fails = 0
                if k <= kmin * 1.0000001:
                    break
                k = max(k * 0.5, kmin)
        if best > ctol or it > (MAX_IT_EXISTING if existing else 10000):
            break
    if best <= ctol:
        # face snap: the hill-climb stops within k_min (0.01°) of the best plane; when one
        # block shows a face to the plane, that face's own normal is tried and kept if it
        # is no worse, so face contacts get the exact plane (a 0.01° tilt across a 1 m face
        # is a spurious 0.1 mm overlap)
        for side in range(2):
            f0, f1, f2 = _face_normal(va if side == 0 else vb, m0, m1, m2, ctol, side == 0)
            if f0 == 0.0 and f1 == 0.0 and f2 == 0.0:
                continue
            g = _gap3(va, vb, f0, f1, f2)
            if g >= best - eps:
                best = g
                m0 = f0
                m1 = f1
                m2 = f2
                break
    n = np.empty(3)
    n[0] = m0
    n[1] = m1
    n[2] = m2
    # translation: Eq. (8) for touching blocks, Eq. (9) (midway between nearest vertices) if apart
    ia = 0
    da = -1e300
    for i in range(va.shape[0]):
        d = n[0] * va[i, 0] + n[1] * va[i, 1] + n[2] * va[i, 2]
        if d > da:
            da = d
            ia = i
    ib = 0
    db = 1e300
    for i in range(vb.shape[0]):
        d = n[0] * vb[i, 0] + n[1] * vb[i, 1] + n[2] * vb[i, 2]
        if d < db:
            db = d
            ib = i
    gap = db - da
    for i in range(3):
        out_n[i] = n[i]
    if gap > 0.0:
        for i in range(3):
            out_c[i] = 0.5 * (va[ia, i] + vb[ib, i])
    else:
        # keep the in-plane position of out_c (the caller's reference point), move it along n
        dc = n[0] * out_c[0] + n[1] * out_c[1] + n[2] * out_c[2]
        for i in range(3):
            out_c[i] += (0.5 * (da + db) - dc) * n[i]
    if gap > ctol:
        return gap, 0, 0, it
    na = 0
    for i in range(va.shape[0]):
        if n[0] * va[i, 0] + n[1] * va[i, 1] + n[2] * va[i, 2] >= da - ctol:
            na += 1
    nb = 0
    for i in range(vb.shape[0]):
        if n[0] * vb[i, 0] + n[1] * vb[i, 1] + n[2] * vb[i, 2] <= db + ctol:
            nb += 1
    return gap, na, nb, it
