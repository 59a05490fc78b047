"""Range elements: pure functions turning a store into a boolean mask over its live rows.

Every element is ``mask_<name>(model, store_name, **params) -> np.ndarray[bool]`` (length
``store.n``). Geometric elements test a point per row: a block's centroid (3DEC selects
blocks by centroid), a face's area centroid, a vertex's position. Bounds are inclusive
within the model's geometric tolerance (``block tolerance``), so ``position-x 10`` finds
faces lying on x = 10. Angles are radians, lengths metres (commands convert).

Modifiers: ``not`` negates the element just before it, ``union`` ORs the elements instead
of the default AND; ``combine`` applies both to a list of element masks.
"""
from __future__ import annotations

from typing import Iterable, Sequence

import numpy as np

from dec3d.geometry.planes import dip_normal

from .groups import GROUP_FIELD

#: the point each store is located by
_POSITION_FIELD = {"blocks": "centroid", "faces": "centroid", "vertices": "pos"}


def positions(model, store_name: str) -> np.ndarray:
    """The (n, 3) point by which rows of a store are selected geometrically."""
    store = model.store(store_name)
    if store.name == "zones":                 # a zone is located by its centroid
        from .zone_quality import centroids
        return centroids(model)
    key = _POSITION_FIELD.get(store.name)
    for k in (key, "centroid", "pos"):
        if k is not None and k in store:
            return store[k]
    raise KeyError(f"{store_name}s have no position to select by")


def _vec(v) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64).reshape(3)
    return a


# ------------------------------------------------------------------ geometric
def mask_position(model, store_name: str, lower, upper) -> np.ndarray:
    """``position <v1> <v2>``: inside the axis-aligned box with corners v1 and v2."""
    p = positions(model, store_name)
    lo = np.minimum(_vec(lower), _vec(upper)) - model.tolerance
    hi = np.maximum(_vec(lower), _vec(upper)) + model.tolerance
    return np.all((p >= lo) & (p <= hi), axis=1)


def _position_axis(model, store_name: str, axis: int, a: float, b: float | None) -> np.ndarray:
    x = positions(model, store_name)[:, axis]
    lo, hi = (a, a) if b is None else (min(a, b), max(a, b))
    return (x >= lo - model.tolerance) & (x <= hi + model.tolerance)


def mask_position_x(model, store_name: str, a: float, b: float | None = None) -> np.ndarray:
    """``position-x <a> [<b>]``: a ≤ x ≤ b, or x = a within tolerance when b is omitted."""
    return _position_axis(model, store_name, 0, a, b)


def mask_position_y(model, store_name: str, a: float, b: float | None = None) -> np.ndarray:
    """``position-y <a> [<b>]``: as ``position-x`` for y."""
    return _position_axis(model, store_name, 1, a, b)


def mask_position_z(model, store_name: str, a: float, b: float | None = None) -> np.ndarray:
    """``position-z <a> [<b>]``: as ``position-x`` for z."""
    return _position_axis(model, store_name, 2, a, b)


def mask_plane(model, store_name: str, side: str | None = None, origin=(0.0, 0.0, 0.0),
               dip: float | None = None, dip_direction: float | None = None,
               normal=None, distance: float | None = None) -> np.ndarray:
    """``plane [origin <v>] dip <d> dip-direction <dd> | normal <v> above|below [distance <f>]``.

    The plane passes through ``origin`` with the given normal, or the upward normal of
    (dip, dip direction). ``above``: on the normal's side (signed distance ≥ −tol);
    ``below``: the other side (≤ +tol); no side: within ``distance`` (default the
    tolerance) of the plane. ``above`` together with ``distance``: 0 ≤ s ≤ distance.
    """
    if normal is not None:
        n = _vec(normal)
        if not np.linalg.norm(n) > 0:
            raise ValueError("plane: the normal is zero")
        n = n / np.linalg.norm(n)
    elif dip is not None:
        n = dip_normal(dip, dip_direction or 0.0)
    else:
        raise ValueError("plane: give either 'dip' (and 'dip-direction') or 'normal'")
    s = (positions(model, store_name) - _vec(origin)) @ n
    tol = model.tolerance
    if side is None:
        d = tol if distance is None else abs(distance) + tol
        return np.abs(s) <= d
    if side not in ("above", "below"):
        raise ValueError(f"plane: side must be 'above' or 'below', not '{side}'")
    if side == "below":
        s = -s
    m = s >= -tol
    if distance is not None:
        m &= s <= abs(distance) + tol
    return m


def mask_cylinder(model, store_name: str, end1, end2, radius: float,
                  radius2: float | None = None) -> np.ndarray:
    """``cylinder end-1 <v> end-2 <v> radius <r> [<r2>]``: within radius r of the axis
    segment end-1–end-2 (between the end planes); with two radii, the annulus between them."""
    a, b = _vec(end1), _vec(end2)
    axis = b - a
    length = np.linalg.norm(axis)
    if not length > 0:
        raise ValueError("cylinder: end-1 and end-2 coincide")
    axis /= length
    rel = positions(model, store_name) - a
    t = rel @ axis
    r = np.linalg.norm(rel - t[:, None] * axis, axis=1)
    tol = model.tolerance
    rlo, rhi = (0.0, radius) if radius2 is None else (min(radius, radius2), max(radius, radius2))
    return (t >= -tol) & (t <= length + tol) & (r >= rlo - tol) & (r <= rhi + tol)


def mask_sphere(model, store_name: str, centre, radius: float) -> np.ndarray:
    """``sphere centre <v> radius <r>``: within distance r of the centre."""
    d = np.linalg.norm(positions(model, store_name) - _vec(centre), axis=1)
    return d <= radius + model.tolerance


