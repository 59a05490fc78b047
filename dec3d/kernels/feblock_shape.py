"""20-node serendipity bricks (FE blocks): node tables, shape functions, Gauss rules, and the
kernels that only interpolate with them: Gauss-point positions, slave (mid-face) nodes, and
consistent nodal loads of face stresses on the 8-node element faces.

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
-sqrt(3/5), 0, sqrt(3/5), weights 5/9, 8/9, 5/9).
"""
import numpy as np
from numba import njit


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


#: master coordinates (s, t) of the nodes of an element face in the layout of ``FACES``: the 4
#: corners counter-clockwise seen from outside, then the mid-edge nodes of edges 01 12 23 30
QNODE = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0],
                  [0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])


@njit(cache=True)
def quad_shape(s, t, nn, n, ds, dt):
    """Shape functions n (nn,) and their derivatives ds, dt (nn,) at (s, t) of a quadrilateral
    face with nn = 4 (bilinear: N = 1/4 (1 + a1 s)(1 + a2 t)) or 8 nodes (serendipity: the
    brick's functions restricted to a face, corners N = 1/4 (1 + a1 s)(1 + a2 t)(a1 s + a2 t - 1),
    mid-edge nodes N = 1/2 (1 - s^2)(1 + a2 t) or 1/2 (1 - t^2)(1 + a1 s)), nodes at QNODE[:nn]."""
    for a in range(nn):
        a1 = QNODE[a, 0]
        a2 = QNODE[a, 1]
        if nn == 4:
            n[a] = 0.25 * (1.0 + a1 * s) * (1.0 + a2 * t)
            ds[a] = 0.25 * a1 * (1.0 + a2 * t)
            dt[a] = 0.25 * a2 * (1.0 + a1 * s)
        elif a < 4:
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


@njit(cache=True)
def _face_point(pos, quad, f, s, t, n, ds, dt):
    """Face functions n, ds, dt (``quad_shape``) at (s, t) of face quad[f] (nn = quad.shape[1]
    node rows) and its area vector dx/ds x dx/dt there (outward for nodes counter-clockwise
    seen from outside), returned as (cx, cy, cz)."""
    nn = quad.shape[1]
    quad_shape(s, t, nn, n, ds, dt)
    t1x = 0.0; t1y = 0.0; t1z = 0.0; t2x = 0.0; t2y = 0.0; t2z = 0.0
    for a in range(nn):
        p = pos[quad[f, a]]
        t1x += ds[a] * p[0]; t1y += ds[a] * p[1]; t1z += ds[a] * p[2]
        t2x += dt[a] * p[0]; t2y += dt[a] * p[1]; t2z += dt[a] * p[2]
    return t1y * t2z - t1z * t2y, t1z * t2x - t1x * t2z, t1x * t2y - t1y * t2x


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
    n = np.empty(8)
    ds = np.empty(8)
    dt = np.empty(8)
    for f in range(quad.shape[0]):
        for i in range(3):
            for j in range(3):
                cx, cy, cz = _face_point(pos, quad, f, x[i], x[j], n, ds, dt)
                da = np.sqrt(cx * cx + cy * cy + cz * cz) * wq[i] * wq[j]
                for a in range(8):
                    rr = quad[f, a]
                    w = da * n[a]
                    force[rr, 0] += w * traction[f, 0]
                    force[rr, 1] += w * traction[f, 1]
                    force[rr, 2] += w * traction[f, 2]


@njit(cache=True)
def face_stress_loads(pos, quad, stress, force):
    """Consistent nodal forces of a uniform stress on quadrilateral element faces (``block face
    apply stress`` on FE blocks): force[quad[f, a]] += int N_a sigma_f . n dA, n the outward unit
    normal, the text's Eq. (8)/(9) F_I = int N_I t dA applied to a surface traction t = sigma n.

    quad (k, nn): nn = 8 (an element face: corners counter-clockwise seen from outside, then the
    mid-edge nodes of edges 01 12 23 30, the layout of ``FACES``) or nn = 4 (corners only,
    bilinear); stress (k, 6) [Pa] xx yy zz xy xz yz, tension positive. n dA = dx/ds x dx/dt ds dt,
    so warped or curved faces take the normal of each point; 3 x 3 Gauss rule, exact for flat
    parallelogram faces, where a face of area A under a traction t gets -A t/12 at each corner
    and A t/3 at each mid-edge node (nn = 8), A t/4 at each corner (nn = 4). Modifies force."""
    r = np.sqrt(0.6)
    x = np.array([-r, 0.0, r])
    wq = np.array([5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])
    nn = quad.shape[1]
    n = np.empty(nn)
    ds = np.empty(nn)
    dt = np.empty(nn)
    for f in range(quad.shape[0]):
        sxx = stress[f, 0]; syy = stress[f, 1]; szz = stress[f, 2]
        sxy = stress[f, 3]; sxz = stress[f, 4]; syz = stress[f, 5]
        for i in range(3):
            for j in range(3):
                cx, cy, cz = _face_point(pos, quad, f, x[i], x[j], n, ds, dt)
                w = wq[i] * wq[j]
                tx = (sxx * cx + sxy * cy + sxz * cz) * w
                ty = (sxy * cx + syy * cy + syz * cz) * w
                tz = (sxz * cx + syz * cy + szz * cz) * w
                for a in range(nn):
                    rr = quad[f, a]
                    force[rr, 0] += n[a] * tx
                    force[rr, 1] += n[a] * ty
                    force[rr, 2] += n[a] * tz


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
