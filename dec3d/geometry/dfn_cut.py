"""``block cut dfn``: cut blocks by the disk fractures of a DFN.

3DEC's rule (block cut command page: "Blocks are split completely (i.e., no partial cracks are
allowed) … A cut will be made from each fracture in the DFN, but be aware that the generated joints
will generally be larger than the actual fractures"): a block that a disk touches is cut through by
the disk's whole plane; a block the disk does not reach is not cut. So a block partly crossed by a
disk (the disk's rim inside the block) is still split completely.

A disk touches a convex block when the block has vertices strictly on both sides of the disk's plane
(beyond the tolerance) and the block's section by that plane — the convex polygon of the points where
the block's edges cross the plane — comes within the disk's radius of the disk's centre (the centre
inside the polygon, or closer than r to one of its sides).

Fractures are taken in order (of their rows: the order of generation). Each cut reuses
``cutting.cut_by_planes`` (the kernel ``polycut.cut_blocks``: exact convex pieces, a plane within the
tolerance of a corner passes through it, so no sliver thinner than the tolerance and no zero-volume
piece). Candidate blocks of a disk come from an axis-aligned box prefilter: the disk's extent along
axis k is r √(1 − n_k²); the blocks' boxes are kept up to date for the rows each cut changes.

The new faces each disk makes are recorded in two face fields (added on first use, saved with the
model): ``jointset`` (the joint-set id given to the cut; default the DFN id) and ``fracture`` (the
fracture id). Pieces of those faces cut later keep them. The contact range element
``jointset-id`` selects the contacts lying on faces of a joint set.
"""
from __future__ import annotations

import math

import numpy as np

from .assemble import compact_geometry
from .cutting import _selection, cut_by_planes
from .mass import range_index

_F = np.float64


def _block_boxes(model, rows):
    b = model.blocks
    st, cnt = b["vert_start"][rows], b["vert_count"][rows]
    pos = model.vertices["pos"][range_index(st, cnt)]
    offs = np.concatenate(([0], np.cumsum(cnt)[:-1])).astype(np.int64)
    return np.minimum.reduceat(pos, offs, axis=0), np.maximum.reduceat(pos, offs, axis=0)


def disk_touches_block(model, row: int, c, n, r: float, tol: float) -> bool:
    """Whether the disk (c, n, r) meets block ``row`` so that its plane splits it (see the module)."""
    b, f, fv = model.blocks, model.faces, model.face_vertices
    vs, vc = int(b["vert_start"][row]), int(b["vert_count"][row])
    pos = model.vertices["pos"][vs:vs + vc]
    s = (pos - c) @ n
    if not (s.min() < -tol and s.max() > tol):
        return False
    fs, fc = int(b["face_start"][row]), int(b["face_count"][row])
    nv = f["nvert"][fs:fs + fc]
    st = f["vstart"][fs:fs + fc]
    loops = fv["vertex"][range_index(st, nv)] - vs
    # next vertex of each loop entry (closing each loop)
    ptr = np.concatenate(([0], np.cumsum(nv))).astype(np.int64)
    nxt = np.arange(len(loops)) + 1
    nxt[ptr[1:] - 1] = ptr[:-1]
    a, bb = loops, loops[nxt]
    sa, sb = s[a], s[bb]
    cross = (sa < 0) != (sb < 0)
    if not cross.any():
        return False
    t = sa[cross] / (sa[cross] - sb[cross])
    p = pos[a[cross]] + t[:, None] * (pos[bb[cross]] - pos[a[cross]]) - c
    nx, ny, nz = float(n[0]), float(n[1]), float(n[2])
    u = np.array([-ny, nx, 0.0]) if abs(nz) < 0.9 else np.array([0.0, -nz, ny])   # (0,0,1)×n or (1,0,0)×n
    u /= math.sqrt(u @ u)
    w = np.array([ny * u[2] - nz * u[1], nz * u[0] - nx * u[2], nx * u[1] - ny * u[0]])
    q = np.column_stack([p @ u, p @ w])
    if (np.einsum("ij,ij->i", q, q) <= r * r).any():
        return True
    m = q.mean(axis=0)
    ang = np.arctan2(q[:, 1] - m[1], q[:, 0] - m[0])
    q = q[np.argsort(ang, kind="stable")]
    e0, e1 = q, np.roll(q, -1, axis=0)
    d = e1 - e0
    crs = d[:, 0] * (-e0[:, 1]) - d[:, 1] * (-e0[:, 0])
    if (crs >= -1e-15).all() or (crs <= 1e-15).all():
        return True                                    # the centre is inside the section
    dd = np.einsum("ij,ij->i", d, d)
    tt = np.clip(np.where(dd > 0, -np.einsum("ij,ij->i", e0, d) / np.where(dd > 0, dd, 1), 0), 0, 1)
    close = e0 + tt[:, None] * d
    return bool((np.einsum("ij,ij->i", close, close) <= r * r).any())


class TooManyBlocks(ValueError):
    """The cut made more blocks than the caller allowed (``max_blocks``); the model is part cut."""

    def __init__(self, done: int, blocks: int):
        super().__init__(f"{blocks} blocks after {done} disks")
        self.done, self.blocks = done, blocks


#: a cut that would leave a piece thinner than this fraction of the block's extent along the
#: disk's normal is not made (the would-be sliver stays with its block); counted as skipped
SLIVER = 1e-2


