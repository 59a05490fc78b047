"""Where a history given by a position looks (``block history … position``, ``block zone
history … position``): the visible block whose centroid is nearest, a zoned block's nearest
gridpoint, the zone containing the point. Used by ``dec3d.commands.histories``; the
histories themselves are ``dec3d.physics.history``."""
from __future__ import annotations

import numpy as np


def nearest_block_id(model, position) -> int:
    """Id of the visible block whose centroid is nearest ``position``."""
    b = model.blocks
    rows = np.flatnonzero(~b["hidden"])
    if rows.size == 0:
        raise ValueError("there are no blocks")
    d = np.linalg.norm(b["centroid"][rows] - np.asarray(position, dtype=float), axis=1)
    return int(b["id"][rows[int(np.argmin(d))]])


def nearest_gridpoint(model, block_row: int, position) -> int:
    """Index, within block ``block_row``'s vertex range, of its gridpoint nearest ``position``."""
    b = model.blocks
    s, c = int(b["vert_start"][block_row]), int(b["vert_count"][block_row])
    d = np.linalg.norm(model.vertices["pos"][s:s + c] - np.asarray(position, dtype=float), axis=1)
    return int(np.argmin(d))


def zone_at(model, position) -> int:
    """Id of the zone containing ``position`` (the first one, by row, when it lies on shared faces), or
    of the zone whose centroid is nearest when no zone contains it. ValueError when there are no zones."""
    from dec3d.model.zone_quality import corners
    if "zones" not in model.stores or model.store("zones").n == 0:
        raise ValueError("there are no zones (`block zone generate` makes them)")
    zs = model.store("zones")
    x = np.asarray(position, dtype=float)
    p = corners(model)
    # barycentric coordinates: solve [p1-p0 p2-p0 p3-p0] l = x - p0
    m = np.transpose(p[:, 1:] - p[:, :1], (0, 2, 1))
    ok = np.abs(np.linalg.det(m)) > 0.0
    lam = np.full((zs.n, 3), -1.0)
    if ok.any():
        lam[ok] = np.linalg.solve(m[ok], (x - p[ok, 0])[..., None])[..., 0]
    bary = np.column_stack([1.0 - lam.sum(axis=1), lam])
    inside = np.flatnonzero((bary >= -1e-9).all(axis=1))
    if inside.size:
        return int(zs["id"][inside[0]])
    return int(zs["id"][int(np.argmin(np.linalg.norm(p.mean(axis=1) - x, axis=1)))])
