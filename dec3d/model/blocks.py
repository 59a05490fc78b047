"""Block editing on the model: create, delete, hide, group, join, density, summary.

Every function takes a boolean ``mask`` over the live block rows (what a range gives)
or explicit rows, changes the stores in place and keeps them consistent: contiguous
geometry ranges, leader rows valid, group codes in range.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from dec3d.geometry.assemble import compact_geometry, polys_to_batch, write_pieces
from dec3d.geometry.mass import update_mass_properties
from dec3d.geometry.polyhedron import Poly

from .model import KIND_RIGID, Model
from .zones import follow_geometry


def add_blocks(model: Model, polys: Sequence[Poly], group: str | None = None,
               slot: str | None = None, density: float | None = None,
               kind: int = KIND_RIGID) -> np.ndarray:
    """Append one block per polyhedron; return their rows. Ids continue from the last one."""
    if not polys:
        return np.zeros(0, dtype=np.int64)
    return add_pieces(model, polys_to_batch(polys), group, slot, density, kind)


def add_pieces(model: Model, batch, group: str | None = None, slot: str | None = None,
               density: float | None = None, kind: int = KIND_RIGID) -> np.ndarray:
    """Append one block per piece of ``batch`` (``polys_to_batch``'s form); return their rows."""
    b = model.blocks
    sl = b.append(len(batch[2]))
    rows = np.arange(sl.start, sl.stop, dtype=np.int64)
    b["id"][rows] = np.arange(model.next_block_id, model.next_block_id + len(rows))
    model.next_block_id += len(rows)
    b["leader"][rows] = rows
    b["kind"][rows] = kind
    if density is not None:
        b["density"][rows] = density
    if group is not None:
        model.groups.assign(b, rows, group, slot)
    write_pieces(model, rows, *batch)
    return rows


def _rows(model: Model, mask) -> np.ndarray:
    mask = np.asarray(mask)
    if mask.dtype == bool:
        if mask.shape != (model.blocks.n,):
            raise ValueError(f"block mask has shape {mask.shape}, expected ({model.blocks.n},)")
        return np.flatnonzero(mask)
    return mask.astype(np.int64)


def delete_blocks(model: Model, mask) -> int:
    """Delete blocks; followers of a deleted leader follow the lowest remaining row of
    their group instead. Returns the number deleted."""
    b = model.blocks
    rows = _rows(model, mask)
    if rows.size == 0:
        return 0
    keep = np.ones(b.n, dtype=bool)
    keep[rows] = False
    leader = b["leader"].copy()
    # re-elect a leader where the old one goes away
    orphan = keep & ~keep[leader]
    if orphan.any():
        old = leader[orphan]
        idx = np.flatnonzero(orphan)
        for o in np.unique(old):
            members = idx[old == o]
            leader[members] = members.min()
    remap = b.compact(keep)
    b["leader"][:] = remap[leader[keep]]
    vblock = model.vertices["block"]
    fblock = model.faces["block"]
    vblock[:] = np.where(vblock >= 0, remap[vblock], -1)
    fblock[:] = np.where(fblock >= 0, remap[fblock], -1)
    follow_geometry(model, compact_geometry(model), remap)
    from .cables import remap_hosts     # cable nodes in a deleted block lose their host (and grout)

    remap_hosts(model, remap)
    return int(rows.size)


def hide_blocks(model: Model, mask, on: bool = True) -> int:
    """Set (``on``) or clear the hidden flag. Returns the number of blocks touched."""
    rows = _rows(model, mask)
    if not on:
        rows = rows[~model.blocks["excavated"][rows]]      # excavated blocks come back with `block fill` only
    model.blocks["hidden"][rows] = bool(on)
    return int(rows.size)


def set_density(model: Model, mask, density: float) -> int:
    """Set the density [kg/m³] and recompute mass and inertia."""
    rows = _rows(model, mask)
    model.blocks["density"][rows] = float(density)
    update_mass_properties(model, rows)
    return int(rows.size)


def group_blocks(model: Model, mask, name: str, slot: str | None = None,
                 remove: bool = False) -> int:
    """Put blocks in group ``name`` in ``slot`` (or take them out with ``remove``)."""
    rows = _rows(model, mask)
    if remove:
        model.groups.remove(model.blocks, rows, name, slot)
    else:
        model.groups.assign(model.blocks, rows, name, slot)
    return int(rows.size)


def join_blocks(model: Model, mask, on: bool = True) -> int:
    """Join (``on``) the selected blocks into one rigid body, or release them.

    Joining merges the selection with every joined group it touches; the leader is the
    lowest row. Releasing makes each selected block its own leader; a group that loses
    its leader elects the lowest remaining row.
    """
    b = model.blocks
    rows = _rows(model, mask)
    if rows.size == 0:
        return 0
    leader = b["leader"]
    if on:
        groups = np.unique(leader[rows])
        members = np.flatnonzero(np.isin(leader, groups))
        members = np.union1d(members, rows)
        leader[members] = members.min()
    else:
        old = leader[rows].copy()
        leader[rows] = rows
        released = set(rows.tolist())
        for o in np.unique(old):
            if int(o) in released:
                rest = np.flatnonzero(leader == o)
                rest = rest[rest != o]
                if rest.size:
                    leader[rest] = rest.min()
    return int(rows.size)


def joined_groups(model: Model) -> list[np.ndarray]:
    """Rows of each group of two or more joined blocks, leader first."""
    leader = model.blocks["leader"]
    out = []
    for ld in np.unique(leader):
        members = np.flatnonzero(leader == ld)
        if members.size > 1:
            out.append(np.concatenate(([ld], members[members != ld])))
    return out


def summary(model: Model) -> dict:
    """Counts, volume, extent and tolerance, for ``block list information``."""
    b = model.blocks
    pos = model.vertices["pos"]
    info = {
        "blocks": b.n,
        "hidden": int(b["hidden"].sum()),
        "joined": int(sum(len(g) for g in joined_groups(model))),
        "vertices": model.vertices.n,
        "faces": model.faces.n,
        "volume": float(b["volume"].sum()),
        "mass": float(b["mass"].sum()),
        "tolerance": model.tolerance,
        "extent": (pos.min(axis=0).tolist(), pos.max(axis=0).tolist()) if len(pos) else None,
    }
    return info


def group_faces(model: Model, mask, name: str, slot: str | None = None, remove: bool = False) -> int:
    """Put faces (boolean mask over face rows) in group ``name`` (or take them out)."""
    mask = np.asarray(mask)
    rows = np.flatnonzero(mask) if mask.dtype == bool else mask.astype(np.int64)
    if remove:
        model.groups.remove(model.faces, rows, name, slot)
    else:
        model.groups.assign(model.faces, rows, name, slot)
    return int(rows.size)
