"""Stiffness row sums of the moving bodies, for density scaling by body (``mass-scale ... body``).

Each sub-contact s (contact c, blocks A = ca[c], B = cb[c], normal n = cn[c], area a, stiffnesses
kn, ks) is a pair of springs between the two bodies at its point p (the linear part of the
contact law, 3DEC theory "sub-contact forces": ΔF = k·a·Δu):

    k = a (kn n nᵀ + ks (I − n nᵀ))          (3 × 3)

A point of a body with centroid C moves by G q, q = (u, θ) its six degrees of freedom and
G = [I, −[p − C]×]. The spring adds Gᵀ k G to the 6 × 6 diagonal block of each body and −G_Aᵀ k G_B
(and its transpose) between them; with R = [p − C]× (Rᵀ = −R):

    G_Aᵀ k G_B = [[k, −k R_B], [R_A k, −R_A k R_B]].

The diagonal blocks are summed per body and the coupling blocks per contact (when two bodies
share several contacts, their |coupling| rows add up: an upper bound of the assembled matrix's by
the triangle inequality, so the bound below holds); then, for each row i of a body's six, the Gershgorin row sum Σ_j |K_ij| D_j / D_i is taken over the free degrees of
freedom j (held ones, bits of ``held``, left out), with D = 1 for translations and 1/ρ for
rotations (ρ: the body's radius of gyration). D is a diagonal similarity, so the eigenvalues of
M⁻¹K stay within max_i (row sum_i / M_ii): inertial masses M_ii ≥ R_i (Δt / 2s)² give
ω_max Δt ≤ 2s, the explicit scheme is stable for s < 1 (central differences: ω Δt < 2).

All sub-contacts of a contact share n, kn and ks: k_s = a_s K₀ with K₀ = kn n nᵀ + ks (I − n nᵀ),
so a contact's blocks need only the moments of its sub-contact areas about its first
sub-contact point p₀ (A = Σ a, m1 = Σ a r, M2 = Σ a r rᵀ, r = p − p₀; ``_moments``), shifted
to the bodies' centroids in closed form (``_block``): moments about p₀, not about the origin,
keep the shift free of cancellation. Nothing per sub-contact is kept.
"""
from __future__ import annotations

import numpy as np
from numba import get_num_threads, njit, prange

from .contactmap import parallel_twin

#: the parallel twin (``body_row_sums_parallel``) from this many contacts on more than one thread
#: (``threaded``): below, the pass is over before the other threads wake up, and the serial kernel
#: alone is compiled (a cold start: a parallel kernel takes about three times as long)
PARALLEL_FROM = 40000

#: contacts or bodies per work item of the kernel's two loops (temporaries allocated per item)
CHUNK = 64


