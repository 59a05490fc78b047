"""20-node serendipity bricks (FE blocks): shape functions, Gauss-point strains and stresses,
nodal forces by integration of the Gauss-point stresses, lumped masses, nodal stiffness,
consistent gravity and face loads, slave (mid-face) nodes.

Source: the FE-block text (shared/seeds/003_*, "Structural Finite Elements") with the
corrections of shared/seeds/ERRATA.md (section 003). The text follows Hughes (1987).

Node order (``feblocks.nodes``): Table 1 of the text as corrected, which is the CalculiX /
Abaqus C3D20 and VTK type 25 (quadratic hexahedron) order. Master coordinates y = (y1 y2 y3):

    corners   1 (-1 -1 -1)  2 ( 1 -1 -1)  3 ( 1  1 -1)  4 (-1  1 -1)
              5 (-1 -1  1)  6 ( 1 -1  1)  7 ( 1  1  1)  8 (-1  1  1)
    mid-edge  9 ( 0 -1 -1) 10 ( 1  0 -1) 11 ( 0  1 -1) 12 (-1  0 -1)
             13 ( 0 -1  1) 14 ( 1  0  1) 15 ( 0  1  1) 16 (-1  0  1)   (errata: 13-16)
             17 (-1 -1  0) 18 ( 1 -1  0) 19 ( 1  1  0) 20 (-1  1  0)

(0-based in the arrays: node I is index I - 1.) Slave nodes (Table 2): 21-26 at the face
centres y3 = -1, y3 = 1, y2 = -1, y2 = 1, y1 = -1, y1 = 1, and 27 at the element centre; their
motion is interpolated from the 20 masters by the shape functions (text, "Element
Implementation") and forces on them go to the masters by Eq. (9), F_I = N_I P.

Shape functions ("Shape Functions and Derivatives"), with y_Ik the node's master coordinates:
corners N = 1/8 (1 + y_I1 y1)(1 + y_I2 y2)(1 + y_I3 y3)(y_I1 y1 + y_I2 y2 + y_I3 y3 - 2), and
dN/dy1 = 1/8 y_I1 (1 + y_I2 y2)(1 + y_I3 y3)(2 y_I1 y1 + y_I2 y2 + y_I3 y3 - 1) (errata: +2,
likewise for y2, y3); mid-edge nodes with y_Ik = 0 on axis k: N = 1/4 (1 - yk^2)(1 + ...)(1 + ...)
(the text's three families 9/11/13/15, 10/12/14/16, 17-20; errata: the last derivative of
17-20 is d/dy3).

Quadrature (text, "Stresses and Nodal Forces", Eq. 7): "2 x 2 x 2 or 3 x 3 x 3 Gauss points may
be used", 2 x 2 x 2 (reduced) the default. ``nq`` = 2 or 3 selects the rule; Gauss points are
numbered with y1 fastest, then y2, then y3 (points -1/sqrt 3, 1/sqrt 3, weights 1; or
-sqrt(3/5), 0, sqrt(3/5), weights 5/9, 8/9, 5/9). ``gstress[e, g]`` (e, 27, 6) holds the stress
of point g (the first 8 used with nq = 2), xx yy zz xy xz yz, tension positive (the store order
of ``zones``; the text's vector is 11 22 33 23 31 12), and ``stress[e]`` the volume-weighted
mean sum_g w_g det J_g sigma_g / V.

Sign convention as ``kernels/zones_ho``: ``force[r]`` accumulates the force the element exerts
on node r, -F^S of the text's Eq. (7), -sum_G B_I^T sigma W_G V_G.

Elements must be positively oriented (det J > 0 at every Gauss point). Every kernel that
integrates skips an element whose det J is not positive at one of its points (no NaN reaches
the stores) and returns the first such element row (-1 if none) for the host to report.
"""
import numpy as np
from numba import njit, prange

from .feblock_hg import hg_jacobians, hg_step
from .gather import node_lists, node_sums, scatter
from .zones_ho import add_body_force, add_stiffness_bound

#: master coordinates of the 20 nodes (corrected Table 1), 0-based rows
YNODE = np.array([
    [-1.0, -1.0, -1.0], [1.0, -1.0, -1.0], [1.0, 1.0, -1.0], [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0], [1.0, -1.0, 1.0], [1.0, 1.0, 1.0], [-1.0, 1.0, 1.0],
    [0.0, -1.0, -1.0], [1.0, 0.0, -1.0], [0.0, 1.0, -1.0], [-1.0, 0.0, -1.0],
    [0.0, -1.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [-1.0, 0.0, 1.0],
    [-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]])

#: master coordinates of the slave nodes 21-27 (Table 2)
YSLAVE = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [0.0, 1.0, 0.0],
                   [-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])

#: the six faces (Table 3, 0-based): 4 corners counter-clockwise seen from outside, then the
#: mid-edge nodes of edges c0c1 c1c2 c2c3 c3c0; the face's slave node is 20 + face
FACES = np.array([[1, 0, 3, 2, 8, 11, 10, 9], [4, 5, 6, 7, 12, 13, 14, 15],
                  [0, 1, 5, 4, 8, 17, 12, 16], [2, 3, 7, 6, 10, 19, 14, 18],
                  [3, 0, 4, 7, 11, 16, 15, 19], [1, 2, 6, 5, 9, 18, 13, 17]], dtype=np.int64)

