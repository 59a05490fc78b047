"""The stiffness of a flat 3-node shell element: DKT plate bending (Batoz, Bathe & Ho 1980, the
discrete Kirchhoff triangle) + CST membrane + a weak drilling spring, 6 degrees of freedom per node
(``physics.liners`` uses it for the liners; the tests hold a twin built another way).

Element axes (rows of ``axes``): x from node 1 to node 2, z the normal (x × (x₃ − x₁)), y = z × x.
Local node coordinates (x₁, y₁) = (0, 0), (x₂, 0), (x₃, y₃). Local DOF order per node: u, v, w
(translations along x, y, z), θx, θy, θz (rotations about x, y, z); 18 in all.

Membrane (CST): ε = B_m u, B_m = 1/2A [y₂₃ 0 y₃₁ 0 y₁₂ 0; 0 x₃₂ 0 x₁₃ 0 x₂₁; x₃₂ y₂₃ x₁₃ y₃₁ x₂₁ y₁₂],
K_m = t A B_mᵀ D B_m, D = E / (1 − ν²) [1 ν 0; ν 1 0; 0 0 (1 − ν)/2].

Bending (DKT): the rotations of the normal βx = −w,x = θy and βy = −w,y = −θx are quadratic over
the element, βx = H_xᵀ U, βy = H_yᵀ U (U = w, θx, θy at the three nodes), with the Kirchhoff
constraints at the corners and the mid-sides (Batoz et al. 1980, their H_x, H_y with the side
constants a_k = −x_ij/l², b_k = ¾ x_ij y_ij/l², c_k = (¼x_ij² − ½y_ij²)/l², d_k = −y_ij/l²,
e_k = (¼y_ij² − ½x_ij²)/l², k = 4, 5, 6 for sides 23, 31, 12); curvatures κ = (βx,x, βy,y,
βx,y + βy,x), K_b = ∫ Bᵀ D_b B dA with D_b = t³/12 D, integrated at the three interior Gauss points
(1/6, 1/6), (2/3, 1/6), (1/6, 2/3) (exact: B is linear).

Drilling: the rotations about z have no stiffness in the DKT and CST; a weak penalty
k_d Σᵢ (θzᵢ − ω)² ties each node's θz to the membrane's in-plane rotation ω = ½ (v,x − u,y) (constant
over the CST): zero for a rigid-body rotation, so the element keeps exactly six zero-energy modes, with
k_d = ``DRILL`` × E t³, 10⁻³ of the bending stiffness scale (it does not stiffen the element noticeably).
"""
from __future__ import annotations

import numpy as np
from numba import njit

#: drilling spring over E t³
DRILL = 1e-3


@njit(cache=True)
def _hxy(xi, eta, p4, p5, p6, dxi, deta):
    """H_x, H_y (9 each) derivatives by ξ (``dxi``: rows 0 H_x, 1 H_y) and η (``deta``) at (ξ, η);
    ``p4..p6``: (a, b, c, d, e) of sides 23, 31, 12."""
    lam = 1.0 - xi - eta
    # derivatives of the quadratic shape functions N1..N6 (6: side 12, 4: side 23, 5: side 31)
    nx = (1.0 - 4.0 * lam, 4.0 * xi - 1.0, 0.0, 4.0 * eta, -4.0 * eta, 4.0 * lam - 4.0 * xi)
    ny = (1.0 - 4.0 * lam, 0.0, 4.0 * eta - 1.0, 4.0 * xi, 4.0 * lam - 4.0 * eta, -4.0 * xi)
    for which in range(2):
        n = nx if which == 0 else ny
        out = dxi if which == 0 else deta
        a4, b4, c4, d4, e4 = p4[0], p4[1], p4[2], p4[3], p4[4]
        a5, b5, c5, d5, e5 = p5[0], p5[1], p5[2], p5[3], p5[4]
        a6, b6, c6, d6, e6 = p6[0], p6[1], p6[2], p6[3], p6[4]
        n1, n2, n3, n4, n5, n6 = n[0], n[1], n[2], n[3], n[4], n[5]
        out[0, 0] = 1.5 * (a6 * n6 - a5 * n5)
        out[0, 1] = b5 * n5 + b6 * n6
        out[0, 2] = n1 - c5 * n5 - c6 * n6
        out[0, 3] = 1.5 * (a4 * n4 - a6 * n6)
        out[0, 4] = b6 * n6 + b4 * n4
        out[0, 5] = n2 - c6 * n6 - c4 * n4
        out[0, 6] = 1.5 * (a5 * n5 - a4 * n4)
        out[0, 7] = b4 * n4 + b5 * n5
        out[0, 8] = n3 - c4 * n4 - c5 * n5
        out[1, 0] = 1.5 * (d6 * n6 - d5 * n5)
        out[1, 1] = -n1 + e5 * n5 + e6 * n6
        out[1, 2] = -out[0, 1]
        out[1, 3] = 1.5 * (d4 * n4 - d6 * n6)
        out[1, 4] = -n2 + e6 * n6 + e4 * n4
        out[1, 5] = -out[0, 4]
        out[1, 6] = 1.5 * (d5 * n5 - d4 * n4)
        out[1, 7] = -n3 + e4 * n4 + e5 * n5
        out[1, 8] = -out[0, 7]


@njit(cache=True)
def _side(xi, yi, xj, yj, p):
    x = xi - xj
    y = yi - yj
    l2 = x * x + y * y
    p[0] = -x / l2
    p[1] = 0.75 * x * y / l2
    p[2] = (0.25 * x * x - 0.5 * y * y) / l2
    p[3] = -y / l2
    p[4] = (0.25 * y * y - 0.5 * x * x) / l2


