"""What the liner elements carry, for `structure liner list`, VTK and FISH: membrane forces and bending
moments per unit length in each element's axes, from its nodes' displacements and rotations
(``kernels.dkt``: CST membrane, constant over the element; DKT curvatures at the centroid).

N = t D ε (N_xx, N_yy, N_xy; tension positive), M = t³/12 D κ with κ = (βx,x, βy,y, βx,y + βy,x),
β = (−w,x, −w,y): M_xx = −D_b (w,xx + ν w,yy), Timoshenko's signs; D = E / (1 − ν²) [1 ν 0; ν 1 0;
0 0 (1 − ν)/2].
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.dkt import dkt_curvature_b
from dec3d.model.liners import L_E, L_NU, L_T, liner_stores


def element_resultants(model) -> np.ndarray:
    """(s, 6): N_xx, N_yy, N_xy [N/m], M_xx, M_yy, M_xy [N·m/m] of each liner element."""
    nodes, els = liner_stores(model)
    out = np.zeros((els.n, 6))
    b = np.empty((3, 9))
    for e in range(els.n):
        ax = els["axes"][e]
        x2, x3, y3 = els["lxy"][e]
        c = els["nodes"][e]
        u = nodes["disp"][c] @ ax.T                  # (3 nodes, local u v w)
        r = nodes["rot"][c] @ ax.T                   # (3 nodes, local θx θy θz)
        p = els["prop"][e]
        d = p[L_E] / (1.0 - p[L_NU] ** 2) * np.array([[1.0, p[L_NU], 0.0], [p[L_NU], 1.0, 0.0],
                                                        [0.0, 0.0, 0.5 * (1.0 - p[L_NU])]])
        a2 = x2 * y3
        y23, y31, y12 = -y3, y3, 0.0
        x32, x13, x21 = x3 - x2, -x3, x2
        bm = np.array([[y23, 0, y31, 0, y12, 0], [0, x32, 0, x13, 0, x21], [x32, y23, x13, y31, x21, y12]]) / a2
        um = np.array([u[0, 0], u[0, 1], u[1, 0], u[1, 1], u[2, 0], u[2, 1]])
        out[e, :3] = p[L_T] * d @ (bm @ um)
        dkt_curvature_b(x2, x3, y3, 1.0 / 3.0, 1.0 / 3.0, b)
        ub = np.array([u[0, 2], r[0, 0], r[0, 1], u[1, 2], r[1, 0], r[1, 1], u[2, 2], r[2, 0], r[2, 1]])
        out[e, 3:] = p[L_T] ** 3 / 12.0 * d @ (b @ ub)
    return out