@njit(cache=True)
def body_row_sums(gid, gcen, rho, held, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area, rt, rr):
    """gid (nb,) int64 body of each block row (−1: no rigid body, treated as held); gcen (ng, 3) body
    centroids [m]; rho (ng,) > 0 radii of gyration [m]; held (ng,) int64 fixity bits (0-2
    translation, 3-5 rotation); per contact ca, cb (nc,), cn (nc, 3), kn, ks (nc,) [Pa/m]; per
    sub-contact sc_contact (ns,), sc_pos (ns, 3) [m], sc_area (ns,) [m²], the rows grouped by
    contact in contact order (as detection installs them; ValueError if not).
    Fills rt (ng,) [N/m] and rr (ng,) [N·m/rad]: the largest scaled row sum of each body's free
    translation and rotation rows (0 when it has none).

    Two loops (``prange``; each item writes only its own rows, every sum in a fixed order): over
    the contacts, the row sums of the coupling block on either side; over the bodies, the
    diagonal block from the body's contacts in contact order. The blocks come in closed form from
    the moments of each contact's sub-contact areas (``_moments``; ``_block``, ``_diag_add``). (The per-item
    code is written out in the loops: a helper taking a dozen arrays cost three times the work.)"""
    ng = gcen.shape[0]
    nc = ca.shape[0]
    cstart = np.zeros(nc + 1, dtype=np.int64)
    last = 0
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        if c < last or c >= nc:
            raise ValueError("sub-contact rows are not grouped by contact in contact order")
        last = c
        cstart[c + 1] += 1
    # the contacts of every body (CSR, in contact order); a contact inside one body is no spring
    bstart = np.zeros(ng + 1, dtype=np.int64)
    for c in range(nc):
        cstart[c + 1] += cstart[c]
        A = gid[ca[c]]
        B = gid[cb[c]]
        if A != B:
            if A >= 0:
                bstart[A + 1] += 1
            if B >= 0:
                bstart[B + 1] += 1
    # the similarity D of every body's degrees of freedom: wd[g, j] = D_j when j is free, else 0;
    # wd[g, 6 + i] = 1 / D_i (D = 1 for translations, 1/ρ for rotations)
    wd = np.empty((ng, 12))
    for g in range(ng):
        bstart[g + 1] += bstart[g]
        for j in range(6):
            wd[g, j] = 0.0 if (held[g] >> j) & 1 else (1.0 if j < 3 else 1.0 / rho[g])
            wd[g, 6 + j] = 1.0 if j < 3 else rho[g]
    blist = np.empty(bstart[ng], dtype=np.int64)
    fill = bstart[:ng].copy()
    for c in range(nc):
        A = gid[ca[c]]
        B = gid[cb[c]]
        if A != B:
            if A >= 0:
                blist[fill[A]] = c
                fill[A] += 1
            if B >= 0:
                blist[fill[B]] = c
                fill[B] += 1
    # the coupling block of every contact between two bodies: M = G_Aᵀ k G_B, its scaled row sums
    # over B's free degrees of freedom for A (off[c, :6]) and those of Mᵀ over A's for B (off[c, 6:])
    off = np.zeros((nc, 12))
    nchunk = (nc + CHUNK - 1) // CHUNK
    for t in prange(nchunk):
        mom = np.empty(13)
        dx = np.empty(3)
        dy = np.empty(3)
        p = np.empty((3, 3))
        blk = np.empty((6, 6))
        for c in range(t * CHUNK, min(nc, (t + 1) * CHUNK)):
            A = gid[ca[c]]
            B = gid[cb[c]]
            s0 = cstart[c]
            if A == B or A < 0 or B < 0 or cstart[c + 1] == s0:
                continue
            _moments(s0, cstart[c + 1], sc_pos, sc_area, mom)
            for i in range(3):
                dx[i] = sc_pos[s0, i] - gcen[A, i]
                dy[i] = sc_pos[s0, i] - gcen[B, i]
            _block(cn[c], kn[c], ks[c], mom, dx, dy, p, blk)
            for i in range(6):
                ta = 0.0
                tb = 0.0
                for j in range(6):
                    ta += abs(blk[i, j]) * wd[B, j]
                    tb += abs(blk[j, i]) * wd[A, j]
                off[c, i] = ta * wd[A, 6 + i]
                off[c, 6 + i] = tb * wd[B, 6 + i]
    # per body: the diagonal block summed over its contacts (in contact order), its scaled row sums
    # over its own free degrees of freedom, plus the coupling rows of its contacts
    nchunk = (ng + CHUNK - 1) // CHUNK
    for t in prange(nchunk):
        mom = np.empty(13)
        dx = np.empty(3)
        p = np.empty((3, 3))
        diag = np.empty((6, 6))
        orow = np.empty(6)
        for g in range(t * CHUNK, min(ng, (t + 1) * CHUNK)):
            diag[:] = 0.0
            orow[:] = 0.0
            for k in range(bstart[g], bstart[g + 1]):
                c = blist[k]
                s0 = cstart[c]
                if cstart[c + 1] == s0:
                    continue
                _moments(s0, cstart[c + 1], sc_pos, sc_area, mom)
                for i in range(3):
                    dx[i] = sc_pos[s0, i] - gcen[g, i]
                _diag_add(cn[c], kn[c], ks[c], mom, dx, p, diag)
                side = 0 if gid[ca[c]] == g else 6
                for i in range(6):
                    orow[i] += off[c, side + i]
            for i in range(6):
                for j in range(i):
                    diag[i, j] = diag[j, i]
            tmax = 0.0
            rmax = 0.0
            for i in range(6):
                if wd[g, i] == 0.0:            # held (D > 0 for a free one)
                    continue
                row = 0.0
                for j in range(6):
                    row += abs(diag[i, j]) * wd[g, j]
                row = row * wd[g, 6 + i] + orow[i]
                if i < 3:
                    tmax = max(tmax, row)
                else:
                    rmax = max(rmax, row)
            rt[g] = tmax
            rr[g] = rmax


@njit(cache=True)
def _moments(s0, s1, sc_pos, sc_area, mom):
    """mom (13,) = (A, m1, M2 row by row) of sub-contacts s0:s1 about the first one's point p₀:
    A = Σ a, m1 = Σ a r, M2 = Σ a r rᵀ with r = p − p₀."""
    for i in range(13):
        mom[i] = 0.0
    for s in range(s0, s1):
        a = sc_area[s]
        x = sc_pos[s, 0] - sc_pos[s0, 0]
        y = sc_pos[s, 1] - sc_pos[s0, 1]
        z = sc_pos[s, 2] - sc_pos[s0, 2]
        mom[0] += a
        mom[1] += a * x
        mom[2] += a * y
        mom[3] += a * z
        mom[4] += a * x * x
        mom[5] += a * x * y
        mom[6] += a * x * z
        mom[8] += a * y * y
        mom[9] += a * y * z
        mom[12] += a * z * z
    mom[7] = mom[5]
    mom[10] = mom[6]
    mom[11] = mom[9]


