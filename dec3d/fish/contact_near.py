"""`block.contact.near(v)`: the contact nearest a point (3DEC 7 FISH reference; 3DEC 5's `c_near`,
which legacy decks use to pick the contact under a support, dec3d.lang.legacy)."""
from __future__ import annotations

import numpy as np

from .contact_intrinsics import _ptr, _stores
from .intrinsics import intrinsic
from .values import FishValueError, Vec, type_name


@intrinsic("block.contact.near", 1)
def _c_near(rt, v):
    """The contact whose centre is nearest the point ``v``: the area-weighted centroid of its sub-contacts
    (where it carries force: a small block on a large one has its contact under the small block), its
    stored position when it has none; 0 when the model has no contact. Of two at the same distance, the
    first in block.contact.list order."""
    if type(v) is not Vec:
        raise FishValueError(f"`block.contact.near` takes a vector (the point), not a {type_name(v)}")
    p = np.array([float(v.x), float(v.y), float(v.z)])
    cs, _ = _stores(rt, current=True)
    if cs is None or cs.n == 0:
        return 0
    centre = np.array(cs["pos"][: cs.n], dtype=np.float64)
    ss = rt.session.model.stores.get("subcontacts")
    if ss is not None and ss.n:
        owner = np.asarray(ss["contact"][: ss.n], dtype=np.int64)
        area = np.asarray(ss["area"][: ss.n], dtype=np.float64)
        ok = (owner >= 0) & (owner < cs.n)
        wsum = np.bincount(owner[ok], weights=area[ok], minlength=cs.n)
        for k in range(3):
            num = np.bincount(owner[ok], weights=area[ok] * ss["pos"][: ss.n][ok, k], minlength=cs.n)
            has = wsum > 0
            centre[has, k] = num[has] / wsum[has]
    d = np.einsum("ij,ij->i", centre - p, centre - p)
    return _ptr(cs, int(np.argmin(d)))
