"""The pore-pressure force of the sub-contacts (``dec3d.physics.water``).

Per sub-contact s of contact c (normal n = cn[c], A → B), pore pressure p [Pa] acting on the area A′
[m²] of ``pressure_areas``: the water pushes the faces apart with F = p·A′ (``ppf``) along n on B and
−F n on A, on top of the joint law's
(effective) force. The rigid cycle adds it to the force on B of each sub-contact (sg, before the
block sums, so the moments follow); where a side is zoned it goes to that side's gridpoints by the
sub-contact's interpolation weights, as the joint force does.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .gpcontact import add_to_sides


@njit(cache=True)
def any_pressure(ppf) -> bool:
    """Whether some sub-contact has a non-zero pore-pressure force."""
    for s in range(ppf.shape[0]):
        if ppf[s] != 0.0:
            return True
    return False


@njit(cache=True, inline="always")
def pore_forces(cn, sc_contact, sc_ppf, sg):
    """sg[s] += F n (the force on B of sub-contact s), F = sc_ppf[s] its pore-pressure force [N]."""
    for s in range(sc_contact.shape[0]):
        f = sc_ppf[s]
        if f != 0.0:
            c = sc_contact[s]
            sg[s, 0] += f * cn[c, 0]
            sg[s, 1] += f * cn[c, 1]
            sg[s, 2] += f * cn[c, 2]


@njit(cache=True)
def mixed_pore_forces(bpos, bforce, bmoment, gforce, ca, cb, cn, sc_contact, sc_pos, sc_ppf,
                      nodes_a, w_a, nodes_b, w_b):
    """The pore-pressure force of every sub-contact of a model where zoned and rigid blocks touch
    (``gpcontact.mixed_subcontact_forces`` arrays; sc_ppf (ns,) the pore-pressure forces [N]): F n on
    B and its negative on A, to a rigid
    side's centroid with its moment (x − centroid) × force, or to a zoned side's gridpoints in
    proportion to their weights (node −1: rigid side). Serial: sub-contacts share blocks and
    gridpoints."""
    for s in range(sc_contact.shape[0]):
        f = sc_ppf[s]
        if f == 0.0:
            continue
        c = sc_contact[s]
        add_to_sides(s, cb[c], ca[c], sc_pos[s, 0], sc_pos[s, 1], sc_pos[s, 2], f * cn[c, 0], f * cn[c, 1],
                     f * cn[c, 2], nodes_a, w_a, nodes_b, w_b, bpos, bforce, bmoment, gforce)


@njit(cache=True)
def _hull_weights(u, v, keep, w):
    """Weights w of the points (u, v) with keep[i] set (the others get 0) such that Σ w f(x_i) is the
    exact integral of any linear f over their convex hull: each triangle (C, h_t, h_t+1) around the
    hull's centroid C gives a third of its area to its two hull corners and a third to C, whose value
    is spread over the corners by λ (below). Returns the hull's area (0 when the points are collinear)."""
    k = u.shape[0]
    idx = np.empty(k, dtype=np.int64)
    m = 0
    for i in range(k):
        w[i] = 0.0
        if keep[i]:
            idx[m] = i
            m += 1
    if m < 3:
        return 0.0
    # Andrew's monotone chain on the kept points, sorted by (u, v)
    order = idx[:m].copy()
    for a in range(1, m):           # insertion sort (a handful of points)
        x = order[a]
        b = a - 1
        while b >= 0 and (u[order[b]] > u[x] or (u[order[b]] == u[x] and v[order[b]] > v[x])):
            order[b + 1] = order[b]
            b -= 1
        order[b + 1] = x
    hull = np.empty(2 * m, dtype=np.int64)
    h = 0
    for t in range(m):
        p = order[t]
        while h >= 2 and ((u[hull[h - 1]] - u[hull[h - 2]]) * (v[p] - v[hull[h - 2]])
                          - (v[hull[h - 1]] - v[hull[h - 2]]) * (u[p] - u[hull[h - 2]])) <= 0.0:
            h -= 1
        hull[h] = p
        h += 1
    lower = h + 1
    for t in range(m - 2, -1, -1):
        p = order[t]
        while h >= lower and ((u[hull[h - 1]] - u[hull[h - 2]]) * (v[p] - v[hull[h - 2]])
                              - (v[hull[h - 1]] - v[hull[h - 2]]) * (u[p] - u[hull[h - 2]])) <= 0.0:
            h -= 1
        hull[h] = p
        h += 1
    h -= 1                          # (the first point closes the chain)
    if h < 3:
        return 0.0
    # triangles (C, h_t, h_t+1) around the hull's area centroid C; p(C) of a linear p is Σ λ_j p(h_j) with
    # λ the least-norm weights that reproduce 1, u and v at C (1/h each when C is the corners' mean: a
    # parallelogram's four equal shares), so the weights are symmetric where the polygon is
    total = 0.0
    cu = 0.0
    cv = 0.0
    for t in range(1, h - 1):
        p0 = hull[0]
        p1 = hull[t]
        p2 = hull[t + 1]
        a = 0.5 * ((u[p1] - u[p0]) * (v[p2] - v[p0]) - (v[p1] - v[p0]) * (u[p2] - u[p0]))
        total += a
        cu += a * (u[p0] + u[p1] + u[p2]) / 3.0
        cv += a * (v[p0] + v[p1] + v[p2]) / 3.0
    if not total > 0.0:
        return 0.0
    cu /= total
    cv /= total
    # least-norm λ: λ = Mᵀ (M Mᵀ)⁻¹ (1, cu, cv), M the rows (1, u_j, v_j) over the hull corners
    g = np.zeros((3, 3))
    for t in range(h):
        q = hull[t]
        r = (1.0, u[q], v[q])
        for i in range(3):
            for j in range(3):
                g[i, j] += r[i] * r[j]
    mu = np.linalg.solve(g, np.array([1.0, cu, cv]))
    for t in range(h):
        q = hull[t]
        nxt = hull[(t + 1) % h]
        a = 0.5 * ((u[q] - cu) * (v[nxt] - cv) - (v[q] - cv) * (u[nxt] - cu))
        lam = mu[0] + mu[1] * u[q] + mu[2] * v[q]
        w[q] += a / 3.0 + total / 3.0 * lam
        w[nxt] += a / 3.0
    return total


