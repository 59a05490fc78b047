"""FISH intrinsics of disk fractures (``fracture …``; store ``fractures``).

Itasca hands fracture pointers; dec3d hands fracture ids (from 1, as `fracture list`/files show them),
as it does for blocks and cables. Confirmed in Itasca's FISH pages: ``fracture.normal`` (the upward
unit normal). The others are dec3d's, named in the same family: ``fracture.pos`` (centre),
``fracture.diameter`` (3DEC's fracture size), ``fracture.dip`` and ``fracture.ddir`` (degrees),
``fracture.set``, ``fracture.dfn`` (the DFN id) and ``fracture.num()`` (how many fractures there are).
"""
from __future__ import annotations

import math

from .intrinsics import intrinsic
from .values import FishValueError, Vec, type_name


def _row(rt, i, name):
    if type(i) is not int:
        raise FishValueError(f"`{name}` takes a fracture id (an integer), not a {type_name(i)}")
    st = rt.session.model.stores.get("fractures")
    if st is not None and st.n:
        import numpy as np

        rows = np.flatnonzero(st["id"] == i)
        if rows.size:
            return st, int(rows[0])
    raise FishValueError(f"`{name}`: there is no fracture with id {i}")


@intrinsic("fracture.num", 0)
def _num(rt):
    """Number of disk fractures (all DFNs)."""
    st = rt.session.model.stores.get("fractures")
    return int(st.n) if st is not None else 0


@intrinsic("fracture.normal", 1)
def _normal(rt, i):
    """Upward unit normal of the fracture."""
    st, r = _row(rt, i, "fracture.normal")
    n = st["normal"][r]
    return Vec(float(n[0]), float(n[1]), float(n[2]))


@intrinsic("fracture.pos", 1)
def _pos(rt, i):
    """Centre of the fracture [m]."""
    st, r = _row(rt, i, "fracture.pos")
    c = st["center"][r]
    return Vec(float(c[0]), float(c[1]), float(c[2]))


@intrinsic("fracture.diameter", 1)
def _diameter(rt, i):
    """Diameter of the disk [m]."""
    st, r = _row(rt, i, "fracture.diameter")
    return 2.0 * float(st["radius"][r])


@intrinsic("fracture.dip", 1)
def _dip(rt, i):
    """Dip of the fracture [degrees]."""
    st, r = _row(rt, i, "fracture.dip")
    return math.degrees(math.acos(max(-1.0, min(1.0, float(st["normal"][r, 2])))))


@intrinsic("fracture.ddir", 1)
def _ddir(rt, i):
    """Dip direction of the fracture [degrees clockwise from +y]."""
    st, r = _row(rt, i, "fracture.ddir")
    n = st["normal"][r]
    return math.degrees(math.atan2(float(n[0]), float(n[1]))) % 360.0


@intrinsic("fracture.set", 1)
def _set(rt, i):
    """Set id of the fracture."""
    st, r = _row(rt, i, "fracture.set")
    return int(st["set"][r])


@intrinsic("fracture.dfn", 1)
def _dfn(rt, i):
    """Id of the DFN the fracture belongs to."""
    st, r = _row(rt, i, "fracture.dfn")
    return int(st["dfn"][r])
