"""FISH zone intrinsics (deformable blocks): read the ``zones`` store of dec3d.model.zones.

A zone is handed to FISH as its id (an integer from 1, what `block.zone.list` holds and
`block.zone.find` returns; 0, FISH's null, when no zone has it), as blocks are. Names follow
Itasca's 3DEC 7 FISH reference: block.zone.list, .num, .find, .id, .block, .vol, .pos,
.stress and its six components (tension positive), .gp(z, i) (1-based corner, a gridpoint row
+ 1 for now). Gridpoint intrinsics (block.gp.*) and writes are not here yet.
"""
from __future__ import annotations

import numpy as np

from .intrinsics import intrinsic
from .values import FishValueError, Vec, type_name

_COMP = ("xx", "yy", "zz", "xy", "xz", "yz")


def _zones(rt):
    st = rt.session.model.stores.get("zones")
    return st


def _row(rt, z, name):
    if type(z) is not int:
        raise FishValueError(f"`{name}` takes a zone (its id from block.zone.list), not a {type_name(z)}")
    st = _zones(rt)
    rows = np.nonzero(st["id"] == z)[0] if st is not None and st.n else ()
    if len(rows) == 0:
        raise FishValueError(f"`{name}`: there is no zone with id {z}")
    return rt.session.model, st, int(rows[0])


@intrinsic("block.zone.list")
def _list(rt):
    st = _zones(rt)
    return [] if st is None else [int(i) for i in st["id"]]


@intrinsic("block.zone.num")
def _num(rt):
    st = _zones(rt)
    return 0 if st is None else int(st.n)


@intrinsic("block.zone.find", 1)
def _find(rt, z):
    if type(z) is not int:
        raise FishValueError(f"`block.zone.find` takes a zone id (an integer), not a {type_name(z)}")
    st = _zones(rt)
    return z if st is not None and st.n and bool(np.any(st["id"] == z)) else 0


@intrinsic("block.zone.id", 1)
def _id(rt, z):
    _row(rt, z, "block.zone.id")
    return z


@intrinsic("block.zone.block", 1)
def _block(rt, z):
    m, st, r = _row(rt, z, "block.zone.block")
    return int(m.blocks["id"][int(st["block"][r])])


@intrinsic("block.zone.vol", 1)
def _vol(rt, z):
    _, st, r = _row(rt, z, "block.zone.vol")
    return float(st["volume"][r])


def _centroid(m, st, r):
    gp = st["gp"][r][:4]
    return m.vertices["pos"][gp].mean(axis=0)


@intrinsic("block.zone.pos", 1)
def _pos(rt, z):
    m, st, r = _row(rt, z, "block.zone.pos")
    c = _centroid(m, st, r)
    return Vec(float(c[0]), float(c[1]), float(c[2]))


for _k, _c in (("x", 0), ("y", 1), ("z", 2)):
    def _posc(rt, z, c=_c, full=f"block.zone.pos.{_k}"):
        m, st, r = _row(rt, z, full)
        return float(_centroid(m, st, r)[c])
    intrinsic(f"block.zone.pos.{_k}", 1)(_posc)

for _c, _k in enumerate(_COMP):
    def _sc(rt, z, c=_c, full=f"block.zone.stress.{_k}"):
        _, st, r = _row(rt, z, full)
        return float(st["stress"][r, c])
    intrinsic(f"block.zone.stress.{_k}", 1)(_sc)


@intrinsic("block.zone.gp", 2)
def _gp(rt, z, i):
    _, st, r = _row(rt, z, "block.zone.gp")
    n = int(st["nnode"][r])
    if type(i) is not int or not 1 <= i <= n:
        raise FishValueError(f"`block.zone.gp`: the node index must be an integer 1..{n}, not {i!r}")
    return int(st["gp"][r, i - 1]) + 1
