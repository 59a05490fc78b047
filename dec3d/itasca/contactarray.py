"""``it.contactarray`` (also ``it.block.contactarray``): contact values as numpy arrays, one row per contact
(the order of ``it.block.contact.list()``), with the contacts up to date (detected first when the blocks
changed). Contacts are rebuilt at every detection, so these are copies (a view would go out of date at the
next detection). Values as dec3d stores them: normal force compression positive, shear force on block B,
normal from block A to block B.

===============  =======  ========  ===============================================
function         shape    dtype     unit
===============  =======  ========  ===============================================
ids()            (n, 2)   int64     ids of blocks A, B (A < B)
pos()            (n, 3)   float64   reference point [m]
normal()         (n, 3)   float64   unit normal A → B
gap()            (n,)     float64   gap at the last detection [m]
area()           (n,)     float64   sum of the sub-contact areas [m²]
force_norm()     (n,)     float64   normal force [N], sum over sub-contacts
force_shear()    (n, 3)   float64   shear force on B [N], sum over sub-contacts
sub_count()      (n,)     int64     number of sub-contacts
===============  =======  ========  ===============================================
"""
from __future__ import annotations

import numpy as np

from ._bind import Model
from ._objects import api_of


def _stores(model):
    from .block.contact import _stores as st

    return st(api_of(model))


def _field(model, key, shape=()):
    cs, _ = _stores(model)
    if cs is None:
        return np.zeros((0, *shape))
    return cs[key].copy()


def _sum(model, key, shape=()):
    cs, ss = _stores(model)
    if cs is None or cs.n == 0:
        return np.zeros((0, *shape))
    out = np.zeros((cs.n, *shape))
    owner = ss["contact"]
    np.add.at(out, owner, ss[key])
    return out


def ids(model: Model | None = None) -> np.ndarray:
    cs, _ = _stores(model)
    if cs is None:
        return np.zeros((0, 2), dtype=np.int64)
    return np.stack([cs["ida"], cs["idb"]], axis=1).astype(np.int64)


def pos(model: Model | None = None) -> np.ndarray:
    return _field(model, "pos", (3,))


def normal(model: Model | None = None) -> np.ndarray:
    return _field(model, "normal", (3,))


def gap(model: Model | None = None) -> np.ndarray:
    return _field(model, "gap")


def sub_count(model: Model | None = None) -> np.ndarray:
    return _field(model, "sub_count").astype(np.int64)


def area(model: Model | None = None) -> np.ndarray:
    return _sum(model, "area")


def force_norm(model: Model | None = None) -> np.ndarray:
    return _sum(model, "fn")


def force_shear(model: Model | None = None) -> np.ndarray:
    return _sum(model, "fs", (3,))