NGMAX = 27

#: elements per work unit of the parallel element pass
CHUNK = 256


@njit(cache=True)
def shape20(y1, y2, y3, n, dn):
    """Shape functions n (20,) and their master derivatives dn (20, 3) at (y1, y2, y3)."""
    for a in range(20):
        a1 = YNODE[a, 0]
        a2 = YNODE[a, 1]
        a3 = YNODE[a, 2]
        if a < 8:
            p1 = 1.0 + a1 * y1
            p2 = 1.0 + a2 * y2
            p3 = 1.0 + a3 * y3
            s = a1 * y1 + a2 * y2 + a3 * y3
            n[a] = 0.125 * p1 * p2 * p3 * (s - 2.0)
            dn[a, 0] = 0.125 * a1 * p2 * p3 * (2.0 * a1 * y1 + a2 * y2 + a3 * y3 - 1.0)
            dn[a, 1] = 0.125 * a2 * p3 * p1 * (2.0 * a2 * y2 + a1 * y1 + a3 * y3 - 1.0)
            dn[a, 2] = 0.125 * a3 * p1 * p2 * (2.0 * a3 * y3 + a1 * y1 + a2 * y2 - 1.0)
        elif a1 == 0.0:           # 9, 11, 13, 15
            q = 1.0 - y1 * y1
            p2 = 1.0 + a2 * y2
            p3 = 1.0 + a3 * y3
            n[a] = 0.25 * q * p2 * p3
            dn[a, 0] = -0.5 * y1 * p2 * p3
            dn[a, 1] = 0.25 * a2 * q * p3
            dn[a, 2] = 0.25 * a3 * q * p2
        elif a2 == 0.0:           # 10, 12, 14, 16
            q = 1.0 - y2 * y2
            p1 = 1.0 + a1 * y1
            p3 = 1.0 + a3 * y3
            n[a] = 0.25 * q * p3 * p1
            dn[a, 0] = 0.25 * a1 * q * p3
            dn[a, 1] = -0.5 * y2 * p3 * p1
            dn[a, 2] = 0.25 * a3 * q * p1
        else:                     # 17-20
            q = 1.0 - y3 * y3
            p1 = 1.0 + a1 * y1
            p2 = 1.0 + a2 * y2
            n[a] = 0.25 * q * p1 * p2
            dn[a, 0] = 0.25 * a1 * q * p2
            dn[a, 1] = 0.25 * a2 * q * p1
            dn[a, 2] = -0.5 * y3 * p1 * p2


@njit(cache=True)
def gauss_rule(nq):
    """Points (nq^3, 3) and weights (nq^3,) of the nq x nq x nq Gauss rule (nq = 2 or 3),
    y1 fastest. Any other nq is taken as 2."""
    if nq == 3:
        r = np.sqrt(0.6)
        x = np.array([-r, 0.0, r])
        w = np.array([5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])
        m = 3
    else:
        r = 1.0 / np.sqrt(3.0)
        x = np.array([-r, r])
        w = np.array([1.0, 1.0])
        m = 2
    pts = np.empty((m * m * m, 3))
    wts = np.empty(m * m * m)
    g = 0
    for k in range(m):
        for j in range(m):
            for i in range(m):
                pts[g, 0] = x[i]
                pts[g, 1] = x[j]
                pts[g, 2] = x[k]
                wts[g] = w[i] * w[j] * w[k]
                g += 1
    return pts, wts


@njit(cache=True)
def ref_tables(nq):
    """Shape functions (ng, 20), master derivatives (ng, 20, 3) and weights (ng,) at the Gauss
    points of the nq-rule."""
    pts, wts = gauss_rule(nq)
    ng = pts.shape[0]
    shp = np.empty((ng, 20))
    dref = np.empty((ng, 20, 3))
    for g in range(ng):
        shape20(pts[g, 0], pts[g, 1], pts[g, 2], shp[g], dref[g])
    return shp, dref, wts


@njit(cache=True)
def hg_tables():
    """Tables of the hourglass control (``feblock_hg``): master derivatives (6, 20, 3) at the
    face centres (YSLAVE rows 0-5) and the trilinear weights (6, 8) of the 2 x 2 x 2 Gauss points
    at them, w_pg = prod_i (1 + 3 y_gi p_i) / 2."""
    pts, wts = gauss_rule(np.int64(2))
    n = np.empty(20)
    dface = np.empty((6, 20, 3))
    wpg = np.empty((6, 8))
    for p in range(6):
        shape20(YSLAVE[p, 0], YSLAVE[p, 1], YSLAVE[p, 2], n, dface[p])
        for g in range(8):
            w = 1.0
            for i in range(3):
                w *= 0.5 * (1.0 + 3.0 * pts[g, i] * YSLAVE[p, i])
            wpg[p, g] = w
    return dface, wpg