def _prefilter(model, cand, c, n, r, tol):
    """Of the candidate blocks, (sure: the disk touches them for certain, maybe: test exactly,
    slivers: touched blocks left uncut because a piece would be a sliver)."""
    b = model.blocks
    st, cnt = b["vert_start"][cand], b["vert_count"][cand]
    pos = model.vertices["pos"][range_index(st, cnt)]
    offs = np.concatenate(([0], np.cumsum(cnt)[:-1])).astype(np.int64)
    rel = pos - c
    sv = rel @ n
    ax2 = np.einsum("ij,ij->i", rel, rel) - sv * sv            # squared distance from the disk's axis
    smin, smax = np.minimum.reduceat(sv, offs), np.maximum.reduceat(sv, offs)
    straddle = (smin < -tol) & (smax > tol)
    thin = straddle & (np.minimum(-smin, smax) < SLIVER * (smax - smin))
    ok = straddle & ~thin
    sure = ok & (np.maximum.reduceat(ax2, offs) <= r * r)
    # the section lies in the block's bounding ball about its centroid: too far from the disk → no
    cen = b["centroid"][cand]
    d = cen - c
    h = d @ n
    inplane = np.sqrt(np.clip(np.einsum("ij,ij->i", d, d) - h * h, 0, None))
    rad2 = np.maximum.reduceat(np.einsum("ij,ij->i", pos - np.repeat(cen, cnt, axis=0),
                                         pos - np.repeat(cen, cnt, axis=0)), offs)
    far = inplane > r + np.sqrt(np.clip(rad2 - h * h, 0, None)) + tol
    maybe = ok & ~sure & ~far
    return cand[sure], cand[maybe], cand[thin]


def cut_dfn(model, centers, normals, radii, frac_ids, jointset: int, mask=None,
            join: bool = False, max_blocks: int | None = None, keep_whole=None) -> tuple[int, int, int]:
    """Cut the visible blocks in ``mask`` by the disks in order. Returns (new blocks, disks that cut,
    cuts skipped as slivers). The faces store must hold the int64 fields ``jointset`` and ``fracture``
    (``dec3d.model.fractures.ensure_face_fields``). More than ``max_blocks`` blocks raises
    ``TooManyBlocks`` at once, and a disk that would split a block of ``keep_whole`` (``cutting.cut_by_planes``)
    ``GeometryError`` (the caller puts the model back after either)."""
    centers, normals, radii = np.asarray(centers, _F), np.asarray(normals, _F), np.asarray(radii, _F)
    tol = float(model.tolerance)
    b, fs = model.blocks, model.faces
    allowed = np.zeros(b.n, bool)
    allowed[_selection(model, mask)] = True
    if not allowed.any() or len(radii) == 0:
        return 0, 0, 0
    rows = np.arange(b.n)
    lo, hi = _block_boxes(model, rows)
    made = used = skipped = 0
    ext = radii[:, None] * np.sqrt(np.clip(1.0 - normals ** 2, 0.0, None))
    dlo, dhi = centers - ext - tol, centers + ext + tol
    for k in range(len(radii)):
        cand = np.flatnonzero(allowed & (lo <= dhi[k]).all(axis=1) & (hi >= dlo[k]).all(axis=1))
        if cand.size == 0:
            continue
        c, n, r = centers[k], normals[k], float(radii[k])
        sure, maybe, thin = _prefilter(model, cand, c, n, r, tol)
        hit = list(sure) + [int(i) for i in maybe if disk_touches_block(model, int(i), c, n, r, tol)]
        skipped += sum(1 for i in thin if disk_touches_block(model, int(i), c, n, r, tol))
        if not hit:
            continue
        m = np.zeros(b.n, bool)
        m[hit] = True
        n0, f0 = b.n, fs.n
        new = cut_by_planes(model, n, [float(n @ c)], mask=m, join=join, compact=False, keep_whole=keep_whole)
        # the faces of this cut are appended (nothing is compacted between cuts); the new ones lie on
        # the plane, the others are pieces of older faces and keep what those had
        js = fs["jointset"]
        cand_f = f0 + np.flatnonzero(js[f0:] == -1)
        d0 = float(n @ c)
        on_plane = (np.abs(np.abs(fs["normal"][cand_f] @ n) - 1.0) < 1e-9) & \
            (np.abs(fs["centroid"][cand_f] @ n - d0) <= 10 * tol)
        fresh = cand_f[on_plane]
        js[fresh] = int(jointset)
        fs["fracture"][fresh] = int(frac_ids[k])
        live = int(b["face_count"].sum())
        if fs.n > 2 * live + 1024:            # drop the dead rows now and then
            compact_geometry(model)
        if new:
            used += 1
            made += new
            if max_blocks is not None and b.n > max_blocks:
                raise TooManyBlocks(k + 1, int(b.n))
            changed = np.concatenate([np.asarray(hit, np.int64), np.arange(n0, b.n)])
            allowed = np.concatenate([allowed, np.ones(b.n - n0, bool)])
            allowed[n0:] = True
            lo = np.concatenate([lo, np.zeros((b.n - n0, 3))])
            hi = np.concatenate([hi, np.zeros((b.n - n0, 3))])
            lo[changed], hi[changed] = _block_boxes(model, changed)
    compact_geometry(model)
    return made, used, skipped
