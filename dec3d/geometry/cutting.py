"""Cutting blocks by planes and joint sets (``block cut joint-set``).

The geometry is done by the kernel ``dec3d.kernels.polycut.cut_blocks`` over every
selected block and every plane of the set in one call. Here the pieces go back into the
stores: the first piece of a block (lowest along the set's normal) keeps the block's row
and id; the others get new rows and the next ids, and copy every attribute of the parent
(density, groups, hidden, kind, fixity, velocities). Faces cut from an old face keep its
groups; the new cut faces have none.

Only visible blocks are cut, and of those only the ones in the given mask (3DEC: "only
visible blocks in range are cut").
"""
from __future__ import annotations

import math

import numpy as np

from dec3d.kernels.polycut import cut_blocks as _cut_kernel

from .assemble import compact_geometry, write_pieces
from .errors import GeometryError
from .mass import range_index
from .planes import dip_normal, plane_basis


def _selection(model, mask) -> np.ndarray:
    b = model.blocks
    sel = ~b["hidden"]
    if mask is not None:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != (b.n,):
            raise ValueError(f"block mask has shape {mask.shape}, expected ({b.n},)")
        sel = sel & mask
    return np.flatnonzero(sel).astype(np.int64)


def joint_set_offsets(normal, origin, spacing: float | None, number: int | None,
                      smin: float, smax: float) -> np.ndarray:
    """Plane offsets d (n·x = d) of a joint set, ascending.

    No spacing: one plane through ``origin``. Spacing without number: every plane
    ``n·origin + k·spacing`` (k any integer) that meets [smin, smax]. Spacing and number:
    ``number`` planes from the origin on, k = 0 .. number−1, in the normal's direction.
    """
    d0 = float(np.dot(normal, origin))
    if spacing is None:
        if number not in (None, 1):
            raise GeometryError("joint set: 'number' needs a 'spacing'")
        return np.array([d0])
    if not spacing > 0:
        raise GeometryError(f"joint set: spacing must be positive, got {spacing:g}")
    k0, k1 = _plane_range(d0, spacing, number, smin, smax)
    if k1 - k0 > 10_000_000:
        raise GeometryError(f"joint set: {k1 - k0} planes of spacing {spacing:g} m: spacing too small")
    return d0 + spacing * np.arange(k0, k1 + 1, dtype=np.float64)


def _plane_range(d0: float, spacing: float, number: int | None, smin: float, smax: float) -> tuple[int, int]:
    """Indices k0..k1 of the planes d0 + k·spacing that may meet [smin, smax] (one plane of margin
    each side); with `number`, only k = 0 .. number−1 (planes beyond the blocks cut nothing, so a
    large `number` costs nothing)."""
    if number is not None and number < 1:
        raise GeometryError(f"joint set: number must be at least 1, got {number}")
    span = max(abs(smin - d0), abs(smax - d0)) / spacing
    if not span < 1e15:
        raise GeometryError(f"joint set: spacing {spacing:g} m is too small for blocks {smax - smin:g} m across")
    k0 = math.floor((smin - d0) / spacing)
    k1 = math.ceil((smax - d0) / spacing)
    if number is not None:
        k0, k1 = max(k0, 0), min(k1, int(number) - 1)
    return k0, k1


def joint_set_estimate(model, dip: float, dip_direction: float, origin=(0.0, 0.0, 0.0),
                       spacing: float | None = None, number: int | None = None, mask=None) -> int:
    """At most how many new blocks `cut_joint_set` with these arguments makes, worked out from
    each block's extent along the set's normal before anything is allocated per plane: a convex
    block crossed by m parallel planes falls into at most m + 1 pieces. (Capped at 10^18.)"""
    rows = _selection(model, mask)
    if rows.size == 0 or spacing is None:
        return int(rows.size)                     # one plane: each block in two at most
    n = dip_normal(dip, dip_direction)
    b = model.blocks
    starts, counts = b["vert_start"][rows], b["vert_count"][rows]
    s = model.vertices["pos"][range_index(starts, counts)] @ n
    offs = np.concatenate(([0], np.cumsum(counts)[:-1])).astype(np.int64)
    lo, hi = np.minimum.reduceat(s, offs), np.maximum.reduceat(s, offs)
    d0 = float(np.dot(n, np.asarray(origin, dtype=np.float64)))
    # planes strictly inside each block's extent: k with lo < d0 + k·spacing < hi
    first = np.floor((lo - d0) / spacing) + 1
    last = np.ceil((hi - d0) / spacing) - 1
    if number is not None:
        first, last = np.maximum(first, 0), np.minimum(last, int(number) - 1)
    total = float(np.clip(last - first + 1, 0, None).sum())
    return int(total) if total < 1e18 else 10**18


