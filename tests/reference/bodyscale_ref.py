"""Slow twin of ``dec3d.kernels.bodyscale.body_row_sums``: the whole stiffness matrix of the free
bodies assembled densely, spring by spring, then Gershgorin row sums (plain numpy, loops)."""
import numpy as np


def cross_matrix(r):
    """The matrix X with X v = r × v."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def dense_stiffness(gid, gcen, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area):
    """(6 ng, 6 ng) stiffness of the bodies: each sub-contact two springs (normal kn·a along n,
    shear ks·a across) between the points p of bodies A and B; a body's point moves by
    u + θ × (p − c). Blocks that are no body (gid −1) are held fast."""
    ng = len(gcen)
    K = np.zeros((6 * ng, 6 * ng))
    for s in range(len(sc_contact)):
        c = sc_contact[s]
        bodies = (gid[ca[c]], gid[cb[c]])
        if bodies[0] == bodies[1]:
            continue
        n = np.asarray(cn[c], float)
        k = sc_area[s] * (kn[c] * np.outer(n, n) + ks[c] * (np.eye(3) - np.outer(n, n)))
        # relative motion at p: Σ_side sign · J_side q_side, J = [I, −X(p − c)]
        J = {}
        for sign, g in zip((-1.0, 1.0), bodies):
            if g >= 0:
                J[g] = sign * np.hstack((np.eye(3), -cross_matrix(sc_pos[s] - gcen[g])))
        for gi, Ji in J.items():
            for gj, Jj in J.items():
                K[6 * gi:6 * gi + 6, 6 * gj:6 * gj + 6] += Ji.T @ k @ Jj
    return K


def row_sums_ref(gid, gcen, rho, held, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area):
    """(Rt, Rr): per body the largest of Σ_j |K_ij| d_j / d_i over its free translation rows and
    over its free rotation rows (d = 1 for translation, 1/ρ for rotation; held columns skipped)."""
    ng = len(gcen)
    K = dense_stiffness(gid, gcen, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area)
    d = np.ones(6 * ng)
    free = np.ones(6 * ng, bool)
    for g in range(ng):
        d[6 * g + 3:6 * g + 6] = 1.0 / rho[g]
        for j in range(6):
            free[6 * g + j] = not (int(held[g]) >> j) & 1
    rt = np.zeros(ng)
    rr = np.zeros(ng)
    for i in range(6 * ng):
        if not free[i]:
            continue
        total = sum(abs(K[i, j]) * d[j] for j in range(6 * ng) if free[j]) / d[i]
        g, local = divmod(i, 6)
        if local < 3:
            rt[g] = max(rt[g], total)
        else:
            rr[g] = max(rr[g], total)
    return rt, rr
