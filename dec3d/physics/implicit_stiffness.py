"""Element stiffness matrices and their sparse assembly for the implicit static solve
(``physics.implicit``).

- 20-node bricks (FE blocks) and 10-node tetrahedra: probed from the engine's own step kernels
  (``feb_element_pass_serial``, ``tet10_step``). Each element runs alone, on a private copy of its
  nodes, from zero stress, with a unit velocity on one of its degrees of freedom over a unit time; the
  negated nodal forces are that column of its stiffness (the kernels' stresses and forces are linear in
  the velocities). One pass per local degree of freedom gives every element's column at once, and the
  stiffness is exactly the step's (Gauss rule, hourglass control), not a second formulation of it.
- 4-node tetrahedra: the constant-strain stiffness V Bᵀ D B (times the zone's weight, ½ for the two
  overlaid tetrahedra of a hexahedral set), without the nodal or hexahedral averaging of the volumetric
  strain that the zone step applies (``zone_step``). It only preconditions the conjugate gradients of the
  zone operator, which is the step's own, so the difference changes the iteration count, not the answer.
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.feblock import feb_element_pass_serial

_F = np.float64
_I = np.int64


def _private(pos, nodes, rows, k):
    """Positions (n k, 3) and node table (n, k) of the elements ``rows`` each on its own k nodes."""
    nr = len(rows)
    xp = np.ascontiguousarray(pos[nodes[rows, :k]].reshape(nr * k, 3))
    return xp, np.arange(nr * k, dtype=_I).reshape(nr, k)


def element_stiffness(pos, nodes, rows, bulk, shear, nq, hg) -> tuple[np.ndarray, np.ndarray]:
    """(ke (len(rows), 60, 60), ok (len(rows),) bool) of 20-node bricks as the explicit element pass
    (``feb_element_pass_serial``, Gauss rule ``nq``, hourglass ε ``hg``) computes forces from
    velocities: ke[k, 3a+i, 3b+j] = −(force on node a, component i, of element k) for a unit velocity
    of node b in direction j over a unit time from zero stress. ok: det J positive everywhere."""
    nr = len(rows)
    xp, pnodes = _private(pos, nodes, rows, 20)
    prow = np.arange(nr, dtype=_I)
    bk = np.ascontiguousarray(bulk[rows])
    sh = np.ascontiguousarray(shear[rows])
    vel = np.zeros((nr * 20, 3))
    gs = np.zeros((nr, 27, 6))
    st = np.zeros((nr, 6))
    fe = np.empty((nr, 20, 3))
    ok = np.ones(nr, np.bool_)
    okk = np.empty(nr, np.bool_)
    ke = np.empty((nr, 60, 60))
    for a in range(20):
        for i in range(3):
            vel[:] = 0.0
            vel[a::20, i] = 1.0
            gs[:] = 0.0
            feb_element_pass_serial(xp, vel, pnodes, prow, bk, sh, 1.0, gs, st, fe, okk, nq, hg)
            ok &= okk
            ke[:, :, 3 * a + i] = -fe.reshape(nr, 60)
    return ke, ok


def tet10_stiffness(pos, gp, rows, bulk, shear) -> tuple[np.ndarray, bool]:
    """(ke (len(rows), 30, 30), ok) of 10-node zones, probed from ``zones_ho.tet10_step`` as
    ``element_stiffness`` probes the bricks; ok False when a zone is inverted or flat."""
    from dec3d.kernels.zones_ho import tet10_step

    nr = len(rows)
    xp, pgp = _private(pos, gp, rows, 10)
    prow = np.arange(nr, dtype=_I)
    bk = np.ascontiguousarray(bulk[rows])
    sh = np.ascontiguousarray(shear[rows])
    vel = np.zeros((nr * 10, 3))
    gs = np.zeros((nr, 4, 6))
    st = np.zeros((nr, 6))
    f = np.zeros((nr * 10, 3))
    ok = True
    ke = np.empty((nr, 30, 30))
    for a in range(10):
        for i in range(3):
            vel[:] = 0.0
            vel[a::10, i] = 1.0
            gs[:] = 0.0
            f[:] = 0.0
            ok &= tet10_step(xp, vel, pgp, prow, bk, sh, 1.0, gs, st, f) < 0
            ke[:, :, 3 * a + i] = -f.reshape(nr, 30)
    return ke, ok


def tet4_stiffness(x, bulk, shear, weight) -> np.ndarray:
    """Constant-strain stiffness (n, 12, 12) of tetrahedra with corners x (n, 4, 3): weight V Bᵀ D B,
    isotropic D from the bulk and shear moduli, engineering shear strains; dof 3a + i."""
    n = len(x)
    e = x[:, 1:] - x[:, :1]                                   # (n, 3, 3) edge vectors from corner 0
    vol = np.linalg.det(e) / 6.0
    inv = np.linalg.inv(e)                                    # grad of the barycentric coordinates 1-3
    g = np.empty((n, 4, 3))
    g[:, 1:] = np.transpose(inv, (0, 2, 1))
    g[:, 0] = -g[:, 1:].sum(axis=1)
    B = np.zeros((n, 6, 12))
    for a in range(4):
        gx, gy, gz = g[:, a, 0], g[:, a, 1], g[:, a, 2]
        B[:, 0, 3 * a], B[:, 1, 3 * a + 1], B[:, 2, 3 * a + 2] = gx, gy, gz
        B[:, 3, 3 * a], B[:, 3, 3 * a + 1] = gy, gx
        B[:, 4, 3 * a], B[:, 4, 3 * a + 2] = gz, gx
        B[:, 5, 3 * a + 1], B[:, 5, 3 * a + 2] = gz, gy
    lam = bulk - 2.0 * shear / 3.0
    D = np.zeros((n, 6, 6))
    D[:, :3, :3] = lam[:, None, None]
    for i in range(3):
        D[:, i, i] += 2.0 * shear
        D[:, 3 + i, 3 + i] = shear
    return (weight * np.abs(vol))[:, None, None] * np.einsum("nki,nkl,nlj->nij", B, D, B)


def assemble(parts, n: int):
    """The (n, n) CSC matrix of the element matrices ``parts``: pairs (dof (ne, k) int, ke (ne, k, k))."""
    from scipy.sparse import coo_matrix

    ii, jj, kk = [], [], []
    for dof, ke in parts:
        k = dof.shape[1]
        ii.append(np.repeat(dof[:, :, None], k, axis=2).ravel())
        jj.append(np.repeat(dof[:, None, :], k, axis=1).ravel())
        kk.append(ke.ravel())
    if not ii:
        return coo_matrix((n, n)).tocsc()
    return coo_matrix((np.concatenate(kk), (np.concatenate(ii), np.concatenate(jj))), shape=(n, n)).tocsc()
