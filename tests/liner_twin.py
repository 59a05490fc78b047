"""A slow twin of the liner element (``dec3d.kernels.dkt``), built another way from the formulas and
sharing no code or constants with it:

* membrane: linear shape functions from the inverse of [1 x y] at the corners;
* bending: the discrete Kirchhoff constraints applied directly — corner rotations of the normal
  βx = −w,x, βy = −w,y from θx = w,y, θy = −w,x; at each mid-side the tangential rotation from the
  cubic w along the side, β_s = −(3/2 (w_j − w_i)/l − ¼ (w,s_i + w,s_j)), and the normal one the mean
  of the corners' — fitted by a full quadratic polynomial in (x, y) through the six points, its
  curvatures integrated at the three mid-side points (weights A/3);
* drilling: the penalty 10⁻³ E t³ Σ (θz − ω)², ω = ½ (v,x − u,y) the in-plane rotation (written out).
"""
from __future__ import annotations

import numpy as np


def dmat(e, nu):
    return e / (1.0 - nu ** 2) * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, (1.0 - nu) / 2.0]])


def membrane_k(xy, e, nu, t):
    m = np.column_stack([np.ones(3), xy])
    g = np.linalg.inv(m)[1:, :]                  # rows: d/dx, d/dy of the three linear functions
    area = 0.5 * abs(np.linalg.det(m))
    b = np.zeros((3, 6))
    for i in range(3):
        b[0, 2 * i] = g[0, i]
        b[1, 2 * i + 1] = g[1, i]
        b[2, 2 * i] = g[1, i]
        b[2, 2 * i + 1] = g[0, i]
    return t * area * b.T @ dmat(e, nu) @ b


def _poly(x, y):
    return np.array([1.0, x, y, x * x, x * y, y * y])


def _poly_dx(x, y):
    return np.array([0.0, 1.0, 0.0, 2 * x, y, 0.0])


def _poly_dy(x, y):
    return np.array([0.0, 0.0, 1.0, 0.0, x, 2 * y])


def _beta_points(xy, u):
    """Six points (corners, mid-sides 12, 23, 31) and β there for bending DOFs u (w, θx, θy per node)."""
    w = u[0::3]
    th_x, th_y = u[1::3], u[2::3]
    grad = np.column_stack([-th_y, th_x])        # (w,x, w,y) at the corners
    beta = -grad
    pts, vals = list(xy), list(beta)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        d = xy[j] - xy[i]
        ln = np.linalg.norm(d)
        s = d / ln
        n = np.array([s[1], -s[0]])
        ws_mid = 1.5 * (w[j] - w[i]) / ln - 0.25 * (grad[i] @ s + grad[j] @ s)
        bn = 0.5 * (beta[i] @ n + beta[j] @ n)
        pts.append(0.5 * (xy[i] + xy[j]))
        vals.append(-ws_mid * s + bn * n)
    return np.array(pts), np.array(vals)


def bending_b(xy, x, y):
    """3 × 9 curvature matrix at (x, y), column by column from unit DOF vectors."""
    b = np.zeros((3, 9))
    for c in range(9):
        u = np.zeros(9)
        u[c] = 1.0
        pts, vals = _beta_points(xy, u)
        v = np.array([_poly(*p) for p in pts])
        cx = np.linalg.solve(v, vals[:, 0])
        cy = np.linalg.solve(v, vals[:, 1])
        b[0, c] = _poly_dx(x, y) @ cx
        b[1, c] = _poly_dy(x, y) @ cy
        b[2, c] = _poly_dy(x, y) @ cx + _poly_dx(x, y) @ cy
    return b


def bending_k(xy, e, nu, t):
    e1, e2 = xy[1] - xy[0], xy[2] - xy[0]
    area = 0.5 * abs(e1[0] * e2[1] - e1[1] * e2[0])
    db = dmat(e, nu) * t ** 3 / 12.0
    k = np.zeros((9, 9))
    for i, j in ((0, 1), (1, 2), (2, 0)):
        x, y = 0.5 * (xy[i] + xy[j])
        b = bending_b(xy, x, y)
        k += area / 3.0 * b.T @ db @ b
    return k


def local_k(xy, e, nu, t):
    """18 × 18, DOF order u v w θx θy θz per node."""
    k = np.zeros((18, 18))
    km = membrane_k(xy, e, nu, t)
    kb = bending_k(xy, e, nu, t)
    mi = [6 * n + c for n in range(3) for c in (0, 1)]
    bi = [6 * n + c for n in range(3) for c in (2, 3, 4)]
    k[np.ix_(mi, mi)] += km
    k[np.ix_(bi, bi)] += kb
    # drilling: 1e-3 E t³ Σ (θz_i − ω)², ω = ½ (v,x − u,y) from the linear functions' gradients
    g = np.linalg.inv(np.column_stack([np.ones(3), xy]))[1:, :]
    omega = np.zeros(18)
    for n in range(3):
        omega[6 * n] = -0.5 * g[1, n]
        omega[6 * n + 1] = 0.5 * g[0, n]
    for n in range(3):
        r = -omega.copy()
        r[6 * n + 5] += 1.0
        k += 1e-3 * e * t ** 3 * np.outer(r, r)
    return k


def frame(p):
    """Rows x (1 → 2), y, z (normal) and local 2-D corners of triangle p (3, 3)."""
    ex = (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])
    ez = np.cross(p[1] - p[0], p[2] - p[0])
    ez /= np.linalg.norm(ez)
    ey = np.cross(ez, ex)
    r = np.array([ex, ey, ez])
    xy = np.array([[r[0] @ (q - p[0]), r[1] @ (q - p[0])] for q in p])
    return r, xy


def global_k(p, e, nu, t):
    r, xy = frame(np.asarray(p, float))
    tm = np.zeros((18, 18))
    for g in range(6):
        tm[3 * g:3 * g + 3, 3 * g:3 * g + 3] = r
    return tm.T @ local_k(xy, e, nu, t) @ tm