@njit(cache=True, inline='always')
def _jacobian(x, dxi):
    """det J and the entries i_kj = dy_k/dx_j of J^-1 at one point, from the master derivatives
    dxi (20, 3) and the element's node coordinates x (20, 3) (text: J_km = dN_I/dy_m x_Ik,
    Y = J^-1). Returns (det, i00, i01, i02, i10, i11, i12, i20, i21, i22), the inverse all
    zeros when det J is not positive. Scalars only (every Gauss point of every element)."""
    j00 = 0.0; j01 = 0.0; j02 = 0.0
    j10 = 0.0; j11 = 0.0; j12 = 0.0
    j20 = 0.0; j21 = 0.0; j22 = 0.0
    for a in range(20):
        x0 = x[a, 0]; x1 = x[a, 1]; x2 = x[a, 2]
        d0 = dxi[a, 0]; d1 = dxi[a, 1]; d2 = dxi[a, 2]
        j00 += x0 * d0; j01 += x0 * d1; j02 += x0 * d2
        j10 += x1 * d0; j11 += x1 * d1; j12 += x1 * d2
        j20 += x2 * d0; j21 += x2 * d1; j22 += x2 * d2
    c00 = j11 * j22 - j12 * j21
    c01 = j12 * j20 - j10 * j22
    c02 = j10 * j21 - j11 * j20
    det = j00 * c00 + j01 * c01 + j02 * c02
    if not det > 0.0:
        return det, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    r = 1.0 / det
    return (det, c00 * r, (j02 * j21 - j01 * j22) * r, (j01 * j12 - j02 * j11) * r,
            c01 * r, (j00 * j22 - j02 * j20) * r, (j02 * j10 - j00 * j12) * r,
            c02 * r, (j01 * j20 - j00 * j21) * r, (j00 * j11 - j01 * j10) * r)


@njit(cache=True)
def _grad_n(x, dxi, dn):
    """Cartesian derivatives dn (20, 3) = dN_a/dx_j at one point from the master derivatives
    dxi (20, 3) and the element's node coordinates x (20, 3) (text, Eq. 5: N_I,m = dN_I/dy_j
    Y_jm). Returns det J; dn is left as it was when det J is not positive."""
    det, i00, i01, i02, i10, i11, i12, i20, i21, i22 = _jacobian(x, dxi)
    if not det > 0.0:
        return det
    for a in range(20):
        d0 = dxi[a, 0]; d1 = dxi[a, 1]; d2 = dxi[a, 2]
        dn[a, 0] = d0 * i00 + d1 * i10 + d2 * i20
        dn[a, 1] = d0 * i01 + d1 * i11 + d2 * i21
        dn[a, 2] = d0 * i02 + d1 * i12 + d2 * i22
    return det


@njit(cache=True)
def _gather(arr, nodes, e, nd, out):
    """nd[a] = nodes[e, a] and out[a] = arr[nd[a]] (20 rows) for one element."""
    for a in range(20):
        r = nodes[e, a]
        nd[a] = r
        out[a, 0] = arr[r, 0]
        out[a, 1] = arr[r, 1]
        out[a, 2] = arr[r, 2]


@njit(cache=True)
def _elem_grads(x, dref, wts, dng, wd):
    """Cartesian derivatives dng (ng, 20, 3) and w_g det J_g (ng,) at every Gauss point of one
    element with node coordinates x (20, 3). False when det J is not positive at some point."""
    for g in range(wts.shape[0]):
        det = _grad_n(x, dref[g], dng[g])
        if not det > 0.0:
            return False
        wd[g] = wts[g] * det
    return True


@njit(cache=True)
def _elem_force(dng, wd, sg, fe):
    """fe[a] = -sum_g wd[g] sigma_g . grad N_a(g) (Eq. 7 with the engine's sign), sg (>= ng, 6)."""
    for a in range(20):
        fe[a, 0] = 0.0
        fe[a, 1] = 0.0
        fe[a, 2] = 0.0
    for g in range(wd.shape[0]):
        s = sg[g]
        w = wd[g]
        dn = dng[g]
        for a in range(20):
            fe[a, 0] -= w * (s[0] * dn[a, 0] + s[3] * dn[a, 1] + s[4] * dn[a, 2])
            fe[a, 1] -= w * (s[3] * dn[a, 0] + s[1] * dn[a, 1] + s[5] * dn[a, 2])
            fe[a, 2] -= w * (s[4] * dn[a, 0] + s[5] * dn[a, 1] + s[2] * dn[a, 2])


@njit(cache=True)
def _jac_inv(x, dxi, jinv):
    """Inverse Jacobian jinv (3, 3) (jinv[k, j] = dy_k/dx_j) at one point; returns det J (jinv
    untouched when not positive)."""
    det, i00, i01, i02, i10, i11, i12, i20, i21, i22 = _jacobian(x, dxi)
    if not det > 0.0:
        return det
    jinv[0, 0] = i00; jinv[0, 1] = i01; jinv[0, 2] = i02
    jinv[1, 0] = i10; jinv[1, 1] = i11; jinv[1, 2] = i12
    jinv[2, 0] = i20; jinv[2, 1] = i21; jinv[2, 2] = i22
    return det


