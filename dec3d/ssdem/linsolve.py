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
    """LDL^T-like factor of K (CSR, symmetric) with a pivot test.

    `scale` (ndof,) is the reference stiffness of each DOF, the diagonal of K with the
    intact (initial) springs: a pivot is small when the DOF has lost almost all of the
    stiffness it started with, which also catches a matrix softened uniformly (whose
    pivots stay comparable to its own diagonal).
    """

    def __init__(self, K: sp.csr_matrix, pivot_tol: float, scale: np.ndarray | None = None):
        d = K.diagonal()
        if scale is None:
            scale = d
        scale = np.where(scale > 0, scale, 1.0)
        Ks = (K + sp.diags(SHIFT * scale)).tocsc()
        self.lu = spl.splu(Ks, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options=dict(SymmetricMode=True))
        piv = self.lu.U.diagonal()[self.lu.perm_c]      # pivot of original DOF i
        self.ratio = piv / scale
        self.bad = np.flatnonzero(~(self.ratio > pivot_tol))

    def solve(self, f: np.ndarray) -> np.ndarray:
        return self.lu.solve(f)

    def pcg(self, K: sp.csr_matrix, f: np.ndarray, x0: np.ndarray, rtol: float = 1e-9, maxiter: int = 40):
        """Solve a changed K (same DOFs) by conjugate gradients preconditioned with this factor.

        Secant updates soften a few springs at a time, so the old factor is a very good
        preconditioner and a handful of iterations replace a new factorisation.
        Returns None when CG does not converge (a new mechanism, or large changes).
        """
        return pcg(K, f, x0, self.lu.solve, rtol, maxiter)


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    # einsum, not BLAS ddot: threaded BLAS on a busy 2-core machine made each dot ~100x slower
    return float(np.einsum("i,i->", a, b))


def pcg(K: sp.csr_matrix, f: np.ndarray, x0: np.ndarray, precond, rtol: float, maxiter: int):
    """Preconditioned conjugate gradients; the solution, or None without convergence."""
    x = x0.copy()
    r = f - K @ x
    z = precond(r)
    p = z.copy()
    rz = _dot(r, z)
    stop = rtol * np.sqrt(_dot(f, f))
    for _ in range(maxiter):
        if np.sqrt(_dot(r, r)) <= stop:
            return x
        Kp = K @ p
        pKp = _dot(p, Kp)
        if not pKp > 0:
            return None                      # not positive definite: let the pivot test look
        alpha = rz / pKp
        x += alpha * p
        r -= alpha * Kp
        z = precond(r)
        rz_new = _dot(r, z)
        p = z + (rz_new / rz) * p
        rz = rz_new
    return x if np.sqrt(_dot(r, r)) <= stop else None


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
