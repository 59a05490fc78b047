"""`block.contact.near(v)`: the contact nearest a point (3DEC 7 FISH reference; 3DEC 5's `c_near`,
which legacy decks use to pick the contact under a support, dec3d.lang.legacy)."""
from __future__ import annotations

import numpy as np

from .contact_intrinsics import _ptr, _stores
from .intrinsics import intrinsic
from .values import FishValueError, Vec, type_name


@intrinsic("block.contact.near", 1)
def _c_near(rt, v):
    """The contact whose position (the centroid of its sub-contacts) is nearest the point ``v``; 0 when
    the model has no contact. Of two at the same distance, the first in block.contact.list order."""
    if type(v) is not Vec:
        raise FishValueError(f"`block.contact.near` takes a vector (the point), not a {type_name(v)}")
    p = np.array([float(v.x), float(v.y), float(v.z)])
    cs, _ = _stores(rt, current=True)
    if cs is None or cs.n == 0:
        return 0
    d = np.einsum("ij,ij->i", cs["pos"][: cs.n] - p, cs["pos"][: cs.n] - p)
    return _ptr(cs, int(np.argmin(d)))
