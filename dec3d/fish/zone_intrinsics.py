"""FISH zone intrinsics (deformable blocks): read the ``zones`` store of dec3d.model.zones.

A zone is handed to FISH as its id (an integer from 1, what `block.zone.list` holds and
`block.zone.find` returns; 0, FISH's null, when no zone has it), as blocks are. Names follow
Itasca's 3DEC 7 FISH reference: block.zone.list, .num, .find, .id, .block, .vol, .pos,
.stress and its six components (tension positive), .state (plastic state bits), .gp(z, i) (the gridpoint at node i, from 1),
.model (the model's name), .prop(z, name) (a property of the zone's model in the units `block zone property`
takes, or a history value of the model by its name).

A gridpoint is handed to FISH as its index: its row in the ``vertices`` store + 1 (gridpoints are
vertices, dec3d.model.zones; the vertices of rigid blocks are gridpoints too, as in 3DEC). The
index stays valid until blocks are made, deleted or zoned. block.gplist(b) (the block's gridpoints,
a list), block.gp.list, .num, .find, .id, .block
(host block id; .hostblock too), .near(x, y, z | v), .zoned, .pos, .disp, .vel, .force (with .x .y .z):
a gridpoint of a zoned block reads its own fields (displacement, velocity, unbalanced force of the
last step); a vertex of a rigid block reads the block's motion there (displacement pos - origin,
velocity v + w x (x - c)) and has no force of its own. Writes are not here yet.
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
    if st is not None and 0 < z <= st.n:
        ids = st["id"]
        if ids[z - 1] == z:                 # zones numbered 1..n in row order (the mesher's): no search
            return rt.session.model, st, z - 1
        rows = np.nonzero(ids == z)[0]
    else:
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


@intrinsic("block.zone.state", 1)
def _state(rt, z):
    """The zone's plastic state bits (Itasca's flags, as the `zones` store keeps them): 1 shear-now,
    2 tension-now, 4 shear-past, 8 tension-past; 0 never yielded (elastic zones are always 0)."""
    _, st, r = _row(rt, z, "block.zone.state")
    return int(st["state"][r])


#: ``ZMODELS[0](code)`` -> the zone model of that code (``physics.cmodels.ZoneModel``: ``name``, ``props``,
#: ``value(row, name)``, ``hist_names``), or None for null; set by dec3d.commands.fish_cmds (FISH imports no
#: physics)
ZMODELS: list = [None]


@intrinsic("block.zone.model", 1)
def _model(rt, z):
    """The name of the zone's constitutive model ('null' when none is assigned)."""
    _, st, r = _row(rt, z, "block.zone.model")
    m = ZMODELS[0](int(st["cmodel"][r])) if ZMODELS[0] is not None else None
    return "null" if m is None else m.name


@intrinsic("block.zone.prop", 2)
def _zprop(rt, z, name):
    """A property of the zone's model by the name `block zone property` uses, in its units (angles in
    degrees), or one of the model's history values by name (strain-softening's plastic strains …)."""
    fname = "block.zone.prop"
    if type(name) is not str:
        raise FishValueError(f"`{fname}` takes a property name (a string), not a {type_name(name)}")
    _, st, r = _row(rt, z, fname)
    m = ZMODELS[0](int(st["cmodel"][r])) if ZMODELS[0] is not None else None
    if m is None:
        raise FishValueError(f"`{fname}`: zone {z} has no constitutive model (null)")
    key = name.lower()
    if key in m.props:
        return float(m.value(st["prop"][r], key))
    hist = [h.lower() for h in m.hist_names]
    if key in hist:
        return float(st["hist"][r, hist.index(key)])
    have = sorted(m.props) + list(m.hist_names)
    raise FishValueError(f"`{fname}`: zone model `{m.name}` has no property '{name}' (it has {', '.join(have)})")


@intrinsic("block.zone.gp", 2)
def _zone_gp(rt, z, i):
    _, st, r = _row(rt, z, "block.zone.gp")
    n = int(st["nnode"][r])
    if type(i) is not int or not 1 <= i <= n:
        raise FishValueError(f"`block.zone.gp`: the node index must be an integer 1..{n}, not {i!r}")
    return int(st["gp"][r, i - 1]) + 1


# ---------------------------------------------------------------- gridpoints (block.gp.*)

def _gprow(rt, g, name):
    """(model, vertex row) of gridpoint index `g`."""
    if type(g) is not int:
        raise FishValueError(f"`{name}` takes a gridpoint (from block.gp.list, block.gp.near or block.zone.gp), "
                             f"not a {type_name(g)}")
    m = rt.session.model
    if not 1 <= g <= m.vertices.n:
        raise FishValueError(f"`{name}`: there is no gridpoint {g}")
    return m, g - 1


def _zoned(m, r) -> bool:
    v = m.vertices
    return "zoned" in v.fields and bool(v["zoned"][r])


