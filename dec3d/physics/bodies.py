"""Host-side preparation of the moving bodies for the motion kernel (``kernels.motion``):
composite properties of joined blocks and the inertial masses of density scaling (the damping
state is ``kernels.bundles.Damping``). Plain numpy, run once per ``model cycle``/detection.
"""
from __future__ import annotations

import numpy as np


def group_properties(gstart, gmember, mass, centroid, inertia, inertia_approx, prin=None, axes=None):
    """Composite properties of groups of joined blocks.

    gstart (ng+1,) int64 CSR into gmember (int64 block rows); mass (nb,) kg; centroid (nb, 3) m;
    inertia (nb, 3, 3) kg·m² full tensor of each block about its own centroid; inertia_approx (nb,)
    kg·m² the scalar approximate inertia of each block (3DEC's average-distance value).
    Returns (gmass (ng,), gcentroid (ng, 3), ginertia (ng, 3, 3) about the group centroid by the
    parallel-axis theorem I_C = Σ [I_b + m_b (|d|² E − d dᵀ)], d = c_b − C; gprin (ng, 3)
    principal moments ascending; gaxes (ng, 3, 3) principal axes as columns, right-handed;
    giscalar (ng,) = Σ [I_approx,b + m_b |d|²]). A group of one keeps its block's centroid exactly,
    and with ``prin`` (nb, 3) / ``axes`` (nb, 3, 3), the blocks' own principal moments and axes
    (so that a block's orientation passes from run to run without the round-off of an eigh).
    """
    gstart = np.asarray(gstart, np.int64)
    gmember = np.asarray(gmember, np.int64)
    mass = np.asarray(mass, np.float64)
    centroid = np.asarray(centroid, np.float64)
    ng = gstart.shape[0] - 1
    cnt = np.diff(gstart)
    gid = np.repeat(np.arange(ng), cnt)
    m = mass[gmember]
    c = centroid[gmember]
    gmass = np.bincount(gid, m, minlength=ng)
    gc = np.empty((ng, 3))
    for k in range(3):
        gc[:, k] = np.bincount(gid, m * c[:, k], minlength=ng) / np.where(gmass > 0, gmass, 1.0)
    one = cnt == 1
    gc[one] = centroid[gmember[gstart[:-1][one]]]
    d = c - gc[gid]
    d2 = (d * d).sum(1)
    ib = np.asarray(inertia, np.float64)[gmember] + m[:, None, None] * (
        d2[:, None, None] * np.eye(3) - d[:, :, None] * d[:, None, :])
    ginertia = np.zeros((ng, 3, 3))
    np.add.at(ginertia, gid, ib)
    giscalar = np.bincount(gid, np.asarray(inertia_approx, np.float64)[gmember] + m * d2, minlength=ng)
    ginertia = 0.5 * (ginertia + ginertia.transpose(0, 2, 1))
    # (the eigen-decomposition only where the blocks' own frames are not taken: it is most of
    # the time of a model of lone blocks, and of the serial part of a short run on two cores)
    own = one if (prin is not None and axes is not None) else np.zeros(ng, bool)
    gprin = np.empty((ng, 3))
    gaxes = np.empty((ng, 3, 3))
    if not own.all():
        p, a = np.linalg.eigh(ginertia[~own])
        a[np.linalg.det(a) < 0, :, 2] *= -1.0
        gprin[~own], gaxes[~own] = p, a
    if own.any():
        lone = gmember[gstart[:-1][own]]
        gprin[own], gaxes[own] = np.asarray(prin)[lone], np.asarray(axes)[lone]
    return gmass, gc, ginertia, gprin, np.ascontiguousarray(gaxes), giscalar


def inertial_masses(mass, iscalar, kblock, dt, frac):
    """Density scaling (3DEC theory "Mass (Density) Scaling", Eq. 87).

    mass (n,) kg real (gravitational) masses; iscalar (n,) kg·m² scalar inertias; kblock (n,) N/m
    the stiffness sum of each group (sum over its contacts of the larger of k_n A, k_s A); dt the
    wanted step [s]; frac the Eq. 87 factor (0.1). Returns (imass, iscalar_scaled) with
    imass = max(mass, kblock (dt / (2 frac))²), so that frac·2·sqrt(imass / kblock) ≥ dt (equal
    where scaled), and iscalar_scaled = iscalar · imass / mass.
    """
    mass = np.asarray(mass, np.float64)
    need = np.asarray(kblock, np.float64) * (dt / (2.0 * frac)) ** 2
    imass = np.maximum(mass, need)
    return imass, np.asarray(iscalar, np.float64) * (imass / mass)