def cut_by_planes(model, normal, offsets, mask=None, join: bool = False, compact: bool = True,
                  keep_whole=None) -> int:
    """Cut the visible blocks in ``mask`` by the planes n·x = offsets. Returns new blocks made.

    ``join``: the pieces of each block are joined to each other (leader/follower); without
    it, pieces of a joined block stay in its group and pieces of a free block are free.
    ``compact=False`` leaves the parents' old vertex and face rows in the stores (unreferenced;
    a caller cutting many times compacts once, with ``assemble.compact_geometry``); the new rows
    are then the last ones of each store. ``keep_whole`` (bool per block row, or None): blocks that must
    not be split (zoned and FE blocks: their meshes would not follow); ``GeometryError`` before any
    change when the planes would split one.
    """
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    offsets = np.sort(np.asarray(offsets, dtype=np.float64))
    rows = _selection(model, mask)
    if rows.size == 0 or offsets.size == 0:
        return 0
    b, f = model.blocks, model.faces
    u, w = plane_basis(n)
    parent, pnv, pnf, pos, vsrc, fn, fsrc, fv = _cut_kernel(
        model.vertices["pos"], model.face_vertices["vertex"], f["vstart"], f["nvert"],
        b["vert_start"], b["vert_count"], b["face_start"], b["face_count"],
        rows, n, offsets, float(model.tolerance), u, w)
    if parent.size == 0:
        return 0
    first = np.ones(parent.size, dtype=bool)
    first[1:] = parent[1:] != parent[:-1]
    extra = ~first
    src = parent[extra]
    # refused before anything changes (rows past keep_whole: pieces of this command's earlier cuts,
    # so of blocks it let be cut)
    old = src[src < len(keep_whole)] if keep_whole is not None else src[:0]
    if keep_whole is not None and keep_whole[old].any():
        bad = np.unique(old[keep_whole[old]])
        ids = ", ".join(str(int(i)) for i in b["id"][bad[:10]]) + (" …" if bad.size > 10 else "")
        raise GeometryError(f"the cut would split zoned or FE blocks ({ids}), whose zones or elements would not "
                            "follow it: cut before `block zone generate` / `feblock generate`, or leave these "
                            "blocks out of the range")
    # joined parents (followers, or leaders of others), before new rows copy their leader
    lead = b["leader"]
    has_followers = np.zeros(b.n, dtype=bool)
    has_followers[lead[lead != np.arange(b.n)]] = True
    joined = (lead[src] != src) | has_followers[src]
    sl = b.append(int(extra.sum()))
    new_rows = np.arange(sl.start, sl.stop, dtype=np.int64)
    for key in b.fields:
        arr = b.full(key)
        arr[new_rows] = arr[src]
    b["id"][new_rows] = np.arange(model.next_block_id, model.next_block_id + new_rows.size)
    model.next_block_id += int(new_rows.size)

    lead = b["leader"]
    lead[new_rows] = np.where(join | joined, lead[src], new_rows)

    piece_rows = np.empty(parent.size, dtype=np.int64)
    piece_rows[first] = parent[first]
    piece_rows[extra] = new_rows
    write_pieces(model, piece_rows, pos, vsrc, pnv, fn, fsrc, pnf, fv)
    if compact:
        compact_geometry(model)
    return int(new_rows.size)


def cut_joint_set(model, dip: float, dip_direction: float, origin=(0.0, 0.0, 0.0),
                  spacing: float | None = None, number: int | None = None,
                  mask=None, join: bool = False, keep_whole=None) -> int:
    """``block cut joint-set``: dip and dip direction in radians, origin and spacing in m;
    ``keep_whole`` as ``cut_by_planes``'.

    Returns the number of new blocks.
    """
    n = dip_normal(dip, dip_direction)
    rows = _selection(model, mask)
    if rows.size == 0:
        return 0
    b = model.blocks
    vidx = range_index(b["vert_start"][rows], b["vert_count"][rows])
    s = model.vertices["pos"][vidx] @ n
    offsets = joint_set_offsets(n, np.asarray(origin, dtype=np.float64), spacing, number,
                                float(s.min()), float(s.max()))
    if offsets.size == 0:
        return 0
    return cut_by_planes(model, n, offsets, mask=mask, join=join, keep_whole=keep_whole)