@njit(cache=True, inline='always')
def _gauss_force(sxx, syy, szz, sxy, sxz, syz, ji, d, fe):
    """fe[a] -= (S J^-T) dN_a/dy for the weighted stress S (w det J sigma) of one point."""
    p00 = sxx * ji[0, 0] + sxy * ji[0, 1] + sxz * ji[0, 2]
    p01 = sxx * ji[1, 0] + sxy * ji[1, 1] + sxz * ji[1, 2]
    p02 = sxx * ji[2, 0] + sxy * ji[2, 1] + sxz * ji[2, 2]
    p10 = sxy * ji[0, 0] + syy * ji[0, 1] + syz * ji[0, 2]
    p11 = sxy * ji[1, 0] + syy * ji[1, 1] + syz * ji[1, 2]
    p12 = sxy * ji[2, 0] + syy * ji[2, 1] + syz * ji[2, 2]
    p20 = sxz * ji[0, 0] + syz * ji[0, 1] + szz * ji[0, 2]
    p21 = sxz * ji[1, 0] + syz * ji[1, 1] + szz * ji[1, 2]
    p22 = sxz * ji[2, 0] + syz * ji[2, 1] + szz * ji[2, 2]
    for a in range(20):
        n0 = d[a, 0]; n1 = d[a, 1]; n2 = d[a, 2]
        fe[a, 0] -= p00 * n0 + p01 * n1 + p02 * n2
        fe[a, 1] -= p10 * n0 + p11 * n1 + p12 * n2
        fe[a, 2] -= p20 * n0 + p21 * n1 + p22 * n2


@njit(cache=True)
def _elem_step(xe, ve, dref, wts, lam, g2, dt, sg, se, fe, jinv, wd, hg, dface, wpg, jf, eg, tg):
    """Stress update and nodal forces of one element (node coordinates xe, velocities ve
    (20, 3)): Gauss-point stresses sg (>= ng, 6) and mean se (6,) updated, fe (20, 3) filled
    with the element's force on each node. False, changing nothing, when det J is not positive
    at a Gauss point (or, with the control, at a face centre). Works in master coordinates:
    grad v = (sum_a v_a (x) dN_a/dy) J^-1 and f_a = -(w det J sigma J^-T) dN_a/dy, the same sums
    as B^T sigma without forming grad N. With 8 points and hg > 0 the hourglass control of
    ``feblock_hg`` is added (sg rows 8-13; scratch jf (6, 3, 3), eg and tg (8, 6))."""
    ng = wts.shape[0]
    ctl = ng == 8 and hg > 0.0
    vol = 0.0
    for g in range(ng):
        det = _jac_inv(xe, dref[g], jinv[g])
        if not det > 0.0:
            return False
        wd[g] = wts[g] * det
        vol += wd[g]
    if ctl and not hg_jacobians(xe, dface, jf):
        return False
    for a in range(20):
        fe[a, 0] = 0.0
        fe[a, 1] = 0.0
        fe[a, 2] = 0.0
    for c in range(6):
        se[c] = 0.0
    for g in range(ng):
        d = dref[g]
        # master velocity gradient m[i, k] = sum_a v_ai dN_a/dy_k
        m00 = 0.0; m01 = 0.0; m02 = 0.0
        m10 = 0.0; m11 = 0.0; m12 = 0.0
        m20 = 0.0; m21 = 0.0; m22 = 0.0
        for a in range(20):
            v0 = ve[a, 0]; v1 = ve[a, 1]; v2 = ve[a, 2]
            n0 = d[a, 0]; n1 = d[a, 1]; n2 = d[a, 2]
            m00 += v0 * n0; m01 += v0 * n1; m02 += v0 * n2
            m10 += v1 * n0; m11 += v1 * n1; m12 += v1 * n2
            m20 += v2 * n0; m21 += v2 * n1; m22 += v2 * n2
        ji = jinv[g]
        # L = m J^-1
        l00 = m00 * ji[0, 0] + m01 * ji[1, 0] + m02 * ji[2, 0]
        l01 = m00 * ji[0, 1] + m01 * ji[1, 1] + m02 * ji[2, 1]
        l02 = m00 * ji[0, 2] + m01 * ji[1, 2] + m02 * ji[2, 2]
        l10 = m10 * ji[0, 0] + m11 * ji[1, 0] + m12 * ji[2, 0]
        l11 = m10 * ji[0, 1] + m11 * ji[1, 1] + m12 * ji[2, 1]
        l12 = m10 * ji[0, 2] + m11 * ji[1, 2] + m12 * ji[2, 2]
        l20 = m20 * ji[0, 0] + m21 * ji[1, 0] + m22 * ji[2, 0]
        l21 = m20 * ji[0, 1] + m21 * ji[1, 1] + m22 * ji[2, 1]
        l22 = m20 * ji[0, 2] + m21 * ji[1, 2] + m22 * ji[2, 2]
        exx = l00 * dt; eyy = l11 * dt; ezz = l22 * dt
        exy = 0.5 * (l01 + l10) * dt
        exz = 0.5 * (l02 + l20) * dt
        eyz = 0.5 * (l12 + l21) * dt
        ev = exx + eyy + ezz
        s = sg[g]
        s[0] += lam * ev + g2 * exx
        s[1] += lam * ev + g2 * eyy
        s[2] += lam * ev + g2 * ezz
        s[3] += g2 * exy
        s[4] += g2 * exz
        s[5] += g2 * eyz
        w = wd[g]
        fv = w / vol
        for c in range(6):
            se[c] += fv * s[c]
        if ctl:
            e = eg[g]
            e[0] = exx; e[1] = eyy; e[2] = ezz; e[3] = exy; e[4] = exz; e[5] = eyz
        else:
            _gauss_force(s[0] * w, s[1] * w, s[2] * w, s[3] * w, s[4] * w, s[5] * w, ji, d, fe)
    if ctl:
        hg_step(ve, dface, jf, wpg, vol, lam, g2, hg, dt, eg, sg, tg, fe)
        for g in range(8):
            s = sg[g]
            w = wd[g]
            t = tg[g]
            _gauss_force(s[0] * w - t[0], s[1] * w - t[1], s[2] * w - t[2], s[3] * w - t[3], s[4] * w - t[4],
                         s[5] * w - t[5], jinv[g], dref[g], fe)
    return True


