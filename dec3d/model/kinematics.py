"""What the blocks have moved, worked out from the stores (for VTK output and histories).

The rigid engine moves vertex positions, block centroids (and ``disp``), velocities and spins;
it keeps no orientation. Everything here is derived from those and from each vertex's
``origin`` (its position when its block was made):

- vertex displacement: pos − origin;
- vertex velocity: the rigid-body velocity at the vertex, v + ω × (x − c) of its block;
- block rotation: the rotation R of the block since it was made, the best fit (Kabsch) of its
  vertex arms now, x − x̄, to its arms at the origin, x₀ − x̄₀ (x̄: the mean of the block's
  vertices, which a rigid motion carries along). It is given as the rotation vector θ n
  (radians; n the unit axis, 0 ≤ θ ≤ π): ``rotation-x|-y|-z`` are its components and
  ``rotation`` is θ. A block spun at a constant ω about a fixed axis for a time t has turned by
  θ = |ω| t (while |ω| t ≤ π; histories continue past π, see ``unwrap_rotation``).
"""
from __future__ import annotations

import numpy as np

from dec3d.geometry.mass import range_index


def vertex_displacement(model) -> np.ndarray:
    """(nv, 3) displacement [m] of every vertex since its block was made."""
    v = model.vertices
    return v["pos"] - v["origin"]


def vertex_velocity(model) -> np.ndarray:
    """(nv, 3) rigid-body velocity [m/s] at every vertex: v + ω × (x − c) of the vertex's block."""
    v, b = model.vertices, model.blocks
    row = v["block"]
    if v.n == 0:
        return np.zeros((0, 3))
    arm = v["pos"] - b["centroid"][row]
    return b["velocity"][row] + np.cross(b["spin"][row], arm)


def rotation_from_covariance(h: np.ndarray) -> np.ndarray:
    """R = U diag(1, 1, det(U Vᵀ)) Vᵀ for H = U S Vᵀ (k, 3, 3): the proper rotation nearest H."""
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(u @ vt))
    d[d == 0] = 1.0
    fix = np.ones((h.shape[0], 3))
    fix[:, 2] = d
    return (u * fix[:, None, :]) @ vt


def block_rotation_matrices(model, rows=None) -> np.ndarray:
    """(k, 3, 3) rotation of blocks ``rows`` (all live blocks by default) since they were made."""
    b, v = model.blocks, model.vertices
    rows = np.arange(b.n) if rows is None else np.asarray(rows, dtype=np.int64)
    if rows.size == 0:
        return np.zeros((0, 3, 3))
    cnt = b["vert_count"][rows]
    vidx = range_index(b["vert_start"][rows], cnt)
    owner = np.repeat(np.arange(rows.size), cnt)
    pos, org = v["pos"][vidx], v["origin"][vidx]
    mean_p = np.zeros((rows.size, 3))
    mean_o = np.zeros((rows.size, 3))
    np.add.at(mean_p, owner, pos)
    np.add.at(mean_o, owner, org)
    mean_p /= cnt[:, None]
    mean_o /= cnt[:, None]
    arm, arm0 = pos - mean_p[owner], org - mean_o[owner]
    h = np.zeros((rows.size, 3, 3))
    np.add.at(h, owner, arm[:, :, None] * arm0[:, None, :])
    r = rotation_from_covariance(h)
    still = np.ones(rows.size, dtype=bool)            # vertices exactly where they started
    np.logical_and.at(still, owner, (pos == org).all(axis=1))
    r[still] = np.eye(3)
    return r


def rotation_vector(r: np.ndarray) -> np.ndarray:
    """(k, 3) rotation vectors θ n (0 ≤ θ ≤ π) of rotation matrices r (k, 3, 3).

    Through the unit quaternion (w ≥ 0) by Shepperd's choice of the largest of 4w², 4x², 4y², 4z²
    (S. W. Shepperd, "Quaternion from rotation matrix", J. Guidance and Control 1(3), 1978), so the
    axis stays accurate near θ = 0 and θ = π; θ = 2 atan2(|q_v|, w)."""
    k = r.shape[0]
    tr = r[:, 0, 0] + r[:, 1, 1] + r[:, 2, 2]
    cand = np.stack([tr, r[:, 0, 0], r[:, 1, 1], r[:, 2, 2]], axis=1)
    pick = np.argmax(cand, axis=1)
    q = np.zeros((k, 4))
    for j in range(4):
        m = pick == j
        if not m.any():
            continue
        rr = r[m]
        if j == 0:
            s = 2.0 * np.sqrt(1.0 + tr[m])
            q[m] = np.stack([0.25 * s, (rr[:, 2, 1] - rr[:, 1, 2]) / s, (rr[:, 0, 2] - rr[:, 2, 0]) / s,
                             (rr[:, 1, 0] - rr[:, 0, 1]) / s], axis=1)
        else:
            i1, i2, i3 = j - 1, j % 3, (j + 1) % 3
            s = 2.0 * np.sqrt(np.maximum(1.0 + rr[:, i1, i1] - rr[:, i2, i2] - rr[:, i3, i3], 0.0))
            qq = np.zeros((rr.shape[0], 4))
            qq[:, 0] = (rr[:, i3, i2] - rr[:, i2, i3]) / s
            qq[:, 1 + i1] = 0.25 * s
            qq[:, 1 + i2] = (rr[:, i2, i1] + rr[:, i1, i2]) / s
            qq[:, 1 + i3] = (rr[:, i3, i1] + rr[:, i1, i3]) / s
            q[m] = qq
    q[q[:, 0] < 0] *= -1.0
    qv = q[:, 1:]
    nv = np.linalg.norm(qv, axis=1)
    theta = 2.0 * np.arctan2(nv, q[:, 0])
    out = np.zeros((k, 3))
    ok = nv > 0
    out[ok] = qv[ok] * (theta[ok] / nv[ok])[:, None]
    return out


def block_rotation(model, rows=None) -> np.ndarray:
    """(k, 3) rotation vector [rad] of blocks ``rows`` since they were made (module docstring)."""
    return rotation_vector(block_rotation_matrices(model, rows))


def unwrap_rotation(rv: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
    """The rotation vector equivalent to ``rv`` (θ n + 2πk n, k integer) nearest ``previous``.

    A history sampled often enough thus follows a block that keeps turning past θ = π (a spin ω
    about a fixed axis gives ω t for every t), instead of jumping to the short way round."""
    rv = np.asarray(rv, dtype=float)
    if previous is None:
        return rv
    theta = float(np.linalg.norm(rv))
    if theta == 0.0:
        n = np.asarray(previous, dtype=float)
        pn = float(np.linalg.norm(n))
        if pn == 0.0:
            return rv
        n = n / pn
    else:
        n = rv / theta
    k = round((float(np.dot(previous, n)) - theta) / (2.0 * np.pi))
    return (theta + 2.0 * np.pi * k) * n