def _gp_pos(m, r):
    return m.vertices["pos"][r]


def _gp_disp(m, r):
    v = m.vertices
    return v["disp"][r] if _zoned(m, r) else v["pos"][r] - v["origin"][r]


def _gp_vel(m, r):
    v = m.vertices
    if _zoned(m, r):
        return v["velocity"][r]
    b = m.blocks
    k = int(v["block"][r])
    return b["velocity"][k] + np.cross(b["spin"][k], v["pos"][r] - b["centroid"][k])


def _gp_force(m, r, name):
    if not _zoned(m, r):
        raise FishValueError(f"`{name}`: gridpoint {r + 1} is a vertex of a rigid block, which has no gridpoint "
                             "force (block.force.unbal gives the block's)")
    return m.vertices["force"][r]


@intrinsic("block.gp.list")
def _gp_list(rt):
    return list(range(1, rt.session.model.vertices.n + 1))


@intrinsic("block.gp.num")
def _gp_num(rt):
    return int(rt.session.model.vertices.n)


@intrinsic("block.gp.find", 1)
def _gp_find(rt, g):
    if type(g) is not int:
        raise FishValueError(f"`block.gp.find` takes a gridpoint index (an integer), not a {type_name(g)}")
    return g if 1 <= g <= rt.session.model.vertices.n else 0


@intrinsic("block.gp.id", 1)
def _gp_id(rt, g):
    _gprow(rt, g, "block.gp.id")
    return g


def _host(rt, g, name="block.gp.block"):
    m, r = _gprow(rt, g, name)
    return int(m.blocks["id"][int(m.vertices["block"][r])])


intrinsic("block.gp.block", 1)(_host)
intrinsic("block.gp.hostblock", 1)(lambda rt, g: _host(rt, g, "block.gp.hostblock"))


@intrinsic("block.gp.zoned", 1)
def _gp_is_zoned(rt, g):
    m, r = _gprow(rt, g, "block.gp.zoned")
    return _zoned(m, r)


@intrinsic("block.gp.near", 1, 3)
def _gp_near(rt, *xyz):
    """The gridpoint nearest (x, y, z) (or a vector); 0 when the model has none. Ties: the lowest index."""
    if len(xyz) == 1 and type(xyz[0]) is Vec:
        xyz = tuple(xyz[0])
    if len(xyz) != 3 or any(type(c) not in (int, float) for c in xyz):
        raise FishValueError("`block.gp.near` takes a vector or three numbers x, y, z")
    v = rt.session.model.vertices
    if v.n == 0:
        return 0
    d = np.einsum("ij,ij->i", v["pos"] - np.array(xyz, dtype=float), v["pos"] - np.array(xyz, dtype=float))
    return int(np.argmin(d)) + 1


def _gp_family(name, get):
    def whole(rt, g):
        m, r = _gprow(rt, g, name)
        a = get(m, r, name)
        return Vec(float(a[0]), float(a[1]), float(a[2]))
    intrinsic(name, 1)(whole)
    for k, c in (("x", 0), ("y", 1), ("z", 2)):
        def comp(rt, g, c=c, full=f"{name}.{k}"):
            m, r = _gprow(rt, g, full)
            return float(get(m, r, full)[c])
        intrinsic(f"{name}.{k}", 1)(comp)


_gp_family("block.gp.pos", lambda m, r, n: _gp_pos(m, r))
_gp_family("block.gp.disp", lambda m, r, n: _gp_disp(m, r))
_gp_family("block.gp.vel", lambda m, r, n: _gp_vel(m, r))
_gp_family("block.gp.force", _gp_force)


@intrinsic("block.gplist", 1)
def _gplist(rt, b):
    """The gridpoints of block `b`, as a list (what `loop foreach g block.gplist(b)` walks in the
    public decks, compas_3dec's displacement.dat and SAFEGO's 06_dynamic_load.dat); block.gp.next
    still walks from one of them to the next."""
    if type(b) is not int:
        raise FishValueError(f"`block.gplist` takes a block id, not a {type_name(b)}")
    m = rt.session.model
    rows = np.nonzero(m.blocks["id"] == b)[0] if m.blocks.n else ()
    if len(rows) == 0:
        raise FishValueError(f"`block.gplist`: there is no block with id {b}")
    k = int(rows[0])
    start = int(m.blocks["vert_start"][k])
    return list(range(start + 1, start + int(m.blocks["vert_count"][k]) + 1))


@intrinsic("block.gp.next", 1)
def _gp_next(rt, g):
    """The next gridpoint of the same block, 0 after its last."""
    m, r = _gprow(rt, g, "block.gp.next")
    k = int(m.vertices["block"][r])
    end = int(m.blocks["vert_start"][k]) + int(m.blocks["vert_count"][k])
    return g + 1 if r + 1 < end else 0
