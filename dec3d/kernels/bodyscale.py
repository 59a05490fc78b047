"""Stiffness row sums of the moving bodies, for density scaling by body (``mass-scale ... body``).

Each sub-contact s (contact c, blocks A = ca[c], B = cb[c], normal n = cn[c], area a, stiffnesses
kn, ks) is a pair of springs between the two bodies at its point p (the linear part of the
contact law, 3DEC theory "sub-contact forces": ΔF = k·a·Δu):

    k = a (kn n nᵀ + ks (I − n nᵀ))          (3 × 3)

A point of a body with centroid C moves by G q, q = (u, θ) its six degrees of freedom and
G = [I, −[p − C]×]. The spring adds Gᵀ k G to the 6 × 6 diagonal block of each body and −G_Aᵀ k G_B
(and its transpose) between them; with R = [p − C]× (Rᵀ = −R):

    G_Aᵀ k G_B = [[k, −k R_B], [R_A k, −R_A k R_B]].

The diagonal blocks are summed per body and the coupling blocks per contact; then, for each
row i of a body's six, the Gershgorin row sum Σ_j |K_ij| D_j / D_i is taken over the free degrees of
freedom j (held ones, bits of ``held``, left out), with D = 1 for translations and 1/ρ for
rotations (ρ: the body's radius of gyration). D is a diagonal similarity, so the eigenvalues of
M⁻¹K stay within max_i (row sum_i / M_ii): inertial masses M_ii ≥ R_i (Δt / 2s)² give
ω_max Δt ≤ 2s, the explicit scheme is stable for s < 1 (central differences: ω Δt < 2).
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def body_row_sums(gid, gcen, rho, held, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area, rt, rr):
    """gid (nb,) int64 body of each block row (−1: no rigid body, treated as held); gcen (ng, 3) body
    centroids [m]; rho (ng,) > 0 radii of gyration [m]; held (ng,) int64 fixity bits (0-2
    translation, 3-5 rotation); per contact ca, cb (nc,), cn (nc, 3), kn, ks (nc,) [Pa/m]; per
    sub-contact sc_contact (ns,), sc_pos (ns, 3) [m], sc_area (ns,) [m²].
    Fills rt (ng,) [N/m] and rr (ng,) [N·m/rad]: the largest scaled row sum of each body's free
    translation and rotation rows (0 when it has none)."""
    ng = gcen.shape[0]
    nc = ca.shape[0]
    diag = np.zeros((ng, 6, 6))
    off = np.zeros((nc, 6, 6))
    pa = np.full(nc, -1, dtype=np.int64)
    pb = np.full(nc, -1, dtype=np.int64)
    k = np.empty((3, 3))
    ra = np.empty((3, 3))
    rb = np.empty((3, 3))
    m = np.empty((6, 6))
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        A = gid[ca[c]]
        B = gid[cb[c]]
        if A == B:
            continue
        pa[c] = A
        pb[c] = B
        a = sc_area[s]
        for i in range(3):
            for j in range(3):
                k[i, j] = a * (kn[c] - ks[c]) * cn[c, i] * cn[c, j]
            k[i, i] += a * ks[c]
        for side in range(2):
            body = A if side == 0 else B
            if body < 0:
                continue
            _skew(sc_pos[s, 0] - gcen[body, 0], sc_pos[s, 1] - gcen[body, 1], sc_pos[s, 2] - gcen[body, 2], ra)
            _gtkg(k, ra, ra, m)
            for i in range(6):
                for j in range(6):
                    diag[body, i, j] += m[i, j]
        if A >= 0 and B >= 0:
            _skew(sc_pos[s, 0] - gcen[A, 0], sc_pos[s, 1] - gcen[A, 1], sc_pos[s, 2] - gcen[A, 2], ra)
            _skew(sc_pos[s, 0] - gcen[B, 0], sc_pos[s, 1] - gcen[B, 1], sc_pos[s, 2] - gcen[B, 2], rb)
            _gtkg(k, ra, rb, m)
            for i in range(6):
                for j in range(6):
                    off[c, i, j] -= m[i, j]
    row = np.zeros((ng, 6))
    for g in range(ng):
        for i in range(6):
            t = 0.0
            for j in range(6):
                if not (held[g] >> j) & 1:
                    t += abs(diag[g, i, j]) * _d(rho[g], j)
            row[g, i] = t / _d(rho[g], i)
    for c in range(nc):
        A = pa[c]
        B = pb[c]
        if A < 0 or B < 0:
            continue
        for i in range(6):
            ta = 0.0
            tb = 0.0
            for j in range(6):
                if not (held[B] >> j) & 1:
                    ta += abs(off[c, i, j]) * _d(rho[B], j)
                if not (held[A] >> j) & 1:
                    tb += abs(off[c, j, i]) * _d(rho[A], j)
            row[A, i] += ta / _d(rho[A], i)
            row[B, i] += tb / _d(rho[B], i)
    for g in range(ng):
        t = 0.0
        r = 0.0
        for i in range(3):
            if not (held[g] >> i) & 1:
                t = max(t, row[g, i])
            if not (held[g] >> (3 + i)) & 1:
                r = max(r, row[g, 3 + i])
        rt[g] = t
        rr[g] = r


@njit(cache=True)
def _d(rho, j):
    """The similarity D of degree of freedom j (0-2 translation: 1, 3-5 rotation: 1/ρ)."""
    return 1.0 if j < 3 else 1.0 / rho


@njit(cache=True)
def _skew(x, y, z, out):
    """out = [r]× (out @ v = r × v)."""
    out[0, 0] = 0.0
    out[0, 1] = -z
    out[0, 2] = y
    out[1, 0] = z
    out[1, 1] = 0.0
    out[1, 2] = -x
    out[2, 0] = -y
    out[2, 1] = x
    out[2, 2] = 0.0


@njit(cache=True)
def _gtkg(k, ra, rb, out):
    """out = G_Aᵀ k G_B = [[k, −k R_B], [R_A k, −R_A k R_B]] (6 × 6)."""
    for i in range(3):
        for j in range(3):
            krb = 0.0
            rak = 0.0
            for l in range(3):
                krb += k[i, l] * rb[l, j]
                rak += ra[i, l] * k[l, j]
            out[i, j] = k[i, j]
            out[i, 3 + j] = -krb
            out[3 + i, j] = rak
    for i in range(3):
        for j in range(3):
            t = 0.0
            for l in range(3):
                t += ra[i, l] * (k[l, 0] * rb[0, j] + k[l, 1] * rb[1, j] + k[l, 2] * rb[2, j])
            out[3 + i, 3 + j] = -t
