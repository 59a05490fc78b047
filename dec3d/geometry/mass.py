"""Mass properties of blocks and geometry of faces, written into the model's stores.

Volume, centroid and the second moment come from the divergence-theorem kernel
(``dec3d.kernels.massprops``). From the second moment J = ∫(x−c)(x−c)ᵀ dV the inertia
tensor about the centroid is I = ρ (tr(J) 𝟙 − J); its eigenvalues and eigenvectors are
the principal moments and axes used by Euler's equations (3DEC theory, Eq. 45).

For quasi-static runs 3DEC uses "only an approximate moment of inertia, I, ... based upon
the average distance from the centroid to vertices of the block" (3DEC theory, Rigid
Block Motion, before Eq. 46). The text gives no formula; dec3d takes the inertia of a
solid sphere whose radius is that mean distance r̄:  I_approx = 2/5 · m · r̄².
For a cube of side a this is 0.30 m a² against the exact m a²/6: larger, which only
slows rotation in a damped static run (a safe side). Change it here and only here.

These functions read and write ``model.blocks``, ``model.vertices``, ``model.faces`` and
``model.face_vertices`` by attribute; they do not import the model package.
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.massprops import block_mass_properties, face_geometry

#: I_approx = APPROX_INERTIA_FACTOR · m · r̄² (solid sphere of radius r̄)
APPROX_INERTIA_FACTOR = 0.4


def range_index(starts: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Concatenation of ``arange(s, s + c)`` for every (s, c), as one int64 array."""
    starts = np.asarray(starts, dtype=np.int64)
    counts = np.asarray(counts, dtype=np.int64)
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, dtype=np.int64)
    offs = np.zeros(len(counts), dtype=np.int64)
    np.cumsum(counts[:-1], out=offs[1:])
    return np.repeat(starts - offs, counts) + np.arange(total, dtype=np.int64)


def principal_inertia(inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (k, 3), ascending, and axes (k, 3, 3) as columns, for (k, 3, 3) tensors.

    Axis signs are fixed (largest component positive, then a right-handed triple) so that
    the result does not depend on the eigen-solver's arbitrary sign choice.
    """
    inertia = np.asarray(inertia, dtype=np.float64)
    if inertia.shape[0] == 0:
        return np.zeros((0, 3)), np.zeros((0, 3, 3))
    sym = 0.5 * (inertia + np.swapaxes(inertia, 1, 2))
    w, v = np.linalg.eigh(sym)
    idx = np.argmax(np.abs(v), axis=1)                        # (k, 3): row of largest entry
    sign = np.sign(np.take_along_axis(v, idx[:, None, :], axis=1))[:, 0, :]
    sign[sign == 0] = 1.0
    v = v * sign[:, None, :]
    flip = np.linalg.det(v) < 0
    v[flip, :, 2] *= -1.0
    return w, v


def geometric_properties(model, rows: np.ndarray):
    """Volume (k,) m³, centroid (k, 3) m and second moment J (k, 3, 3) m⁵ of blocks ``rows``."""
    b, f = model.blocks, model.faces
    rows = np.asarray(rows, dtype=np.int64)
    vol = np.empty(len(rows))
    cen = np.empty((len(rows), 3))
    j = np.empty((len(rows), 3, 3))
    if len(rows):
        block_mass_properties(model.vertices["pos"], model.face_vertices["vertex"],
                              f["vstart"], f["nvert"], b["face_start"], b["face_count"],
                              b["vert_start"], b["vert_count"], rows, vol, cen, j)
    return vol, cen, j


def update_mass_properties(model, rows) -> None:
    """Recompute volume, centroid, mass, inertia (full, principal, approximate) of ``rows``."""
    b = model.blocks
    rows = np.asarray(rows, dtype=np.int64)
    if rows.size == 0:
        return
    vol, cen, j = geometric_properties(model, rows)
    rho = b["density"][rows]
    tr = np.trace(j, axis1=1, axis2=2)
    inertia = rho[:, None, None] * (tr[:, None, None] * np.eye(3) - j)
    mass = rho * vol
    moments, axes = principal_inertia(inertia)
    # mean centroid-to-vertex distance, block by block (vertex ranges are contiguous)
    counts = b["vert_count"][rows]
    vidx = range_index(b["vert_start"][rows], counts)
    owner = np.repeat(np.arange(len(rows)), counts)
    dist = np.linalg.norm(model.vertices["pos"][vidx] - cen[owner], axis=1)
    rbar = np.bincount(owner, weights=dist, minlength=len(rows)) / counts
    b["volume"][rows] = vol
    b["centroid"][rows] = cen
    b["mass"][rows] = mass
    b["inertia"][rows] = inertia
    b["principal_moment"][rows] = moments
    b["principal_axes"][rows] = axes
    b["inertia_approx"][rows] = APPROX_INERTIA_FACTOR * mass * rbar ** 2


def update_face_geometry(model, face_rows) -> None:
    """Recompute unit normal, area and centroid of ``face_rows``."""
    f = model.faces
    rows = np.asarray(face_rows, dtype=np.int64)
    if rows.size:
        face_geometry(model.vertices["pos"], model.face_vertices["vertex"], f["vstart"],
                      f["nvert"], rows, f["normal"], f["area"], f["centroid"])


def joined_properties(model):
    """Mass properties of each rigid body made of joined blocks (leader/follower).

    Returns (leaders (g,) rows, mass (g,) kg, centroid (g, 3) m, inertia (g, 3, 3) kg·m²
    about the group's centroid), one entry per distinct leader (free blocks included, as
    groups of one). 3DEC: "the motion calculations are only performed for the leader
    block, whose mass, moment of inertia, and centroid position are modified to represent
    the group of blocks" (Rigid Block Motion, after Eq. 52). Parallel-axis theorem:
    I = Σ [I_i + m_i (|d_i|² 𝟙 − d_i d_iᵀ)], d_i = c_i − C.
    """
    b = model.blocks
    leaders, group = np.unique(b["leader"], return_inverse=True)
    m = b["mass"]
    mass = np.bincount(group, weights=m, minlength=len(leaders))
    first = np.zeros((len(leaders), 3))
    np.add.at(first, group, m[:, None] * b["centroid"])
    safe = np.where(mass > 0, mass, 1.0)
    centroid = np.where(mass[:, None] > 0, first / safe[:, None],
                        b["centroid"][leaders])
    d = b["centroid"] - centroid[group]
    shift = m[:, None, None] * ((d * d).sum(axis=1)[:, None, None] * np.eye(3)
                                - d[:, :, None] * d[:, None, :])
    inertia = np.zeros((len(leaders), 3, 3))
    np.add.at(inertia, group, b["inertia"] + shift)
    return leaders, mass, centroid, inertia