@njit(cache=True)
def feb_step(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, force, nq, hg=0.0):
    """One elastic step of the 20-node elements in ``rows`` with the nq x nq x nq rule.

    pos, vel (nv, 3): node positions and velocities; nodes (ne, 20) node rows; rows (k,) int64
    element rows; bulk, shear (ne,) [Pa] by element row; dt [s]; gstress (ne, 27, 6),
    stress (ne, 6) [Pa]; force (nv, 3) [N]; nq 2 or 3.
    At each Gauss point: grad v = sum_I v_I (x) grad N_I (Eq. 4-5 with velocities), strain
    increment sym(grad v) dt (Eq. 3, 6), gstress += lambda tr(de) I + 2 G de (elastic model),
    then stress[e] = volume-weighted mean and force[nodes[e, a]] += -sum_g w det J sigma . grad N_a
    (Eq. 7), element by element in the order of rows; hg > 0 adds the hourglass control of
    ``feblock_hg`` to 2 x 2 x 2 elements (eps_h = hg). Modifies gstress, stress, force. Returns
    the first element row skipped (det J not positive at a Gauss point), -1 if none.
    """
    shp, dref, wts = ref_tables(nq)
    dface, wpg = hg_tables()
    jf = np.empty((6, 3, 3))
    eg = np.empty((8, 6))
    tg = np.empty((8, 6))
    ng = wts.shape[0]
    jinv = np.empty((ng, 3, 3))
    wd = np.empty(ng)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    ve = np.empty((20, 3))
    fe = np.empty((20, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        _gather(vel, nodes, e, nd, ve)
        if not _elem_step(xe, ve, dref, wts, bulk[e] - 2.0 * shear[e] / 3.0, 2.0 * shear[e], dt,
                          gstress[e], stress[e], fe, jinv, wd, hg, dface, wpg, jf, eg, tg):
            if bad < 0:
                bad = e
            continue
        scatter(force, nd, fe)
    return bad


@njit(cache=True)
def _element_chunk(lo, hi, pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg):
    """Elements rows[lo:hi] of the element pass (see ``feb_element_pass``)."""
    shp, dref, wts = ref_tables(nq)
    dface, wpg = hg_tables()
    jf = np.empty((6, 3, 3))
    eg = np.empty((8, 6))
    tg = np.empty((8, 6))
    ng = wts.shape[0]
    jinv = np.empty((ng, 3, 3))
    wd = np.empty(ng)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    ve = np.empty((20, 3))
    for kk in range(lo, hi):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        _gather(vel, nodes, e, nd, ve)
        ok[kk] = _elem_step(xe, ve, dref, wts, bulk[e] - 2.0 * shear[e] / 3.0, 2.0 * shear[e], dt,
                            gstress[e], stress[e], fe[kk], jinv, wd, hg, dface, wpg, jf, eg, tg)


@njit(cache=True, parallel=True)
def feb_element_pass(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg=0.0):
    """The element half of ``feb_step_parallel``, in parallel over chunks of rows (each element
    writes only its own rows): stress update, and fe[k] (20, 3) = the force of element rows[k]
    on each of its nodes; ok[k] = False for an element with det J not positive (untouched)."""
    n = rows.shape[0]
    nchunk = (n + CHUNK - 1) // CHUNK
    for c in prange(nchunk):
        _element_chunk(c * CHUNK, min(n, (c + 1) * CHUNK), pos, vel, nodes, rows, bulk, shear, dt, gstress,
                       stress, fe, ok, nq, hg)


@njit(cache=True)
def feb_element_pass_serial(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg=0.0):
    """``feb_element_pass`` on the calling thread (small meshes: no thread start-up), same results."""
    _element_chunk(0, rows.shape[0], pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg)


@njit(cache=True)
def feb_node_lists(nv, nodes, rows):
    """Per node, the (element, local node) entries that add to it, in a fixed order (CSR): the
    entries of node r are nent[nstart[r]:nstart[r + 1]], each 20 k + a (node a of element
    rows[k]), ascending: the order of the serial scatter of ``feb_step``
    (``kernels/gather.node_lists``). Made once per mesh. Returns (nstart (nv + 1,), nent
    (20 k,)) int64."""
    return node_lists(nv, np.arange(nv), nodes, rows, 20)


@njit(cache=True)
def _node_range_mag(lo, hi, force, fmag, fe, ok, nstart, nent):
    for r in range(lo, hi):
        f0 = force[r, 0]; f1 = force[r, 1]; f2 = force[r, 2]
        mg = fmag[r]
        for q in range(nstart[r], nstart[r + 1]):
            kk = nent[q] // 20
            if ok[kk]:
                a = nent[q] - 20 * kk
                x = fe[kk, a, 0]; y = fe[kk, a, 1]; z = fe[kk, a, 2]
                f0 += x; f1 += y; f2 += z
                mg += np.sqrt(x * x + y * y + z * z)
        force[r, 0] = f0; force[r, 1] = f1; force[r, 2] = f2
        fmag[r] = mg


@njit(cache=True, parallel=True)
def feb_node_sums_mag(force, fmag, fe, ok, nstart, nent):
    """``kernels/gather.node_sums`` that also adds to fmag[r] the magnitude of every element force on node
    r (sum over its entries of |fe|: the scale of the forces meeting at the node, for
    equilibrium ratios). Parallel over chunks of nodes; the same sums for any thread count."""
    nv = nstart.shape[0] - 1
    nchunk = (nv + 4 * CHUNK - 1) // (4 * CHUNK)
    for c in prange(nchunk):
        _node_range_mag(c * 4 * CHUNK, min(nv, (c + 1) * 4 * CHUNK), force, fmag, fe, ok, nstart, nent)


@njit(cache=True)
def feb_node_sums_mag_serial(force, fmag, fe, ok, nstart, nent):
    """``feb_node_sums_mag`` on the calling thread, same results."""
    _node_range_mag(0, nstart.shape[0] - 1, force, fmag, fe, ok, nstart, nent)


@njit(cache=True)
def feb_step_parallel(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, force, nq,
                      fe, ok, nstart, nent, hg=0.0):
    """``feb_step`` on several threads, bit for bit the same result whatever the thread count
    (and the same as ``feb_step``): a parallel element pass into the scratch fe (len(rows), 20,
    3) [N] and ok (len(rows),) bool, then fixed-order sums per node over the lists of
    ``feb_node_lists(len(force), nodes, rows)``. Returns the first element row skipped in the
    order of rows (-1 none)."""
    feb_element_pass(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg)
    node_sums(force, fe, ok, nstart, nent)
    for kk in range(rows.shape[0]):
        if not ok[kk]:
            return rows[kk]
    return -1


@njit(cache=True)
def feb_forces(pos, nodes, rows, gstress, force, nq):
    """Nodal forces of the Gauss-point stresses as they are (no update): force[nodes[e, a]] +=
    -sum_g w det J sigma_g . grad N_a. Modifies force; returns the first element row skipped,
    -1 if none."""
    shp, dref, wts = ref_tables(nq)
    ng = wts.shape[0]
    dng = np.empty((ng, 20, 3))
    wd = np.empty(ng)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    fe = np.empty((20, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        if not _elem_grads(xe, dref, wts, dng, wd):
            if bad < 0:
                bad = e
            continue
        _elem_force(dng, wd, gstress[e], fe)
        scatter(force, nd, fe)
    return bad


@njit(cache=True)
def feb_volume(pos, nodes, rows, volume):
    """Element volumes sum_g w det J by the 3 x 3 x 3 rule (exact for parallelepipeds).
    Modifies volume; returns the first element row with det J not positive (volume 0), -1 if none."""
    shp, dref, wts = ref_tables(np.int64(3))
    dng = np.empty((27, 20, 3))
    wd = np.empty(27)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        if not _elem_grads(xe, dref, wts, dng, wd):
            volume[e] = 0.0
            if bad < 0:
                bad = e
            continue
        v = 0.0
        for g in range(27):
            v += wd[g]
        volume[e] = v
    return bad


@njit(cache=True)
def feb_lumped_mass(pos, nodes, rows, density, mass):
    """Lumped node masses of 20-node elements, added to mass[nodes] (density by element row).

    The text lumps through its fictitious tetrahedral discretization and names "more accurate
    schemes" (Hughes 1987); row sums of the consistent mass are negative at the corners (-M/8,
    errata), so HRZ diagonal scaling is used (Hinton, Rock & Zienkiewicz 1976; Hughes 1987,
    section 7.3.2): node a gets M d_a / sum_b d_b with d_a = int rho N_a^2 dV, M = rho V, both by
    the 3 x 3 x 3 rule (exact for parallelepipeds). Every mass is positive; for a rectangular
    brick the fractions are 0.0282 M per corner and 0.0645 M per mid-edge node (errata).
    Modifies mass; returns the first element row skipped, -1 if none."""
    shp, dref, wts = ref_tables(np.int64(3))
    dng = np.empty((27, 20, 3))
    wd = np.empty(27)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    dd = np.empty(20)
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        if not _elem_grads(xe, dref, wts, dng, wd):
            if bad < 0:
                bad = e
            continue
        v = 0.0
        tot = 0.0
        for a in range(20):
            dd[a] = 0.0
        for g in range(27):
            v += wd[g]
            for a in range(20):
                dd[a] += wd[g] * shp[g, a] * shp[g, a]
        for a in range(20):
            tot += dd[a]
        m = density[e] * v
        for a in range(20):
            mass[nd[a]] += m * dd[a] / tot
    return bad


@njit(cache=True)
def feb_stiffness(pos, nodes, rows, bulk, shear, kdiag, nq, hg=0.0):
    """Per-node stiffness bound for the explicit time step, added to kdiag[nodes].

    The text takes its time step from the fictitious tetrahedral discretization ("Solution
    Algorithm"); this uses a bound that is safe by construction instead: the element stiffness
    K = sum_g w det J B^T D B with the nq-rule of the forces (never used for forces, only
    here; with nq = 2 and hg > 0 plus the hourglass stiffness of ``feblock_hg``, its six face
    points weighted hg V / 6) and, per node, the largest absolute row sum of its three rows.
    Summed over elements it bounds the global row sums, so by Gershgorin's theorem the largest
    eigenvalue of M^-1 K is at most max_i k_i / m_i for any diagonal mass, and
    dt <= 2 min sqrt(m_i / k_i) is stable. Modifies kdiag; returns the first element row
    skipped, -1 if none."""
    shp, dref, wts = ref_tables(nq)
    ng = wts.shape[0]
    with_hg = ng == 8 and hg > 0.0
    nh = ng + 6 if with_hg else ng
    dface, wpg = hg_tables()
    dng = np.empty((nh, 20, 3))
    wd = np.empty(nh)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    K = np.empty((60, 60))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        ok = _elem_grads(xe, dref, wts, dng[:ng], wd[:ng])
        if ok and with_hg:
            vol = 0.0
            for g in range(8):
                vol += wd[g]
            for p in range(6):
                # grad of dB_p: grad N(p) - sum_g w_pg grad N(g)
                h = dng[8 + p]
                ok = ok and _grad_n(xe, dface[p], h) > 0.0
                for g in range(8):
                    w = wpg[p, g]
                    for a in range(20):
                        for j in range(3):
                            h[a, j] -= w * dng[g, a, j]
                wd[8 + p] = hg * vol / 6.0
        if not ok:
            if bad < 0:
                bad = e
            continue
        add_stiffness_bound(dng, wd, bulk[e] - 2.0 * shear[e] / 3.0, shear[e], nd, K, kdiag)
    return bad


@njit(cache=True)
def feb_body_force(pos, nodes, rows, density, gvec, force):
    """Consistent nodal forces of gravity, the text's Eq. (8) F_I = int N_I g dV (rho g per
    unit volume; the errata: gravity is Eq. 8, not Eq. 5), by the 3 x 3 x 3 rule (exact for
    parallelepipeds). Not all positive: a rectangular brick of weight W gives -W/8 per corner
    and W/6 per mid-edge node. density (ne,) [kg/m3], gvec (3,) [m/s2]. Modifies force;
    returns the first element row skipped, -1 if none."""
    shp, dref, wts = ref_tables(np.int64(3))
    dng = np.empty((27, 20, 3))
    wd = np.empty(27)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        if not _elem_grads(xe, dref, wts, dng, wd):
            if bad < 0:
                bad = e
            continue
        add_body_force(wd, shp, density[e], gvec, nd, force)
    return bad


@njit(cache=True)
def quad8_traction_loads(pos, quad, traction, force):
    """Consistent nodal forces of a uniform traction on 8-node element faces:
    force[quad[f, a]] += traction[f] int N_a dA (Eq. 8/9 applied to a surface load).

    quad (k, 8): the face's 4 corners counter-clockwise seen from outside, then the mid-edge
    nodes of edges 01 12 23 30 (the layout of ``FACES``); traction (k, 3) [Pa]. The 8-node
    serendipity face functions (the brick's restricted to a face) are integrated by the 3 x 3
    Gauss rule, exact for flat parallelogram faces, where a face of area A gives -A/12 at each
    corner and A/3 at each mid-edge node. Modifies force."""
    r = np.sqrt(0.6)
    x = np.array([-r, 0.0, r])
    wq = np.array([5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])
    # master coordinates (s, t) of the 8 face nodes
    cs = np.array([-1.0, 1.0, 1.0, -1.0, 0.0, 1.0, 0.0, -1.0])
    ct = np.array([-1.0, -1.0, 1.0, 1.0, -1.0, 0.0, 1.0, 0.0])
    n = np.empty(8)
    ds = np.empty(8)
    dt = np.empty(8)
    for f in range(quad.shape[0]):
        for i in range(3):
            for j in range(3):
                s = x[i]
                t = x[j]
                for a in range(8):
                    a1 = cs[a]
                    a2 = ct[a]
                    if a < 4:
                        n[a] = 0.25 * (1.0 + a1 * s) * (1.0 + a2 * t) * (a1 * s + a2 * t - 1.0)
                        ds[a] = 0.25 * a1 * (1.0 + a2 * t) * (2.0 * a1 * s + a2 * t)
                        dt[a] = 0.25 * a2 * (1.0 + a1 * s) * (2.0 * a2 * t + a1 * s)
                    elif a1 == 0.0:
                        n[a] = 0.5 * (1.0 - s * s) * (1.0 + a2 * t)
                        ds[a] = -s * (1.0 + a2 * t)
                        dt[a] = 0.5 * a2 * (1.0 - s * s)
                    else:
                        n[a] = 0.5 * (1.0 - t * t) * (1.0 + a1 * s)
                        ds[a] = 0.5 * a1 * (1.0 - t * t)
                        dt[a] = -t * (1.0 + a1 * s)
                t1x = 0.0; t1y = 0.0; t1z = 0.0; t2x = 0.0; t2y = 0.0; t2z = 0.0
                for a in range(8):
                    p = pos[quad[f, a]]
                    t1x += ds[a] * p[0]; t1y += ds[a] * p[1]; t1z += ds[a] * p[2]
                    t2x += dt[a] * p[0]; t2y += dt[a] * p[1]; t2z += dt[a] * p[2]
                cx = t1y * t2z - t1z * t2y
                cy = t1z * t2x - t1x * t2z
                cz = t1x * t2y - t1y * t2x
                da = np.sqrt(cx * cx + cy * cy + cz * cz) * wq[i] * wq[j]
                for a in range(8):
                    rr = quad[f, a]
                    w = da * n[a]
                    force[rr, 0] += w * traction[f, 0]
                    force[rr, 1] += w * traction[f, 1]
                    force[rr, 2] += w * traction[f, 2]


@njit(cache=True)
def feb_gauss_positions(pos, nodes, rows, out, nq):
    """Positions of the Gauss points of the nq-rule: out[e, g] = sum_a N_a(y_g) x_a
    (out (ne, >= nq^3, 3)). Modifies out."""
    shp, dref, wts = ref_tables(nq)
    for kk in range(rows.shape[0]):
        e = rows[kk]
        for g in range(wts.shape[0]):
            x = 0.0; y = 0.0; z = 0.0
            for a in range(20):
                p = pos[nodes[e, a]]
                x += shp[g, a] * p[0]; y += shp[g, a] * p[1]; z += shp[g, a] * p[2]
            out[e, g, 0] = x
            out[e, g, 1] = y
            out[e, g, 2] = z


@njit(cache=True)
def _slave_weights():
    """N_a at the 7 slave nodes: (7, 20)."""
    w = np.empty((7, 20))
    dn = np.empty((20, 3))
    for s in range(7):
        shape20(YSLAVE[s, 0], YSLAVE[s, 1], YSLAVE[s, 2], w[s], dn)
    return w


@njit(cache=True)
def feb_slave_interp(nodes, slaves, rows, arr):
    """Slave nodes follow the masters (text, "Element Implementation"): arr[slaves[e, s]] =
    sum_a N_a(y_s) arr[nodes[e, a]] for every slave s >= 0 (slaves (ne, 7) rows, -1 none) of the
    elements in rows; arr (nv, 3): positions, velocities or displacements. Modifies arr."""
    w = _slave_weights()
    for kk in range(rows.shape[0]):
        e = rows[kk]
        for s in range(7):
            r = slaves[e, s]
            if r < 0:
                continue
            x = 0.0; y = 0.0; z = 0.0
            for a in range(20):
                p = arr[nodes[e, a]]
                x += w[s, a] * p[0]; y += w[s, a] * p[1]; z += w[s, a] * p[2]
            arr[r, 0] = x
            arr[r, 1] = y
            arr[r, 2] = z


@njit(cache=True)
def feb_slave_forces(nodes, slaves, rows, force):
    """Forces on slave nodes (contact, boundary loads) go to the masters by the text's Eq. (9),
    F_I = N_I(y_s) P; the slave's own force is then zero. Force and moment about any point are
    kept when the slave sits where the masters' interpolation puts it (``feb_slave_interp``).
    Modifies force."""
    w = _slave_weights()
    for kk in range(rows.shape[0]):
        e = rows[kk]
        for s in range(7):
            r = slaves[e, s]
            if r < 0:
                continue
            px = force[r, 0]; py = force[r, 1]; pz = force[r, 2]
            for a in range(20):
                m = nodes[e, a]
                force[m, 0] += w[s, a] * px
                force[m, 1] += w[s, a] * py
                force[m, 2] += w[s, a] * pz
            force[r, 0] = 0.0
            force[r, 1] = 0.0
            force[r, 2] = 0.0