@njit(cache=True)
def _block(n, kn, ks, mom, dx, dy, p, out):
    """out (6, 6) = Σ_s G_Xᵀ k_s G_Y over a contact's sub-contacts (normal n, stiffnesses kn, ks
    per unit area, moments ``mom`` about p₀; dx = p₀ − C_X, dy = p₀ − C_Y):

        [[A K₀, −K₀ [u_Y]×], [[u_X]× K₀, −ks (Sᵀ − tr S I) − (kn − ks) [n]× S [n]×]]

    with K₀ = ks I + (kn − ks) n nᵀ, u = m1 + A d (the first moment about the body's centroid) and
    S = Σ a (r + dx)(r + dy)ᵀ = M2 + m1 dyᵀ + dx m1ᵀ + A dx dyᵀ, since for x, y the points' arms
    [x]×[y]× = y xᵀ − (x·y) I and [x]× n nᵀ [y]× = [n]× x yᵀ [n]×. p (3, 3): scratch."""
    A = mom[0]
    e = kn - ks
    ux0 = mom[1] + A * dx[0]
    ux1 = mom[2] + A * dx[1]
    ux2 = mom[3] + A * dx[2]
    uy0 = mom[1] + A * dy[0]
    uy1 = mom[2] + A * dy[1]
    uy2 = mom[3] + A * dy[2]
    for i in range(3):
        for j in range(3):
            k0 = e * n[i] * n[j] + (ks if i == j else 0.0)
            out[i, j] = A * k0
    # K₀ [u]× = ks [u]× + (kn − ks) n (n × u)ᵀ;  [u]× K₀ = ks [u]× + (kn − ks) (u × n) nᵀ
    cy0 = n[1] * uy2 - n[2] * uy1
    cy1 = n[2] * uy0 - n[0] * uy2
    cy2 = n[0] * uy1 - n[1] * uy0
    cx0 = ux1 * n[2] - ux2 * n[1]
    cx1 = ux2 * n[0] - ux0 * n[2]
    cx2 = ux0 * n[1] - ux1 * n[0]
    out[0, 3] = -(e * n[0] * cy0)
    out[0, 4] = -(-ks * uy2 + e * n[0] * cy1)
    out[0, 5] = -(ks * uy1 + e * n[0] * cy2)
    out[1, 3] = -(ks * uy2 + e * n[1] * cy0)
    out[1, 4] = -(e * n[1] * cy1)
    out[1, 5] = -(-ks * uy0 + e * n[1] * cy2)
    out[2, 3] = -(-ks * uy1 + e * n[2] * cy0)
    out[2, 4] = -(ks * uy0 + e * n[2] * cy1)
    out[2, 5] = -(e * n[2] * cy2)
    out[3, 0] = e * cx0 * n[0]
    out[3, 1] = -ks * ux2 + e * cx0 * n[1]
    out[3, 2] = ks * ux1 + e * cx0 * n[2]
    out[4, 0] = ks * ux2 + e * cx1 * n[0]
    out[4, 1] = e * cx1 * n[1]
    out[4, 2] = -ks * ux0 + e * cx1 * n[2]
    out[5, 0] = -ks * ux1 + e * cx2 * n[0]
    out[5, 1] = ks * ux0 + e * cx2 * n[1]
    out[5, 2] = e * cx2 * n[2]
    # S and [n]× S [n]× (P = [n]× S; (P [n]×)_ij = Σ_l P_il [n]×_lj)
    for i in range(3):
        for j in range(3):
            out[3 + i, 3 + j] = (mom[4 + 3 * i + j] + mom[1 + i] * dy[j] + dx[i] * mom[1 + j]
                                 + A * dx[i] * dy[j])          # S_ij, replaced below
    tr = out[3, 3] + out[4, 4] + out[5, 5]
    for j in range(3):
        s0 = out[3, 3 + j]
        s1 = out[4, 3 + j]
        s2 = out[5, 3 + j]
        p[0, j] = n[1] * s2 - n[2] * s1
        p[1, j] = n[2] * s0 - n[0] * s2
        p[2, j] = n[0] * s1 - n[1] * s0
    for i in range(3):
        q0 = p[i, 1] * n[2] - p[i, 2] * n[1]      # row i of P [n]×: (row i of P) × n
        q1 = p[i, 2] * n[0] - p[i, 0] * n[2]
        q2 = p[i, 0] * n[1] - p[i, 1] * n[0]
        p[i, 0] = q0
        p[i, 1] = q1
        p[i, 2] = q2
    for i in range(3):
        for j in range(i, 3):
            sij = out[3 + i, 3 + j]
            sji = out[3 + j, 3 + i]
            vij = ks * sji + e * p[i, j]
            vji = ks * sij + e * p[j, i]
            if i == j:
                vij -= ks * tr
                vji = vij
            out[3 + i, 3 + j] = -vij
            out[3 + j, 3 + i] = -vji


