"""FISH block intrinsics (rigid blocks): read the current model state.

A block is handed to FISH as its id (an integer; ids are never reused), which is what
`block.list` holds and `block.find` returns (0, FISH's null, when no live block has it).
Names and meanings follow Itasca's 3DEC 7 FISH reference (block.id, block.pos, block.vel,
block.disp, block.mass, block.vol, block.group, block.fix, block.near).
"""
from __future__ import annotations

import numpy as np

from .contact_intrinsics import CONTACTS
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


@intrinsic("block.near", 1, 3)
def _block_near(rt, *xyz):
    """The block whose centroid is nearest (x, y, z) (or a vector); 0 when there is no block. Ties: the lowest
    id. (dec3d's meaning: the distance to the centroid, not to the block's surface.)"""
    if len(xyz) == 1 and type(xyz[0]) is Vec:
        xyz = tuple(xyz[0])
    if len(xyz) != 3 or any(type(c) not in (int, float) or c - c for c in xyz):
        raise FishValueError("`block.near` takes a vector or three finite numbers x, y, z")
    b = rt.session.model.blocks
    if b.n == 0:
        return 0
    d = b["centroid"] - np.array(xyz, dtype=float)
    d2 = np.einsum("ij,ij->i", d, d)
    ids = b["id"]
    best = np.nonzero(d2 == d2.min())[0]
    return int(ids[best].min())


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


def _contact_loads(model):
    """(force (n, 3) N, moment about the centroid (n, 3) N·m) on every block from its sub-contacts as
    they stand (normal force fn along the contact normal A → B on B, shear force fs on B; the opposite
    on A)."""
    b = model.blocks
    f = np.zeros((b.n, 3))
    mo = np.zeros((b.n, 3))
    if CONTACTS[0] is not None:           # detected again when the blocks changed (a `block delete`)
        cs, ss = CONTACTS[0](model)
    else:
        st = model.stores
        cs, ss = st.get("contacts"), st.get("subcontacts")
    if cs is None or ss is None or ss.n == 0:
        return f, mo
    c = ss["contact"]
    fb = ss["fn"][:, None] * cs["normal"][c] + ss["fs"]
    for rows, sign in ((cs["b"][c], 1.0), (cs["a"][c], -1.0)):
        np.add.at(f, rows, sign * fb)
        np.add.at(mo, rows, sign * np.cross(ss["pos"] - b["centroid"][rows], fb))
    return f, mo


def _unbalanced(model, r):
    f, mo = _contact_loads(model)
    b = model.blocks
    g = np.asarray(model.settings.gravity, dtype=float)
    return f[r] + b["fapp"][r] + b["mass"][r] * g, mo[r] + b["mapp"][r]


def _load_family(name, which):
    def whole(rt, b):
        m, r = _row(rt, b, name)
        v = _unbalanced(m, r)[which]
        return Vec(float(v[0]), float(v[1]), float(v[2]))
    intrinsic(name, 1)(whole)
    for k, c in (("x", 0), ("y", 1), ("z", 2)):
        def comp(rt, b, c=c, full=f"{name}.{k}"):
            m, r = _row(rt, b, full)
            return float(_unbalanced(m, r)[which][c])
        intrinsic(f"{name}.{k}", 1)(comp)


# the out-of-balance force (contacts, applied force, weight) and moment about the centroid (contacts,
# applied moment) on a block as its sub-contact forces stand (a fixed block: the reaction it needs)
_load_family("block.force.unbal", 0)
_load_family("block.moment", 1)


def _face_row(rt, f, name):
    if type(f) is not int:
        raise FishValueError(f"`{name}` takes a face (from block.subcontact.face), not a {type_name(f)}")
    faces = rt.session.model.faces
    if not 1 <= f <= faces.n:
        raise FishValueError(f"`{name}`: there is no face {f}")
    return faces, f - 1


@intrinsic("block.face.pos", 1)
def _face_pos(rt, f):
    """Area centroid of a block face."""
    faces, r = _face_row(rt, f, "block.face.pos")
    return _vec(faces["centroid"], r)


@intrinsic("block.face.bface", 1)
def _face_bface(rt, f):
    """The block face a face belongs to: for a rigid block's face, the face itself; for a triangle of a
    zoned block's surface, the polygon face it lies on is not kept as a face of its own, so the triangle."""
    _face_row(rt, f, "block.face.bface")
    return f


@intrinsic("block.mass", 1)
def _block_mass(rt, b):
    m, r = _row(rt, b, "block.mass")
    return float(m.blocks["mass"][r])


@intrinsic("block.region", 1)
def _block_region(rt, b):
    m, r = _row(rt, b, "block.region")
    return int(m.blocks["region"][r])


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
