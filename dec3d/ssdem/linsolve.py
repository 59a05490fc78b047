"""Sparse symmetric solve with detection of singular and near-singular pivots.

K is symmetric positive definite when every block is held; a mechanism (a block or
group of blocks free to move) makes it singular.  We factor with SuperLU in
symmetric mode with diagonal pivots only (diag_pivot_thresh = 0 and a symmetric
minimum-degree ordering), so U's diagonal holds the pivots d_j of an LDL^T
factorisation.  A pivot is the stiffness DOF j still has once the DOFs eliminated
before it are free to adjust; d_j / K_jj ~ 0 means DOF j can move at (almost) no
cost, i.e. it belongs to a mechanism (the null vector found by the elimination
has a non-zero entry at j).  Those DOFs' blocks are reported as unstable.

A relative shift of 1e-14 on the diagonal keeps an exactly singular matrix
factorable (the flagged pivots then sit near 1e-14), and changes a regular
solution far below the solver tolerances.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl
from scipy.sparse.csgraph import connected_components

SHIFT = 1e-14


class Factor:
    """LDL^T-like factor of K (CSR, symmetric) with a pivot test."""

    def __init__(self, K: sp.csr_matrix, pivot_tol: float):
        d = K.diagonal()
        self.diag = d
        scale = np.where(d > 0, d, 1.0)
        Ks = (K + sp.diags(SHIFT * scale)).tocsc()
        self.lu = spl.splu(Ks, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options=dict(SymmetricMode=True))
        piv = self.lu.U.diagonal()[self.lu.perm_c]      # pivot of original DOF i
        self.ratio = np.where(d > 0, piv / scale, 0.0)
        self.bad = np.flatnonzero(~(self.ratio > pivot_tol))

    def solve(self, f: np.ndarray) -> np.ndarray:
        return self.lu.solve(f)


def floating_blocks(n: int, a: np.ndarray, b: np.ndarray, carries: np.ndarray, held: np.ndarray) -> np.ndarray:
    """Free blocks with no chain of load-carrying interfaces to a fixed block.

    carries (m,) bool: the interface still has stiffness.  held (n,) bool: fixed blocks.
    Returns a boolean mask (n,) of floating blocks (a whole mechanism at once, where the
    pivot test would find them one DOF at a time).
    """
    ground = n
    ia, ib = a[carries], b[carries]
    fixed_idx = np.flatnonzero(held)
    rows = np.concatenate([ia, fixed_idx])
    cols = np.concatenate([ib, np.full(len(fixed_idx), ground)])
    g = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n + 1, n + 1))
    _, label = connected_components(g, directed=False)
    return label[:n] != label[ground]