# ------------------------------------------------------------------ attributes
def _group_codes(model, names: Iterable[str]) -> np.ndarray:
    return np.array([model.groups.code(n) for n in names], dtype=np.int32)


def mask_group(model, store_name: str, names: str | Sequence[str],
               slot: str | None = None) -> np.ndarray:
    """``group '<g>' [slot '<s>'] [or '<g2>' ...]``: in any of the groups, in ``slot`` if
    given, else in any slot."""
    store = model.store(store_name)
    if GROUP_FIELD not in store:
        raise KeyError(f"{store_name}s have no groups")
    if isinstance(names, str):
        names = [names]
    if store.name == "contacts" and slot is None:
        # a contact is in a group when it is, or when either of its blocks is (3DEC)
        own = _in_groups(model, store, names, None)
        blocks = _in_groups(model, model.blocks, names, None)
        return own | blocks[store["a"]] | blocks[store["b"]]
    if store.name in ("zones", "feblocks", "vertices"):
        # a zone (FE element, gridpoint) is in a group when it is, or when its block is (block groups
        # select zones and gridpoints: `block gridpoint apply … range group 'foundation'`)
        own = _in_groups(model, store, names, slot)
        if not model.blocks.n:
            return own
        blocks = _in_groups(model, model.blocks, names, slot)
        b = store["block"]
        return own | (blocks[np.clip(b, 0, None)] & (b >= 0))
    return _in_groups(model, store, names, slot)


def _in_groups(model, store, names, slot) -> np.ndarray:
    codes = _group_codes(model, names)
    codes = codes[codes >= 0]
    g = store[GROUP_FIELD]
    if codes.size == 0:
        return np.zeros(store.n, dtype=bool)
    if slot is not None:
        col = model.groups.slot_index(store, slot)
        if col < 0:
            return np.zeros(store.n, dtype=bool)
        return np.isin(g[:, col], codes)
    return np.isin(g, codes).any(axis=1)


def mask_group_intersection(model, store_name: str, a: str, b: str, slot: str | None = None) -> np.ndarray:
    """``group-intersection '<a>' '<b>' [slot '<s>']``: rows in both groups (any slot, or the slot
    given). Contacts select the contacts between a block of one group and a block of the other,
    or contacts that are themselves in both groups."""
    store = model.store(store_name)
    if store.name == "contacts":
        own = _in_groups(model, store, [a], slot) & _in_groups(model, store, [b], slot)
        return own | pairs_in_groups(model, store["a"], store["b"], a, b, slot)
    return _in_groups(model, store, [a], slot) & _in_groups(model, store, [b], slot)


def pairs_in_groups(model, ra, rb, a: str, b: str, slot: str | None = None) -> np.ndarray:
    """Block pairs (rows ``ra[i]``, ``rb[i]``) with one block in group ``a`` and the other in ``b``."""
    ga = _in_groups(model, model.blocks, [a], slot)
    gb = _in_groups(model, model.blocks, [b], slot)
    return (ga[ra] & gb[rb]) | (gb[ra] & ga[rb])


def mask_id(model, store_name: str, id: int) -> np.ndarray:  # noqa: A002 (3DEC's keyword)
    """``id <i>``: the row with that user id."""
    return mask_id_list(model, store_name, [id])


def mask_id_list(model, store_name: str, ids: Sequence[int]) -> np.ndarray:
    """``id-list <i> ...``: rows whose user id is in the list."""
    store = model.store(store_name)
    if "id" not in store:
        raise KeyError(f"{store_name}s have no id")
    return np.isin(store["id"], np.asarray(list(ids), dtype=np.int64))


def mask_region(model, store_name: str, region: int) -> np.ndarray:
    """``region <i>``: blocks with that 3DEC 5 region number (``r=<i>`` when created, 0 when not
    given); entities of other stores by the region of the block they belong to."""
    store = model.store(store_name)
    regions = model.blocks["region"]
    if store is model.blocks:
        return regions == int(region)
    if store.name == "contacts":          # a contact is in the region when one of its blocks is
        a, b = store["a"], store["b"]
        return (regions[a] == int(region)) | (regions[b] == int(region))
    if "block" not in store:
        raise KeyError(f"{store_name}s belong to no block: `region` selects blocks and their parts")
    owner = store["block"]
    ok = (owner >= 0) & (owner < len(regions))
    out = np.zeros(store.n, dtype=bool)
    out[ok] = regions[owner[ok]] == int(region)
    return out


# ------------------------------------------------------------------ modifiers
def combine(masks: Sequence[tuple[np.ndarray, bool]], union: bool = False,
            n: int | None = None) -> np.ndarray:
    """Join element masks: each ``(mask, negated)``; AND by default, OR with ``union``.

    An empty range selects everything (``n`` rows).
    """
    if not masks:
        if n is None:
            raise ValueError("combine: no elements and no row count")
        return np.ones(n, dtype=bool)
    out = None
    for m, neg in masks:
        m = ~m if neg else m
        out = m.copy() if out is None else (out | m if union else out & m)
    return out


#: element name -> mask function, for the command layer's range binding
RANGE_ELEMENTS = {
    "position": mask_position,
    "position-x": mask_position_x,
    "position-y": mask_position_y,
    "position-z": mask_position_z,
    "plane": mask_plane,
    "cylinder": mask_cylinder,
    "sphere": mask_sphere,
    "group": mask_group,
    "group-intersection": mask_group_intersection,
    "id": mask_id,
    "id-list": mask_id_list,
    "region": mask_region,
}
