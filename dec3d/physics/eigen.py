"""Natural modes of a rigid-block system about its current state (`block dynamic eigen modes <n>`).

Each moving body (a lone block, or joined blocks with their leader) has six degrees of freedom
q = (u, θ): the translation of its centroid c and a small rotation about it. A point p of the body
moves by u + θ × (p − c) = G(p) q with G(p) = [I, −[p − c]×] (3 × 6).

Stiffness: every closed sub-contact (normal displacement at most the model tolerance) between two
bodies A and B is a pair of springs at its point p, normal kn·a along the contact normal n and
shear ks·a across it (a: the sub-contact's area; kn, ks: its contact's stiffnesses) — the linear
part of the contact law of the 3DEC theory text (sub-contact forces ΔF = k·a·Δu). Its 3 × 3
stiffness k = a (kn n nᵀ + ks (I − n nᵀ)) acts on the relative motion G_B(p) q_B − G_A(p) q_A, so it
adds Gᵀ k G to the diagonal blocks of A and B and −G_Aᵀ k G_B (and its transpose) between them.
Sub-contacts inside one body, and those of hidden blocks, are left out.

Mass: m I₃ for the translation and the full inertia tensor about the centroid for the rotation.
Fixed velocity components (`block fix`, `block apply velocity`) remove their degree of freedom; a
fixed body still holds its springs to the free ones.

The modes solve K φ = ω² M φ (scipy.linalg.eigh for up to 600 degrees of freedom, else
scipy.sparse.linalg.eigsh in shift-invert mode just below 0). Frequencies f = ω / 2π.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dec3d.physics.jmodels import stiffness as joint_stiffness

from .contacts import default_row
from .rigid import engine, mech

DENSE_LIMIT = 600


class EigenError(ValueError):
    """The system cannot be analysed; the message says why."""


@dataclass
class Modes:
    frequencies: np.ndarray      # (k,) Hz, ascending
    omega2: np.ndarray           # (k,) rad²/s²
    shapes: np.ndarray           # (k, nbody, 6): u (m) and θ (rad) per body, mass-normalised (φᵀ M φ = 1)
    bodies: np.ndarray           # (nbody,) block row of each body's leader
    centroids: np.ndarray        # (nbody, 3)
    ndof: int                    # free degrees of freedom


def _skew(r: np.ndarray) -> np.ndarray:
    """[r]× for each row of r (k, 3) -> (k, 3, 3): [r]× v = r × v."""
    z = np.zeros(len(r))
    return np.stack([np.stack([z, -r[:, 2], r[:, 1]], -1),
                     np.stack([r[:, 2], z, -r[:, 0]], -1),
                     np.stack([-r[:, 1], r[:, 0], z], -1)], 1)


def body_properties(model):
    """(leader rows, body of each block row (-1 hidden), mass, centroid, inertia about the centroid)."""
    b = model.blocks
    live = ~b["hidden"][: b.n]
    lead = b["leader"][: b.n]
    leaders = np.unique(lead[live])
    body_of_leader = {int(r): k for k, r in enumerate(leaders)}
    body = np.array([body_of_leader.get(int(lead[r]), -1) if live[r] else -1 for r in range(b.n)], dtype=np.int64)
    nb = len(leaders)
    mass = np.zeros(nb)
    np.add.at(mass, body[live], b["mass"][: b.n][live])
    if (mass <= 0).any():
        k = int(np.flatnonzero(mass <= 0)[0])
        raise EigenError(f"block {int(b['id'][leaders[k]])} has no mass: set `block property density` first")
    cen = np.zeros((nb, 3))
    np.add.at(cen, body[live], b["mass"][: b.n][live, None] * b["centroid"][: b.n][live])
    cen /= mass[:, None]
    inertia = np.zeros((nb, 3, 3))
    for r in np.flatnonzero(live):          # parallel axes: I_c + m (|d|² I − d dᵀ)
        d = b["centroid"][r] - cen[body[r]]
        inertia[body[r]] += b["inertia"][r] + b["mass"][r] * (d @ d * np.eye(3) - np.outer(d, d))
    return leaders, body, mass, cen, inertia


def assemble(model, tol: float | None = None):
    """Sparse stiffness K and mass M (6 per body, all dofs) and the free-dof mask; see the module text."""
    from scipy import sparse

    e = engine(model)
    e.ensure_contacts()
    leaders, body, mass, cen, inertia = body_properties(model)
    nb = len(leaders)
    tol = float(model.tolerance if tol is None else tol)
    c, s = e.contacts, e.subcontacts
    prop = c["prop"].copy()
    follow = c["own_props"] == 0             # contacts that follow the defaults take them now
    for code in np.unique(c["jmodel"][follow]):
        prop[follow & (c["jmodel"] == code)] = default_row(mech(model), int(code), prop.shape[1])
    sc = np.arange(s.n)
    ci = s["contact"][sc]
    ba, bb = body[c["a"][ci]], body[c["b"][ci]]
    use = (s["un"][sc] <= tol) & (ba >= 0) & (bb >= 0) & (ba != bb) & (s["area"][sc] > 0)
    sc, ci, ba, bb = sc[use], ci[use], ba[use], bb[use]
    n = c["normal"][ci]
    a = s["area"][sc]
    kn, ks = (k[sc] * a for k in joint_stiffness(c, s, prop))
    nn = n[:, :, None] * n[:, None, :]
    k3 = kn[:, None, None] * nn + ks[:, None, None] * (np.eye(3) - nn)
    p = s["pos"][sc]
    ga = np.concatenate([np.broadcast_to(np.eye(3), (len(sc), 3, 3)), -_skew(p - cen[ba])], axis=2)
    gb = np.concatenate([np.broadcast_to(np.eye(3), (len(sc), 3, 3)), -_skew(p - cen[bb])], axis=2)
    rows, cols, vals = [], [], []

    def add(bi, bj, mat):            # mat (k, 6, 6) into body blocks (bi, bj)
        i = (6 * bi)[:, None, None] + np.arange(6)[None, :, None]
        j = (6 * bj)[:, None, None] + np.arange(6)[None, None, :]
        rows.append(np.broadcast_to(i, mat.shape).ravel())
        cols.append(np.broadcast_to(j, mat.shape).ravel())
        vals.append(mat.ravel())
    gat, gbt = np.swapaxes(ga, 1, 2), np.swapaxes(gb, 1, 2)
    add(ba, ba, gat @ k3 @ ga)
    add(bb, bb, gbt @ k3 @ gb)
    add(ba, bb, -(gat @ k3 @ gb))
    add(bb, ba, -(gbt @ k3 @ ga))
    ndof = 6 * nb
    if rows:
        K = sparse.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                              shape=(ndof, ndof)).tocsr()
    else:
        K = sparse.csr_matrix((ndof, ndof))
    mblk = np.zeros((nb, 6, 6))
    mblk[:, :3, :3] = mass[:, None, None] * np.eye(3)
    mblk[:, 3:, 3:] = inertia
    M = sparse.block_diag(list(mblk), format="csr") if nb else sparse.csr_matrix((0, 0))
    b = model.blocks
    fix = (b["fixity"][leaders] | b["apply_fix"][leaders]).astype(np.int64)
    free = ((fix[:, None] >> np.arange(6)[None, :]) & 1) == 0
    return K, M, free.ravel(), leaders, cen


def eigenmodes(model, nmodes: int) -> Modes:
    """The ``nmodes`` lowest natural modes of the rigid-block system about its current state."""
    from scipy import linalg, sparse
    from scipy.sparse.linalg import eigsh

    from dec3d.model.zones import has_zones

    if model.blocks.n == 0:
        raise EigenError("there are no blocks")
    if has_zones(model):
        raise EigenError("the model has zoned (deformable) blocks: eigenmodes are worked out for rigid "
                         "blocks only")
    K, M, free, leaders, cen = assemble(model)
    idx = np.flatnonzero(free)
    nf = idx.size
    if nf == 0:
        raise EigenError("every degree of freedom is fixed: there is nothing to vibrate")
    if nmodes > nf:
        raise EigenError(f"{nmodes} modes asked for, but the free blocks have only {nf} degrees of freedom")
    Kf = K[idx][:, idx]
    Mf = M[idx][:, idx]
    if nf <= DENSE_LIMIT or nmodes >= nf - 1:      # eigsh needs k < n - 1
        w2, vec = linalg.eigh(Kf.toarray(), Mf.toarray(), subset_by_index=[0, nmodes - 1])
    else:
        scale = float(np.mean(Kf.diagonal() / Mf.diagonal()))
        sigma = -1e-6 * scale if scale > 0 else -1.0
        w2, vec = eigsh(sparse.csc_matrix(Kf), k=nmodes, M=sparse.csc_matrix(Mf), sigma=sigma, which="LM")
        order = np.argsort(w2)
        w2, vec = w2[order], vec[:, order]
    if not (np.all(np.isfinite(w2)) and np.all(np.isfinite(vec))):
        raise EigenError("the eigensolver gave values that are not finite")
    # round-off can leave a rigid-body (zero) mode slightly negative
    w2 = np.where(w2 < 0, 0.0, w2)
    # a fixed sign per mode, so runs and platforms agree: the largest component positive
    big = np.argmax(np.abs(vec), axis=0)
    vec = vec * np.sign(vec[big, np.arange(vec.shape[1])])[None, :]
    shapes = np.zeros((nmodes, len(leaders) * 6))
    shapes[:, idx] = vec.T
    return Modes(np.sqrt(w2) / (2.0 * np.pi), w2, shapes.reshape(nmodes, len(leaders), 6), leaders, cen, nf)


def vertex_mode_displacement(model, modes: Modes, k: int) -> np.ndarray:
    """(nvertex, 3) displacement of every vertex in mode ``k`` (0-based): u + θ × (x − c) of its body;
    zero for hidden blocks. Scaled so the largest vertex displacement is 1."""
    v = model.vertices
    _, body, _, _, _ = body_properties(model)
    out = np.zeros((v.n, 3))
    vb = body[v["block"][: v.n]]
    ok = vb >= 0
    q = modes.shapes[k][vb[ok]]
    r = v["pos"][: v.n][ok] - modes.centroids[vb[ok]]
    out[ok] = q[:, :3] + np.cross(q[:, 3:], r)
    big = float(np.abs(out).max()) if out.size else 0.0
    return out / big if big > 0 else out
