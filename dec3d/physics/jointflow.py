"""Flow in the joints, steady state (`block fluid solve-steady`, ``physics.flownet``).

The network (``kernels.jointflow``: knots with pressure boundaries and inflows, pipes with the cubic-law
conductance) at steady state: Σ_k c_k (p_i − p_j) = q_in_i at every unfixed knot, p held at the fixed ones.
Assembled as the weighted graph Laplacian L = Σ_k c_k (e_a − e_b)(e_a − e_b)ᵀ (scipy.sparse), reduced to
the unfixed knots and solved directly (``scipy.sparse.linalg.spsolve``). Also the cubic-law conductance and
3DEC's hydraulic aperture from the mechanical one.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve


def hydraulic_aperture(un, azero: float, ares: float, amax: float) -> np.ndarray:
    """a = azero + un (un the joint's normal displacement, opening positive), kept within [ares, amax]
    (3DEC's aperture at zero normal stress, residual and maximum apertures)."""
    if not (0.0 <= ares <= amax) or azero < 0.0:
        raise ValueError("apertures must satisfy 0 ≤ aperture-minimum ≤ aperture-maximum and aperture-initial ≥ 0")
    return np.clip(azero + np.asarray(un, dtype=float), ares, amax)


def conductance(a, width, length, viscosity: float) -> np.ndarray:
    """The cubic law: c = a³ w / (12 μ L) [m³/(s·Pa)]."""
    if not viscosity > 0.0:
        raise ValueError("the viscosity must be > 0")
    a = np.asarray(a, dtype=float)
    if np.any(a < 0.0):
        raise ValueError("an aperture is negative")
    return a ** 3 * np.asarray(width, dtype=float) / (12.0 * viscosity * np.asarray(length, dtype=float))


def steady(nk: int, pa, pb, c, fixed, p_fixed, q_in=None, dg=None):
    """Steady pressures (nk,) [Pa] and pipe flows [m³/s] (from pa to pb). ``fixed`` (nk,) bool, ``p_fixed``
    the pressures there; ``q_in`` (nk,) inflows at the others (default none); ``dg`` (npipe,) the gravity term
    of each pipe (Q = c (p_a − p_b + dg), ``kernels.jointflow.network_steps``; default none). A part of the
    network with no fixed knot makes the system singular: refused."""
    pa = np.asarray(pa, dtype=np.int64)
    pb = np.asarray(pb, dtype=np.int64)
    c = np.asarray(c, dtype=float)
    fixed = np.asarray(fixed, dtype=bool)
    p = np.where(fixed, np.asarray(p_fixed, dtype=float), 0.0)
    q = np.zeros(nk) if q_in is None else np.array(q_in, dtype=float)
    g = np.zeros(len(c)) if dg is None else np.asarray(dg, dtype=float)
    if dg is not None:
        np.add.at(q, pa, -c * g)
        np.add.at(q, pb, c * g)
    if not fixed.any():
        raise ValueError("the network has no pressure boundary")
    rows = np.concatenate((pa, pb, pa, pb))
    cols = np.concatenate((pa, pb, pb, pa))
    vals = np.concatenate((c, c, -c, -c))
    lap = sp.csr_matrix((vals, (rows, cols)), shape=(nk, nk))
    free = np.flatnonzero(~fixed)
    if free.size:
        a_ff = lap[free][:, free].tocsc()
        rhs = q[free] - lap[free][:, np.flatnonzero(fixed)] @ p[fixed]
        with np.errstate(all="ignore"):
            x = spsolve(a_ff, rhs)
        if not np.all(np.isfinite(x)):
            raise ValueError("a part of the network has no pressure boundary")
        p[free] = x
    return p, c * (p[pa] - p[pb] + g)
