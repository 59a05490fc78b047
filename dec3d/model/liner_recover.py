"""Stress-resultant recovery for liner elements (``structure liner recover surface|resultants``; FISH
``struct.shell.resultant``, ``struct.node.resultant``).

Surface system of a node: z its liner normal ``nrm``, x the projection of a user vector v onto the
plane normal to z (``recover surface v``), y = z × x; kept in ``liner_nodes.sx`` (zero: none yet).

Recovery over a patch of elements (the range): each element's membrane forces N (CST, constant) and
bending moments M (DKT curvatures at its three corners; ``model.liner_output`` signs, M_xy = −D (1 − ν)
w,xy so that Q_x = ∂M_x/∂x + ∂M_xy/∂y) are turned into 3-D tensors, projected onto each corner
node's surface system and averaged, node by node, over the elements of the patch that share the node
(``liner_nodes.nres``: M_x, M_y, M_xy, N_x, N_y, N_xy). An element's resultants at its nodes are those
averages; at its centroid the mean of its three nodes' tensors in the element's own surface system (z
its normal, x the projection of the mean of its nodes' surface x axes); Q_x, Q_y (constant over the
element) come from differentiating the linear field of the averaged moments over it in that system
(``liner_elements.eres (4, 8)``: location 0 the centroid, 1-3 the nodes; M_x, M_y, M_xy, N_x, N_y,
N_xy, Q_x, Q_y). Flags ``nresok``/``eresok`` say which values are valid (set by the last recovery
that covered them; any later step leaves them as they were, as Itasca's do).
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.dkt import dkt_curvature_b
from dec3d.model.liners import L_E, L_NU, L_T, liner_stores

#: (ξ, η) of the DKT element's three corners
_CORNERS = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))


def set_surface(model, elems: np.ndarray, v) -> int:
    """Surface x axes of the nodes of the elements ``elems`` (rows) from the vector ``v``; returns the
    number of nodes whose normal is parallel to ``v`` (left without a surface system)."""
    nodes, els = liner_stores(model)
    rows = np.unique(els["nodes"][elems].ravel())
    v = np.asarray(v, float)
    n = nodes["nrm"][rows]
    p = v[None, :] - (n @ v)[:, None] * n
    size = np.linalg.norm(p, axis=1)
    ok = size > 1e-9 * max(float(np.linalg.norm(v)), 1e-300)
    nodes["sx"][rows[ok]] = p[ok] / size[ok, None]
    nodes["sx"][rows[~ok]] = 0.0
    return int((~ok).sum())


def _tensor(ax, m) -> np.ndarray:
    """3-D tensor of the in-plane tensor (m_xx, m_yy, m_xy) in the axes' rows x, y."""
    ex, ey = ax[0], ax[1]
    return (m[0] * np.outer(ex, ex) + m[1] * np.outer(ey, ey) + m[2] * (np.outer(ex, ey) + np.outer(ey, ex)))


def _project(t, sx, sy) -> np.ndarray:
    return np.array([sx @ t @ sx, sy @ t @ sy, sx @ t @ sy])


def corner_resultants(model, e: int) -> tuple[np.ndarray, np.ndarray]:
    """Element ``e``'s membrane forces (3,) and bending moments at its three corners (3, 3), in its axes."""
    nodes, els = liner_stores(model)
    ax = els["axes"][e]
    x2, x3, y3 = els["lxy"][e]
    c = els["nodes"][e]
    u = nodes["disp"][c] @ ax.T
    r = nodes["rot"][c] @ ax.T
    p = els["prop"][e]
    d = p[L_E] / (1.0 - p[L_NU] ** 2) * np.array([[1.0, p[L_NU], 0.0], [p[L_NU], 1.0, 0.0],
                                                    [0.0, 0.0, 0.5 * (1.0 - p[L_NU])]])
    a2 = x2 * y3
    bm = np.array([[-y3, 0, y3, 0, 0, 0], [0, x3 - x2, 0, -x3, 0, x2], [x3 - x2, -y3, -x3, y3, x2, 0]]) / a2
    um = np.array([u[0, 0], u[0, 1], u[1, 0], u[1, 1], u[2, 0], u[2, 1]])
    nm = p[L_T] * d @ (bm @ um)
    ub = np.array([u[0, 2], r[0, 0], r[0, 1], u[1, 2], r[1, 0], r[1, 1], u[2, 2], r[2, 0], r[2, 1]])
    b = np.empty((3, 9))
    mm = np.empty((3, 3))
    for k, (xi, eta) in enumerate(_CORNERS):
        dkt_curvature_b(x2, x3, y3, xi, eta, b)
        mm[k] = p[L_T] ** 3 / 12.0 * d @ (b @ ub)
    return nm, mm


def recover(model, elems: np.ndarray) -> int:
    """Recover the resultants over the elements ``elems`` (rows); returns how many of their nodes have
    no surface system (nothing is recovered then: the caller reports it)."""
    nodes, els = liner_stores(model)
    elems = np.asarray(elems, np.int64)
    conn = els["nodes"][elems]
    rows = np.unique(conn.ravel())
    sx = nodes["sx"]
    missing = int((np.linalg.norm(sx[rows], axis=1) == 0.0).sum())
    if missing:
        return missing
    sy = np.cross(nodes["nrm"], sx)
    mt = np.zeros((nodes.n, 3, 3))
    nt = np.zeros((nodes.n, 3, 3))
    cnt = np.zeros(nodes.n)
    for e in elems:
        nm, mm = corner_resultants(model, int(e))
        ax = els["axes"][e]
        tn = _tensor(ax, nm)
        for k, i in enumerate(els["nodes"][e]):
            mt[i] += _tensor(ax, mm[k])
            nt[i] += tn
            cnt[i] += 1.0
    mt[rows] /= cnt[rows, None, None]
    nt[rows] /= cnt[rows, None, None]
    for i in rows:
        nodes["nres"][i, :3] = _project(mt[i], sx[i], sy[i])
        nodes["nres"][i, 3:] = _project(nt[i], sx[i], sy[i])
    nodes["nresok"][rows] = 1
    for e in elems:
        c = els["nodes"][e]
        z = els["axes"][e, 2]
        xs = sx[c].mean(axis=0)
        xs = xs - (xs @ z) * z
        if np.linalg.norm(xs) < 1e-9:                      # the nodes' x axes cancel: the element's own
            xs = els["axes"][e, 0].copy()
        xs /= np.linalg.norm(xs)
        ys = np.cross(z, xs)
        for k, i in enumerate(c):
            els["eres"][e, k + 1, :6] = nodes["nres"][i]
        mc = np.array([_project(mt[i], xs, ys) for i in c])       # (3 nodes, Mx My Mxy) in the centroid system
        els["eres"][e, 0, :3] = mc.mean(axis=0)
        els["eres"][e, 0, 3:6] = _project(nt[c].mean(axis=0), xs, ys)
        # gradient of the linear field over the triangle, in (xs, ys) coordinates
        pts = nodes["pos0"][c]
        xy = np.column_stack([(pts - pts[0]) @ xs, (pts - pts[0]) @ ys])
        a = np.column_stack([np.ones(3), xy])
        g = np.linalg.solve(a, mc)                          # rows: constant, ∂/∂x, ∂/∂y of Mx My Mxy
        qx = g[1, 0] + g[2, 2]
        qy = g[1, 2] + g[2, 1]
        els["eres"][e, :, 6] = qx
        els["eres"][e, :, 7] = qy
    els["eresok"][elems] = 1
    return 0