@njit(cache=True)
def pressure_areas(sub_start, sub_count, cn, sc_pos, sc_area, out):
    """The area each sub-contact's pore pressure acts on [m²] (out (ns,)): the points of a contact
    span its contact polygon (their convex hull on the contact plane); ``_hull_weights`` gives the
    hull corners weights that integrate a linear function exactly and are symmetric where the polygon
    is (points at one place share their weight equally; points inside the hull get none), scaled so that the contact's total is Σ area. So the
    pressure resultant Σ p_i out_i is the exact integral of a pressure that varies linearly over the
    contact (a water table's), which the sub-contacts' own areas (lumps of the joint stiffness) are
    not. A contact with fewer than three distinct points, or whose points are collinear, keeps its
    sub-contacts' areas."""
    for c in range(sub_start.shape[0]):
        s0 = sub_start[c]
        k = sub_count[c]
        if k == 0:
            continue
        atot = 0.0
        for s in range(s0, s0 + k):
            atot += sc_area[s]
        if k < 3 or not atot > 0.0:
            for s in range(s0, s0 + k):
                out[s] = sc_area[s]
            continue
        n0 = cn[c, 0]
        n1 = cn[c, 1]
        n2 = cn[c, 2]
        # in-plane axes: t1 ⟂ n from the axis n is least along, t2 = n × t1
        if abs(n0) <= abs(n1) and abs(n0) <= abs(n2):
            e0, e1, e2 = 1.0, 0.0, 0.0
        elif abs(n1) <= abs(n2):
            e0, e1, e2 = 0.0, 1.0, 0.0
        else:
            e0, e1, e2 = 0.0, 0.0, 1.0
        d = e0 * n0 + e1 * n1 + e2 * n2
        t0 = e0 - d * n0
        t1 = e1 - d * n1
        t2 = e2 - d * n2
        tl = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        t0 /= tl
        t1 /= tl
        t2 /= tl
        b0 = n1 * t2 - n2 * t1
        b1 = n2 * t0 - n0 * t2
        b2 = n0 * t1 - n1 * t0
        u = np.empty(k)
        v = np.empty(k)
        ext = 0.0
        for j in range(k):
            s = s0 + j
            x0 = sc_pos[s, 0] - sc_pos[s0, 0]
            x1 = sc_pos[s, 1] - sc_pos[s0, 1]
            x2 = sc_pos[s, 2] - sc_pos[s0, 2]
            u[j] = x0 * t0 + x1 * t1 + x2 * t2
            v[j] = x0 * b0 + x1 * b1 + x2 * b2
            ext = max(ext, abs(u[j]), abs(v[j]))
        tol = 1e-9 * ext
        rep = np.empty(k, dtype=np.int64)         # the first point at the same place
        keep = np.zeros(k, dtype=np.bool_)
        for j in range(k):
            rep[j] = j
            for i in range(j):
                if rep[i] == i and abs(u[i] - u[j]) <= tol and abs(v[i] - v[j]) <= tol:
                    rep[j] = i
                    break
            keep[j] = rep[j] == j
        w = np.empty(k)
        hull = _hull_weights(u, v, keep, w)
        if not hull > 1e-12 * ext * ext:
            for s in range(s0, s0 + k):
                out[s] = sc_area[s]
            continue
        share = np.zeros(k)
        for j in range(k):
            share[rep[j]] += 1.0
        scale = atot / hull
        for j in range(k):
            r = rep[j]
            out[s0 + j] = w[r] / share[r] * scale