@njit(cache=True)
def dkt_curvature_b(x2, x3, y3, xi, eta, b):
    """The 3 × 9 curvature matrix B (κ = B U, U = w, θx, θy per node) of the DKT element with local
    corners (0, 0), (x2, 0), (x3, y3) at (ξ, η); returns 2A."""
    x1 = 0.0
    y1 = 0.0
    y2 = 0.0
    p4 = np.empty(5)
    p5 = np.empty(5)
    p6 = np.empty(5)
    _side(x2, y2, x3, y3, p4)
    _side(x3, y3, x1, y1, p5)
    _side(x1, y1, x2, y2, p6)
    dxi = np.empty((2, 9))
    deta = np.empty((2, 9))
    _hxy(xi, eta, p4, p5, p6, dxi, deta)
    x31, x12 = x3 - x1, x1 - x2
    y31, y12 = y3 - y1, y1 - y2
    a2 = x31 * y12 - x12 * y31
    for k in range(9):
        b[0, k] = (y31 * dxi[0, k] + y12 * deta[0, k]) / a2
        b[1, k] = (-x31 * dxi[1, k] - x12 * deta[1, k]) / a2
        b[2, k] = (-x31 * dxi[0, k] - x12 * deta[0, k] + y31 * dxi[1, k] + y12 * deta[1, k]) / a2
    return a2


@njit(cache=True)
def shell_local_stiffness(x2, x3, y3, e, nu, t, k):
    """The 18 × 18 stiffness ``k`` (zeroed and filled) in the element's axes (DOF order in the module
    docstring) of the triangle (0, 0), (x2, 0), (x3, y3): CST membrane + DKT bending + drilling."""
    for p in range(18):
        for q in range(18):
            k[p, q] = 0.0
    c = e / (1.0 - nu * nu)
    d = np.array([[c, c * nu, 0.0], [c * nu, c, 0.0], [0.0, 0.0, c * 0.5 * (1.0 - nu)]])
    a2 = x2 * y3
    area = 0.5 * a2
    # membrane
    bm = np.zeros((3, 6))
    y23, y31, y12 = -y3, y3, 0.0
    x32, x13, x21 = x3 - x2, -x3, x2
    bm[0, 0], bm[0, 2], bm[0, 4] = y23 / a2, y31 / a2, y12 / a2
    bm[1, 1], bm[1, 3], bm[1, 5] = x32 / a2, x13 / a2, x21 / a2
    bm[2, 0], bm[2, 1], bm[2, 2], bm[2, 3], bm[2, 4], bm[2, 5] = (x32 / a2, y23 / a2, x13 / a2, y31 / a2,
                                                                   x21 / a2, y12 / a2)
    mi = (0, 1, 6, 7, 12, 13)
    for p in range(6):
        for q in range(6):
            acc = 0.0
            for r in range(3):
                for s in range(3):
                    acc += bm[r, p] * d[r, s] * bm[s, q]
            k[mi[p], mi[q]] += t * area * acc
    # bending: three interior Gauss points, weight 1/6 each in (ξ, η)
    db = t * t * t / 12.0
    bb = np.empty((3, 9))
    bi = (2, 3, 4, 8, 9, 10, 14, 15, 16)
    gp = ((1.0 / 6.0, 1.0 / 6.0), (2.0 / 3.0, 1.0 / 6.0), (1.0 / 6.0, 2.0 / 3.0))
    for g in range(3):
        j = dkt_curvature_b(x2, x3, y3, gp[g][0], gp[g][1], bb)
        wgt = j / 6.0 * db
        for p in range(9):
            for q in range(9):
                acc = 0.0
                for r in range(3):
                    for s in range(3):
                        acc += bb[r, p] * d[r, s] * bb[s, q]
                k[bi[p], bi[q]] += wgt * acc
    # drilling: k_d Σᵢ (θzᵢ − ω)², ω = ½ (v,x − u,y) the CST's in-plane rotation
    kd = DRILL * e * t * t * t
    om = np.zeros(18)
    dnx = (y23 / a2, y31 / a2, y12 / a2)
    dny = (x32 / a2, x13 / a2, x21 / a2)
    for j in range(3):
        om[6 * j] = -0.5 * dny[j]
        om[6 * j + 1] = 0.5 * dnx[j]
    r = np.empty(18)
    for i in range(3):
        for p in range(18):
            r[p] = -om[p]
        r[6 * i + 5] += 1.0
        for p in range(18):
            if r[p] != 0.0:
                for q in range(18):
                    k[p, q] += kd * r[p] * r[q]


def element_frame(p1, p2, p3) -> tuple[np.ndarray, float, float, float]:
    """(axes (3, 3): rows x, y, z; x2, x3, y3 local coordinates) of the triangle p1, p2, p3."""
    p1, p2, p3 = (np.asarray(p, np.float64) for p in (p1, p2, p3))
    ex = p2 - p1
    ex = ex / np.linalg.norm(ex)
    ez = np.cross(ex, p3 - p1)
    ez = ez / np.linalg.norm(ez)
    ey = np.cross(ez, ex)
    ax = np.array([ex, ey, ez])
    return ax, float(np.dot(p2 - p1, ex)), float(np.dot(p3 - p1, ex)), float(np.dot(p3 - p1, ey))


def global_stiffness(axes, x2, x3, y3, e, nu, t) -> np.ndarray:
    """The 18 × 18 stiffness in global axes: Tᵀ K T (T: ``axes`` on each 3-vector of the 6 groups)."""
    k = np.empty((18, 18))
    shell_local_stiffness(x2, x3, y3, e, nu, t, k)
    tm = np.kron(np.eye(6), axes)
    return tm.T @ k @ tm
