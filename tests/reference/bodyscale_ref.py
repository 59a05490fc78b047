"""Slow twin of ``dec3d.kernels.bodyscale.body_row_sums``: spring by spring (one per sub-contact),
the 6 × 6 blocks of the bodies' stiffness matrix, then Gershgorin row sums (plain numpy, loops).

``row_sums_ref`` is the kernel's definition: diagonal blocks summed per body, coupling blocks
kept per contact (two contacts between the same two bodies add their |K_ij|). ``row_sums_assembled``
takes the row sums of the assembled matrix (``dense_stiffness``): the same where no two contacts
join the same pair of bodies, never more otherwise."""
import numpy as np


def cross_matrix(r):
    """The matrix X with X v = r × v."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def _springs(gid, gcen, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area):
    """Per sub-contact between two different bodies: (contact, {body: J}, k). k: the 3 × 3
    stiffness a (kn n nᵀ + ks (I − n nᵀ)); J (3 × 6): the motion of the point p as the body
    moves, with the sign of its side (−1 for A, +1 for B): u + θ × (p − c) = [I, −X(p − c)] q.
    Blocks that are no body (gid −1) are held fast: no J."""
    out = []
    for s in range(len(sc_contact)):
        c = int(sc_contact[s])
        bodies = (int(gid[ca[c]]), int(gid[cb[c]]))
        if bodies[0] == bodies[1]:
            continue
        n = np.asarray(cn[c], float)
        k = sc_area[s] * (kn[c] * np.outer(n, n) + ks[c] * (np.eye(3) - np.outer(n, n)))
        J = {}
        for sign, g in zip((-1.0, 1.0), bodies):
            if g >= 0:
                J[g] = sign * np.hstack((np.eye(3), -cross_matrix(np.asarray(sc_pos[s], float) - gcen[g])))
        out.append((c, J, k))
    return out


def dense_stiffness(gid, gcen, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area):
    """(6 ng, 6 ng) stiffness of the bodies: each sub-contact two springs (normal kn·a along n,
    shear ks·a across) between the points p of bodies A and B."""
    ng = len(gcen)
    K = np.zeros((6 * ng, 6 * ng))
    for _, J, k in _springs(gid, gcen, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area):
        for gi, Ji in J.items():
            for gj, Jj in J.items():
                K[6 * gi:6 * gi + 6, 6 * gj:6 * gj + 6] += Ji.T @ k @ Jj
    return K


def _scales(rho, held):
    """d (ng, 6): 1 for translation, 1/ρ for rotation; free (ng, 6): not a held bit."""
    ng = len(rho)
    d = np.ones((ng, 6))
    free = np.ones((ng, 6), bool)
    for g in range(ng):
        d[g, 3:] = 1.0 / rho[g]
        for j in range(6):
            free[g, j] = not (int(held[g]) >> j) & 1
    return d, free


def _largest(rows, free):
    """(Rt, Rr) from the row sums (ng, 6): the largest over the free translation / rotation rows."""
    rt = np.array([max([rows[g, i] for i in range(3) if free[g, i]], default=0.0) for g in range(len(rows))])
    rr = np.array([max([rows[g, i] for i in range(3, 6) if free[g, i]], default=0.0) for g in range(len(rows))])
    return rt, rr


def row_sums_ref(gid, gcen, rho, held, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area):
    """(Rt, Rr): per body the largest of Σ_j |K_ij| d_j / d_i over its free translation rows and
    over its free rotation rows (d = 1 for translation, 1/ρ for rotation; held columns skipped),
    K_ij over the body's own block and each of its contacts' coupling blocks apart."""
    ng = len(gcen)
    d, free = _scales(rho, held)
    diag = np.zeros((ng, 6, 6))
    coupling = {}                                  # (contact, body, other body): 6 × 6
    for c, J, k in _springs(gid, gcen, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area):
        for gi, Ji in J.items():
            diag[gi] += Ji.T @ k @ Ji
            for gj, Jj in J.items():
                if gj != gi:
                    coupling[c, gi, gj] = coupling.get((c, gi, gj), np.zeros((6, 6))) + Ji.T @ k @ Jj
    rows = np.zeros((ng, 6))
    for g in range(ng):
        for i in range(6):
            rows[g, i] = sum(abs(diag[g, i, j]) * d[g, j] for j in range(6) if free[g, j]) / d[g, i]
    for (c, g, h), M in coupling.items():
        for i in range(6):
            rows[g, i] += sum(abs(M[i, j]) * d[h, j] for j in range(6) if free[h, j]) / d[g, i]
    return _largest(rows, free)


def row_sums_assembled(gid, gcen, rho, held, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area):
    """(Rt, Rr) as ``row_sums_ref`` but from the assembled matrix (``dense_stiffness``)."""
    ng = len(gcen)
    K = dense_stiffness(gid, gcen, ca, cb, cn, kn, ks, sc_contact, sc_pos, sc_area)
    d, free = _scales(rho, held)
    d, free = d.ravel(), free.ravel()
    rows = np.zeros(6 * ng)
    for i in range(6 * ng):
        rows[i] = sum(abs(K[i, j]) * d[j] for j in range(6 * ng) if free[j]) / d[i]
    return _largest(rows.reshape(ng, 6), free.reshape(ng, 6))
