"""Where a point sits in a quadratic element: the natural coordinates of a point in a 10-node
tetrahedron (``kernels.zones_ho``) or a 20-node brick (``kernels.feblock_shape``), found by Newton's
method on the isoparametric map x(ξ) = Σ N_a(ξ) x_a, and the shape-function values N_a there.

Structural nodes (cables, beams) and hybrid-bolt dowels in such elements follow the material point
Σ N_a x_a, move with Σ N_a v_a and hand a force F on the point to the element's nodes as N_a F (the
consistent nodal forces of a point load), as they do with the barycentric weights of a 4-node zone.

Node orders are the elements' own: tetrahedron corners 0-3, then the mid-edge nodes of edges
01 12 20 03 13 23, with N_i = L_i (2 L_i − 1) at corner i and 4 L_i L_j at the node of edge ij
(L_0 = 1 − ξ1 − ξ2 − ξ3, L_k = ξ_k); brick nodes and shape functions as ``feblock_shape.shape20``.
The twin is in ``tests/test_cable_hosts.py``.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .feblock_shape import shape20

#: corners of the edge of mid-edge node 4 + e of a 10-node tetrahedron
_EI = np.array([0, 1, 2, 0, 1, 2], dtype=np.int64)
_EJ = np.array([1, 2, 0, 3, 3, 3], dtype=np.int64)


@njit(cache=True)
def shape10(x1, x2, x3, n, dn):
    """Shape functions n (10,) and their derivatives dn (10, 3) with respect to ξ at (ξ1, ξ2, ξ3)."""
    L0 = 1.0 - x1 - x2 - x3
    L = (L0, x1, x2, x3)
    dl = np.zeros((10, 4))        # dN/dL_m
    for i in range(4):
        n[i] = L[i] * (2.0 * L[i] - 1.0)
        dl[i, i] = 4.0 * L[i] - 1.0
    for e in range(6):
        i, j = _EI[e], _EJ[e]
        n[4 + e] = 4.0 * L[i] * L[j]
        dl[4 + e, i] = 4.0 * L[j]
        dl[4 + e, j] = 4.0 * L[i]
    for a in range(10):
        for k in range(3):
            dn[a, k] = dl[a, k + 1] - dl[a, 0]


@njit(cache=True)
def _shape(nn, y, n, dn):
    if nn == 10:
        shape10(y[0], y[1], y[2], n, dn)
    else:
        shape20(y[0], y[1], y[2], n, dn)


@njit(cache=True)
def _inside(nn, y, tol):
    if nn == 10:
        return y[0] >= -tol and y[1] >= -tol and y[2] >= -tol and y[0] + y[1] + y[2] <= 1.0 + tol
    return abs(y[0]) <= 1.0 + tol and abs(y[1]) <= 1.0 + tol and abs(y[2]) <= 1.0 + tol


@njit(cache=True)
def _solve3(a, b):
    """b ← a⁻¹ b for a 3 x 3 ``a`` (Cramer's rule); returns det a (0: b unchanged)."""
    c00 = a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]
    c01 = a[1, 2] * a[2, 0] - a[1, 0] * a[2, 2]
    c02 = a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]
    det = a[0, 0] * c00 + a[0, 1] * c01 + a[0, 2] * c02
    if det == 0.0 or not math.isfinite(det):
        return 0.0
    x0 = (b[0] * c00 + b[1] * (a[0, 2] * a[2, 1] - a[0, 1] * a[2, 2]) + b[2] * (a[0, 1] * a[1, 2] - a[0, 2] * a[1, 1])) / det
    x1 = (b[0] * c01 + b[1] * (a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]) + b[2] * (a[0, 2] * a[1, 0] - a[0, 0] * a[1, 2])) / det
    x2 = (b[0] * c02 + b[1] * (a[0, 1] * a[2, 0] - a[0, 0] * a[2, 1]) + b[2] * (a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0])) / det
    b[0], b[1], b[2] = x0, x1, x2
    return det


@njit(cache=True)
def natural_coords(xe, nn, p, y):
    """Newton's method for x(ξ) = p in the element of nodes ``xe (nn, 3)`` (nn 10 or 20), from the
    element's centre; ``y (3,)`` gets ξ. Returns the last correction's size (large or NaN: no
    convergence, e.g. a point far outside a distorted element)."""
    n = np.zeros(nn)
    dn = np.zeros((nn, 3))
    if nn == 10:
        y[0], y[1], y[2] = 0.25, 0.25, 0.25
    else:
        y[0], y[1], y[2] = 0.0, 0.0, 0.0
    jac = np.zeros((3, 3))
    r = np.zeros(3)
    step = np.inf
    for _ in range(30):
        _shape(nn, y, n, dn)
        for i in range(3):
            r[i] = p[i]
            for k in range(3):
                jac[i, k] = 0.0
        for a in range(nn):
            for i in range(3):
                r[i] -= n[a] * xe[a, i]
                for k in range(3):
                    jac[i, k] += xe[a, i] * dn[a, k]
        det = _solve3(jac, r)
        if det == 0.0:
            return np.inf
        step = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
        for k in range(3):
            y[k] += r[k]
        if not step < 1e3:
            return step
        if step < 1e-13:
            break
    return step


@njit(cache=True)
def locate(pos, conn, rows, nn, p, tol, w):
    """The first element of ``rows`` (rows of ``conn (m, ≥nn)``, node rows into ``pos``) that holds
    point ``p``: natural coordinates inside the element by ``tol`` at most. Its shape functions at
    the point (ξ clamped into the element) go to ``w (nn,)``. Returns its index in ``rows``, -1 none."""
    xe = np.zeros((nn, 3))
    y = np.zeros(3)
    dn = np.zeros((nn, 3))
    for k in range(rows.shape[0]):
        e = rows[k]
        for a in range(nn):
            for i in range(3):
                xe[a, i] = pos[conn[e, a], i]
        step = natural_coords(xe, nn, p, y)
        if not step < 1e-8 or not _inside(nn, y, tol):
            continue
        if nn == 10:
            for i in range(3):
                y[i] = max(y[i], 0.0)
            s = y[0] + y[1] + y[2]
            if s > 1.0:
                for i in range(3):
                    y[i] /= s
        else:
            for i in range(3):
                y[i] = min(max(y[i], -1.0), 1.0)
        _shape(nn, y, w, dn)
        return k
    return -1
