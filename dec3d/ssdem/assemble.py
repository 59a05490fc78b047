"""Interface stiffness and its assembly into the global sparse matrix.

Formulation (thesis Ch. 3, rebuilt in ERRATA for 004_47a079be8dc4bc3f):

    K_L = diag(k_n L, k_s L, k_n L^3 / 12)           local (normal, shear, rotation)
    lambda = [[cos a, sin a, 0], [-sin a, cos a, 0], [0, 0, 1]],  a = angle of n
    R_i = [[1, 0, -(y_P - y_i)], [0, 1, x_P - x_i], [0, 0, 1]]   centroid -> point P
    relative displacement at P (b with respect to a) = R_b u_b - R_a u_a
    C_aa = R_a^T K_G R_a,  C_ab = -R_a^T K_G R_b,  C_ba = C_ab^T,  C_bb = R_b^T K_G R_b
    with K_G = lambda^T K_L lambda, added into K at (a,a), (a,b), (b,a), (b,b).

We carry T_i = lambda R_i (global DOFs of block i -> local motion of P), so that
C_ab = -T_a^T K_L T_b with K_L diagonal: three outer products, no 3x3 products.
The local relative motion is (delta_n, delta_s, d_omega) with delta_n > 0 opening.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .model import Blocks, Interfaces


def transfer_matrices(blocks: Blocks, itf: Interfaces) -> tuple[np.ndarray, np.ndarray]:
    """T_a, T_b (m, 3, 3): block DOFs (u_x, u_y, omega) -> local motion of the interface midpoint."""
    def one(idx: np.ndarray) -> np.ndarray:
        r = itf.mid - blocks.ref[idx]                  # lever arm from reference point to P
        c, s = itf.normal[:, 0], itf.normal[:, 1]
        # lambda @ R written out: rows are n, t = (-s, c), and the rotation
        T = np.zeros((len(idx), 3, 3))
        T[:, 0, 0], T[:, 0, 1] = c, s
        T[:, 0, 2] = -c * r[:, 1] + s * r[:, 0]
        T[:, 1, 0], T[:, 1, 1] = -s, c
        T[:, 1, 2] = s * r[:, 1] + c * r[:, 0]
        T[:, 2, 2] = 1.0
        return T
    return one(itf.a), one(itf.b)


def local_stiffness(kn: np.ndarray, ks: np.ndarray, length: np.ndarray) -> np.ndarray:
    """Diagonal of K_L, (m, 3): k_n L, k_s L, k_n L^3/12 (springs integrated along the edge)."""
    return np.column_stack([kn * length, ks * length, kn * length ** 3 / 12.0])


def relative_motion(u: np.ndarray, a: np.ndarray, b: np.ndarray, Ta: np.ndarray, Tb: np.ndarray) -> np.ndarray:
    """Local relative motion (m, 3) = T_b u_b - T_a u_a; u is (n, 3) block DOFs."""
    return np.einsum("mij,mj->mi", Tb, u[b]) - np.einsum("mij,mj->mi", Ta, u[a])


def interface_forces(rel: np.ndarray, kl: np.ndarray) -> np.ndarray:
    """Local force on b at P, (m, 3): (N, T, M) = -K_L * rel (a gets the opposite)."""
    return -kl * rel


class Assembler:
    """Sparse K for a fixed set of active DOFs, reassembled cheaply as springs change.

    dof (n, 3) maps each block DOF to its row in the reduced system, or -1 for a
    fixed DOF or a removed block (eliminated rows and columns, thesis Sec. 3.2.1 H).
    The sparsity pattern is built once; each `matrix(kl)` only scatters new values.
    """

    def __init__(self, a: np.ndarray, b: np.ndarray, Ta: np.ndarray, Tb: np.ndarray, dof: np.ndarray):
        self.a, self.b, self.Ta, self.Tb = a, b, Ta, Tb
        self.ndof = int(np.count_nonzero(dof >= 0))
        da, db = dof[a], dof[b]
        rows, cols, sel = [], [], []
        # the four sub-matrices in a fixed order: aa, ab, ba, bb; entry (m, i, j)
        for q, (r0, c0) in enumerate(((da, da), (da, db), (db, da), (db, db))):
            R = np.broadcast_to(r0[:, :, None], (len(a), 3, 3))
            C = np.broadcast_to(c0[:, None, :], (len(a), 3, 3))
            ok = (R >= 0) & (C >= 0) & np.ones((len(a), 3, 3), bool)
            idx = np.flatnonzero(ok.ravel())
            rows.append(R.ravel()[idx])
            cols.append(C.ravel()[idx])
            sel.append((q, idx))
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        key = rows * max(self.ndof, 1) + cols
        uniq, self.inverse = np.unique(key, return_inverse=True)
        self.nnz = len(uniq)
        r, c = uniq // max(self.ndof, 1), uniq % max(self.ndof, 1)
        self.indices = c.astype(np.int32)
        self.indptr = np.zeros(self.ndof + 1, dtype=np.int64)
        np.add.at(self.indptr, r + 1, 1)
        self.indptr = np.cumsum(self.indptr)
        self.sel = sel
        self.diag_pos = None

    def blocks(self, kl: np.ndarray) -> list[np.ndarray]:
        """C_aa, C_ab, C_ba, C_bb (m, 3, 3) for local stiffness diagonals kl (m, 3), or full
        symmetric local matrices kl (m, 3, 3) (a partly open no-tension interface, contact.py)."""
        Ta, Tb = self.Ta, self.Tb
        if kl.ndim == 3:
            Caa = np.einsum("mki,mkl,mlj->mij", Ta, kl, Ta)
            Cab = -np.einsum("mki,mkl,mlj->mij", Ta, kl, Tb)
            Cbb = np.einsum("mki,mkl,mlj->mij", Tb, kl, Tb)
            return [Caa, Cab, Cab.transpose(0, 2, 1), Cbb]
        Caa = np.einsum("mki,mk,mkj->mij", Ta, kl, Ta)
        Cab = -np.einsum("mki,mk,mkj->mij", Ta, kl, Tb)
        Cbb = np.einsum("mki,mk,mkj->mij", Tb, kl, Tb)
        return [Caa, Cab, Cab.transpose(0, 2, 1), Cbb]

    def matrix(self, kl: np.ndarray) -> sp.csr_matrix:
        C = self.blocks(kl)
        vals = np.concatenate([C[q].ravel()[idx] for q, idx in self.sel])
        data = np.bincount(self.inverse, weights=vals, minlength=self.nnz)
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.ndof, self.ndof))


def assemble_full(blocks: Blocks, itf: Interfaces, kn: np.ndarray, ks: np.ndarray) -> sp.csr_matrix:
    """The unconstrained (3n x 3n) matrix K*, every block included (for checks and tests)."""
    Ta, Tb = transfer_matrices(blocks, itf)
    asm = Assembler(itf.a, itf.b, Ta, Tb, np.arange(3 * blocks.n).reshape(-1, 3))
    return asm.matrix(local_stiffness(kn, ks, itf.length))
