"""FISH extra variables and the density-scaling factor of gridpoints.

block.extra(b[, i]), block.zone.extra(z[, i]), block.gp.extra(g[, i]): Itasca's "extra" slots, a
number kept with each block, zone or gridpoint for the user's own bookkeeping (slot i from 1,
default 1; up to ``MAX_SLOTS``). Read before any write: 0. They live in the stores' field ``extra``
(no column until the first write widens it to the slot written), so `model save` keeps them. dec3d keeps numbers only
(integers and floats, finite): 3DEC also lets a slot hold a string or a vector.

block.gp.dsf(g): the density-scaling factor of a gridpoint, its inertial mass over its real mass
(1 without density scaling, after a cycle; a rigid block's vertex: 1). SAFEGO's
06_dynamic_load.dat copies it into block.gp.extra to check the scaling of a dynamic run.
"""
from __future__ import annotations

import math

from .block_intrinsics import _row as _block_row
from .intrinsics import intrinsic, setter
from .values import FishValueError, type_name
from .zone_intrinsics import _gprow, _row as _zone_row, _zoned

MAX_SLOTS = 64


def _slot(name: str, args) -> int:
    if not args:
        return 0
    i = args[0]
    if type(i) is not int or not 1 <= i <= MAX_SLOTS:
        raise FishValueError(f"`{name}`: the slot is an integer from 1 to {MAX_SLOTS}, not {i!r}")
    return i - 1


def _get(store, r: int, k: int) -> float:
    if store.fields["extra"].shape[0] <= k:
        return 0.0
    return float(store["extra"][r, k])


def _put(name: str, store, r: int, k: int, value) -> None:
    if type(value) not in (int, float) or not math.isfinite(value):
        raise FishValueError(f"`{name}` holds a finite number in dec3d, not a {type_name(value)}")
    if store.fields["extra"].shape[0] <= k:
        store.resize_field("extra", (k + 1,))
    store["extra"][r, k] = float(value)


def _family(name: str, locate):
    """Register ``name(obj[, i])`` and its setter; ``locate(rt, obj, name) -> (store, row)``."""
    def get(rt, obj, *i):
        store, r = locate(rt, obj, name)
        return _get(store, r, _slot(name, i))

    def put(rt, obj, *rest):
        *i, value = rest
        store, r = locate(rt, obj, name)
        _put(name, store, r, _slot(name, i), value)

    intrinsic(name, 1, 2)(get)
    setter(name, "set an extra variable (a number) of the object, slot i from 1")(put)


def _block(rt, b, name):
    m, r = _block_row(rt, b, name)
    return m.blocks, r


def _zone(rt, z, name):
    _, st, r = _zone_row(rt, z, name)
    return st, r


def _gp(rt, g, name):
    m, r = _gprow(rt, g, name)
    return m.vertices, r


_family("block.extra", _block)
_family("block.zone.extra", _zone)
_family("block.gp.extra", _gp)


@intrinsic("block.gp.dsf", 1)
def _gp_dsf(rt, g):
    """Inertial mass over real mass of the gridpoint (1 when not scaled or not yet cycled)."""
    m, r = _gprow(rt, g, "block.gp.dsf")
    v = m.vertices
    if not _zoned(m, r) or "imass" not in v.fields:
        return 1.0
    real, inertial = float(v["mass"][r]), float(v["imass"][r])
    return inertial / real if real > 0 and inertial > 0 else 1.0
