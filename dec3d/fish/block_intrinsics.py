"""FISH block intrinsics (rigid blocks): read the current model state.

A block is handed to FISH as its id (an integer; ids are never reused), which is what
`block.list` holds and `block.find` returns (0, FISH's null, when no live block has it).
Names and meanings follow Itasca's 3DEC 7 FISH reference (block.id, block.pos, block.vel,
block.disp, block.mass, block.vol, block.group, block.fix).
"""
from __future__ import annotations

from .intrinsics import intrinsic, setter
from .values import FishValueError, Vec, type_name


def _row(rt, b, name):
    if type(b) is not int:
        raise FishValueError(f"`{name}` takes a block (its id from block.list or block.find), not a {type_name(b)}")
    model = rt.session.model
    rows = model.block_rows([b])
    if rows[0] < 0:
        raise FishValueError(f"`{name}`: there is no block with id {b}")
    return model, int(rows[0])


def _vec(arr, r):
    return Vec(float(arr[r, 0]), float(arr[r, 1]), float(arr[r, 2]))


@intrinsic("block.list")
def _block_list(rt):
    return [int(i) for i in rt.session.model.blocks["id"]]


@intrinsic("block.num")
def _block_num(rt):
    return int(rt.session.model.blocks.n)


@intrinsic("block.find", 1)
def _block_find(rt, b):
    if type(b) is not int:
        raise FishValueError(f"`block.find` takes a block id (an integer), not a {type_name(b)}")
    return b if rt.session.model.block_rows([b])[0] >= 0 else 0


@intrinsic("block.id", 1)
def _block_id(rt, b):
    _row(rt, b, "block.id")
    return b


def _vector_family(name, field):
    def whole(rt, b):
        m, r = _row(rt, b, name)
        return _vec(m.blocks[field], r)
    intrinsic(name, 1)(whole)
    for k, c in (("x", 0), ("y", 1), ("z", 2)):
        def comp(rt, b, c=c, full=f"{name}.{k}"):
            m, r = _row(rt, b, full)
            return float(m.blocks[field][r, c])
        intrinsic(f"{name}.{k}", 1)(comp)


_vector_family("block.pos", "centroid")
_vector_family("block.vel", "velocity")
_vector_family("block.disp", "disp")
_vector_family("block.rvel", "spin")
_vector_family("block.force.app", "fapp")


@intrinsic("block.mass", 1)
def _block_mass(rt, b):
    m, r = _row(rt, b, "block.mass")
    return float(m.blocks["mass"][r])


@intrinsic("block.vol", 1)
def _block_vol(rt, b):
    m, r = _row(rt, b, "block.vol")
    return float(m.blocks["volume"][r])


@intrinsic("block.density", 1)
def _block_density(rt, b):
    m, r = _row(rt, b, "block.density")
    return float(m.blocks["density"][r])


@intrinsic("block.group", 1, 2)
def _block_group(rt, b, slot=None):
    """The block's group in `slot` (default slot when omitted); "" when it has none there."""
    m, r = _row(rt, b, "block.group")
    if slot is not None and type(slot) is not str:
        raise FishValueError(f"`block.group`: the slot is a string, not a {type_name(slot)}")
    col = m.groups.slot_index(m.blocks, slot)
    if col < 0:
        return ""
    return m.groups.name(int(m.blocks["group"][r, col]))


@intrinsic("block.fix", 1)
def _block_fix(rt, b):
    """True when the block is fixed (`block fix`)."""
    m, r = _row(rt, b, "block.fix")
    return bool(m.blocks["fixity"][r])


@intrinsic("block.head")
def _block_head(rt):
    """The first block (0 when there is none); walk on with block.next."""
    ids = rt.session.model.blocks["id"]
    return int(ids[0]) if len(ids) else 0


@intrinsic("block.next", 1)
def _block_next(rt, b):
    """The block after `b` in block.list order, 0 after the last."""
    m, r = _row(rt, b, "block.next")
    return int(m.blocks["id"][r + 1]) if r + 1 < m.blocks.n else 0


def _set_vector(name, field, what):
    """`name(b) = v` and `name.x(b) = x`: write a block's vector field (finite numbers only)."""
    def whole(rt, b, v):
        m, r = _row(rt, b, name)
        if type(v) is not Vec or any(type(c) not in (int, float) or c - c for c in v):
            raise FishValueError(f"`{name}` is set to a vector of finite numbers, not a {type_name(v)}")
        m.blocks[field][r] = (float(v.x), float(v.y), float(v.z))
    setter(name, f"set the block's {what}")(whole)
    for k, c in (("x", 0), ("y", 1), ("z", 2)):
        def comp(rt, b, x, c=c, full=f"{name}.{k}"):
            m, r = _row(rt, b, full)
            if type(x) not in (int, float) or x - x:
                raise FishValueError(f"`{full}` is set to a finite number, not {x!r}")
            m.blocks[field][r, c] = float(x)
        setter(f"{name}.{k}", f"set one component of the block's {what}")(comp)


_set_vector("block.vel", "velocity", "velocity [m/s]")
_set_vector("block.force.app", "fapp", "applied force [N] (as `block apply force`)")