@njit(cache=True)
def _diag_add(n, kn, ks, mom, d, p, diag):
    """``_block`` with dx = dy = d added to diag (6, 6), on and above its diagonal only (the block
    is symmetric: [u]× K₀ = (−K₀ [u]×)ᵀ, S and [n]× S [n]× symmetric). p (3, 3): scratch."""
    A = mom[0]
    e = kn - ks
    u0 = mom[1] + A * d[0]
    u1 = mom[2] + A * d[1]
    u2 = mom[3] + A * d[2]
    for i in range(3):
        for j in range(i, 3):
            diag[i, j] += A * (e * n[i] * n[j] + (ks if i == j else 0.0))
    c0 = n[1] * u2 - n[2] * u1
    c1 = n[2] * u0 - n[0] * u2
    c2 = n[0] * u1 - n[1] * u0
    diag[0, 3] -= e * n[0] * c0
    diag[0, 4] -= -ks * u2 + e * n[0] * c1
    diag[0, 5] -= ks * u1 + e * n[0] * c2
    diag[1, 3] -= ks * u2 + e * n[1] * c0
    diag[1, 4] -= e * n[1] * c1
    diag[1, 5] -= -ks * u0 + e * n[1] * c2
    diag[2, 3] -= -ks * u1 + e * n[2] * c0
    diag[2, 4] -= ks * u0 + e * n[2] * c1
    diag[2, 5] -= e * n[2] * c2
    # S (symmetric) into p, then P = [n]× S column by column, then the upper part of P [n]×
    s00 = mom[4] + 2.0 * mom[1] * d[0] + A * d[0] * d[0]
    s01 = mom[5] + mom[1] * d[1] + d[0] * mom[2] + A * d[0] * d[1]
    s02 = mom[6] + mom[1] * d[2] + d[0] * mom[3] + A * d[0] * d[2]
    s11 = mom[8] + 2.0 * mom[2] * d[1] + A * d[1] * d[1]
    s12 = mom[9] + mom[2] * d[2] + d[1] * mom[3] + A * d[1] * d[2]
    s22 = mom[12] + 2.0 * mom[3] * d[2] + A * d[2] * d[2]
    tr = s00 + s11 + s22
    p[0, 0] = n[1] * s02 - n[2] * s01
    p[1, 0] = n[2] * s00 - n[0] * s02
    p[2, 0] = n[0] * s01 - n[1] * s00
    p[0, 1] = n[1] * s12 - n[2] * s11
    p[1, 1] = n[2] * s01 - n[0] * s12
    p[2, 1] = n[0] * s11 - n[1] * s01
    p[0, 2] = n[1] * s22 - n[2] * s12
    p[1, 2] = n[2] * s02 - n[0] * s22
    p[2, 2] = n[0] * s12 - n[1] * s02
    q00 = p[0, 1] * n[2] - p[0, 2] * n[1]
    q01 = p[0, 2] * n[0] - p[0, 0] * n[2]
    q02 = p[0, 0] * n[1] - p[0, 1] * n[0]
    q11 = p[1, 2] * n[0] - p[1, 0] * n[2]
    q12 = p[1, 0] * n[1] - p[1, 1] * n[0]
    q22 = p[2, 0] * n[1] - p[2, 1] * n[0]
    diag[3, 3] -= ks * (s00 - tr) + e * q00
    diag[3, 4] -= ks * s01 + e * q01
    diag[3, 5] -= ks * s02 + e * q02
    diag[4, 4] -= ks * (s11 - tr) + e * q11
    diag[4, 5] -= ks * s12 + e * q12
    diag[5, 5] -= ks * (s22 - tr) + e * q22


body_row_sums_parallel = parallel_twin(body_row_sums, "body_row_sums_parallel")


def threaded(nc):
    """``body_row_sums`` for a model with ``nc`` contacts: its parallel twin for ``PARALLEL_FROM``
    contacts or more on more than one thread (the same numbers: every sum in a fixed order)."""
    return body_row_sums_parallel if nc >= PARALLEL_FROM and get_num_threads() > 1 else body_row_sums
