"""Deformable-block state: the ``zones`` store and the gridpoint fields of ``vertices``.

The contract shared by the mesher (``dec3d.geometry.zoning`` via ``block zone generate``),
the zone kernels (``dec3d.kernels.zones``), the deformable step of the cycle
(``dec3d.physics.zones``), the commands that set conditions (``block gridpoint …``,
``block face apply …``, ``block insitu``, ``block zone …``), VTK and save files.

Gridpoints are vertices (design: "gridpoints are vertices"). A zoned block keeps a
contiguous range ``vert_start .. vert_start + vert_count`` of the ``vertices`` store, now
holding *all* its gridpoints (boundary and interior), and its faces are replaced by the
triangles of its zoned surface (``faces.nvert == 3``, counter-clockwise from outside,
``faces.source`` the index of the polygon face the triangle lies on, so face groups carry
over). Joined blocks zoned conformingly share gridpoints by *linking*: each block keeps its
own rows, and a gridpoint whose ``link`` is another row is a copy of that row (its master).
The deformable step sums forces and masses of linked rows onto their master, moves the
master, and copies its motion back, so a joined set behaves as one continuum while every
block still owns a contiguous vertex range (which the contact code relies on).

``zones``  one row per tetrahedron (a hexahedral zone is ten rows: two overlaid sets of five)
    id ()            int64  user-visible number, from 1
    block ()         int64  row of its block
    gp (10,)         int64  gridpoint rows (vertices store): 4 corners, then for a 10-node
                            tetrahedron the mid-edge nodes of edges 01 12 20 03 13 23; -1 unused
    nnode ()         int8   4 or 10
    hex ()           int64  mixed-discretization set: the hexahedral zone it belongs to, -1 none
    overlay ()       int8   0 or 1: which of the two 5-tetrahedron sets of its hexahedron; -1 none
    volume ()        m³     volume (reference configuration; updated in large strain)
    stress (6,)      Pa     xx yy zz xy xz yz, tension positive (3DEC sign convention)
    gstress (4, 6)   Pa     Gauss-point stresses of a 10-node tetrahedron (zone stress = their mean);
                            added with the first 10-node zone (``ho_fields``), as ghist
    cmodel ()        int8   constitutive model code (``kernels/zmodels``: each model's ``CODE``); 0: null
    prop (NZPROP,)   SI     constitutive properties: columns 0-7 shared (``ZP_*``), from 8 on the model's own
    hist (NZHIST,)   -      the model's history (strain-softening's hardening parameters, …): the first
                            ``NHIST`` entries of the zone's model, zeroed when a model is assigned
    ghist (4, NZHIST) -     a 10-node tetrahedron's Gauss-point histories (its ``hist`` is their mean)
    state ()         int32  plastic state bits (``ZSTATE_*``; a model's update returns the "now" bits)
    group (nslots,)  int32  group codes per slot, -1 none
    fbody (3,)       N/m³   body force per unit volume (``block zone apply force``); added by the first such
                            command (``body_force_field``): a model without the field has none

Gridpoint fields added to ``vertices`` (rigid-block vertices leave them at their fill):
    link ()          int64  -1: this row is its own master; else the master row (a shared gridpoint)
    imass ()         kg     inertial mass used by the motion update (density-scaled in static runs)
    fapp (3,)        N      applied force (``block gridpoint apply force``)
    fface (3,)       N      force of applied face stresses (``block face apply stress``), added every step
    vapp (3,)        m/s    applied velocity components (``block gridpoint apply velocity``)
    apply_fix ()     uint8  bits 0-2: the x, y, z velocity components held at ``vapp``
    zoned ()         bool   True for the gridpoints of a zoned (deformable) block
    gpos0 (3,)       m      reference positions of the real (lumped) masses and consistent gravity
                            loads: set at the first run that uses the gridpoint, kept (mass is conserved)
    gpos_geo (3,)    m      positions the zones' stiffness, quiet dashpots and table face loads were
                            last worked out on (large strain: at every detection step)
    gref ()          uint8  bit 0: ``gpos0`` set, bit 1: ``gpos_geo`` set (``physics.zones``)
(``pos``, ``velocity``, ``disp``, ``force``, ``mass`` and ``fixity`` are the vertex store's own:
``mass`` is the real lumped mass [kg], ``force`` the unbalanced force of the last step [N].)

Faces of zoned blocks gain:
    source ()        int64  the polygon face (index within its block, before zoning) this triangle lies on
"""
from __future__ import annotations

import numpy as np

from ..kernels.zmodels import CODES, NZHIST, NZPROP
from ..kernels.zmodels._common import (JOINT_SHEAR_NOW, JOINT_SHEAR_PAST, JOINT_TENSION_NOW, JOINT_TENSION_PAST,
                                       P_BULK, P_COHESION, P_DENSITY, P_SHEAR, P_TANDIL, P_TANFRIC, P_TENSION,
                                       SHEAR_NOW, SHEAR_PAST, TENSION_NOW, TENSION_PAST)
from .groups import group_field
from .store import Field, Store

_F = np.float64
_I = np.int64

#: constitutive model code of null zones (no stress, no mass); the models' codes are their
#: kernels' (``dec3d.kernels.zmodels.CODES``)
ZMODEL_NULL = 0
#: the elastic model's code: FE elements take elastic or null only
ZMODEL_ELASTIC = CODES["elastic"]

#: shared property columns of ``zones.prop`` (``kernels/zmodels/_common``); the models' own
#: columns start at ``P_OWN``
ZP_BULK = P_BULK
ZP_SHEAR = P_SHEAR
ZP_DENSITY = P_DENSITY
ZP_COHESION = P_COHESION
ZP_TANFRIC = P_TANFRIC
ZP_TENSION = P_TENSION
ZP_TANDIL = P_TANDIL

#: plastic state bits of ``zones.state`` (Itasca's shear-n, tension-n, shear-p, tension-p, and
#: the weak plane's of ubiquitous-joint zones): "now" bits are set by the step that yielded and
#: cleared by the next step that does not, "past" bits stay once set
ZSTATE_SHEAR_NOW = SHEAR_NOW
ZSTATE_TENSION_NOW = TENSION_NOW
ZSTATE_SHEAR_PAST = SHEAR_PAST
ZSTATE_TENSION_PAST = TENSION_PAST
ZSTATE_BITS = (("shear-now", SHEAR_NOW), ("tension-now", TENSION_NOW), ("shear-past", SHEAR_PAST),
               ("tension-past", TENSION_PAST), ("joint-shear-now", JOINT_SHEAR_NOW),
               ("joint-tension-now", JOINT_TENSION_NOW), ("joint-shear-past", JOINT_SHEAR_PAST),
               ("joint-tension-past", JOINT_TENSION_PAST))

#: stress components in store order
STRESS_COMPONENTS = ("xx", "yy", "zz", "xy", "xz", "yz")


def _zone_fields() -> dict[str, Field]:
    return {
        "id": Field((), _I, 0),
        "block": Field((), _I, -1),
        "gp": Field((10,), _I, -1),
        "nnode": Field((), np.int8, 4),
        "hex": Field((), _I, -1),
        "overlay": Field((), np.int8, -1),
        "volume": Field((), _F, 0.0),
        "stress": Field((6,), _F, 0.0),
        "cmodel": Field((), np.int8, ZMODEL_NULL),
        "prop": Field((NZPROP,), _F, 0.0),
        "hist": Field((NZHIST,), _F, 0.0),
        "state": Field((), np.int32, 0),
        "group": group_field(),
        "extra": Field((0,), _F, 0.0),        # FISH block.zone.extra slots (widened on first write)
    }


_GP_FIELDS = {
    "link": Field((), _I, -1),
    "imass": Field((), _F, 0.0),
    "fapp": Field((3,), _F, 0.0),
    "fface": Field((3,), _F, 0.0),
    "vapp": Field((3,), _F, 0.0),
    "apply_fix": Field((), np.uint8, 0),
    "zoned": Field((), np.bool_, False),
    "gpos0": Field((3,), _F, 0.0),
    "gpos_geo": Field((3,), _F, 0.0),
    "gref": Field((), np.uint8, 0),
}


def zone_stores(model) -> Store:
    """The model's ``zones`` store, made (with the gridpoint and face fields) on first use.
    Idempotent; restore calls it before loading a save file that has zones (gridpoint fields
    that file lacks are added with their fill here too)."""
    for key, spec in _GP_FIELDS.items():
        if key not in model.vertices:
            model.vertices.add_field(key, spec)
    if "zones" in model.stores:
        return model.store("zones")
    if "source" not in model.faces:
        model.faces.add_field("source", Field((), _I, -1))
    return model.add_store(Store("zones", _zone_fields(), capacity=256))


#: fields only 10-node zones use, added to the store with the first such zone (``ho_fields``): 320 bytes a
#: zone that a model of 4-node zones does not carry
_HO_FIELDS = {"gstress": Field((4, 6), _F, 0.0), "ghist": Field((4, NZHIST), _F, 0.0)}


def ho_fields(zs: Store) -> None:
    """Add ``gstress`` and ``ghist`` (filled with zeros) to the zones store ``zs`` when it has none."""
    for key, spec in _HO_FIELDS.items():
        if key not in zs:
            zs.add_field(key, spec)


def body_force_field(model) -> np.ndarray:
    """``zones.fbody`` (live rows), the field added with zeros if this model has none yet (a model made, or a
    save file written, before the first `block zone apply`)."""
    zs = zone_stores(model)
    if "fbody" not in zs:
        zs.add_field("fbody", Field((3,), _F, 0.0))
    return zs["fbody"]


def has_zones(model) -> bool:
    return "zones" in model.stores and model.store("zones").n > 0


def follow_block_rows(store, block_map: np.ndarray) -> None:
    """Renumber the ``block`` column of an element store (zones, FE elements) by ``block_map``
    (old block row -> new, -1 dropped) and drop the elements of dropped blocks."""
    if not store.n:
        return
    nb = block_map[store["block"]]
    store["block"][:] = nb
    keep = nb >= 0
    if not keep.all():
        store.compact(keep)


def follow_geometry(model, vmap: np.ndarray | None, block_map: np.ndarray | None = None) -> None:
    """Keep zones and gridpoint links consistent after vertex rows moved (``vmap``: old -> new
    row, -1 dropped, from ``compact_geometry``) and/or block rows moved (``block_map``, from
    ``Store.compact``). Zones of dropped blocks go away; links to dropped rows are cleared."""
    if "feblocks" in model.stores:                 # FE-block elements (dec3d.model.feblocks)
        from .feblocks import follow_feblocks
        follow_feblocks(model, vmap, block_map)
    if "zones" not in model.stores:
        return
    zs = model.store("zones")
    if block_map is not None:
        follow_block_rows(zs, block_map)
    if vmap is None:
        return
    if zs.n:
        gp = zs["gp"]
        gp[:] = np.where(gp >= 0, vmap[np.maximum(gp, 0)], -1)
    link = model.vertices["link"]
    link[:] = np.where(link >= 0, vmap[np.maximum(link, 0)], -1)


def install_block_mesh(model, row: int, points: np.ndarray, tets: np.ndarray, tris: np.ndarray,
                       tri_source: np.ndarray, hexid: np.ndarray | None = None,
                       overlay: np.ndarray | None = None, face_rows: np.ndarray | None = None,
                       compact: bool = True) -> slice:
    """Make block ``row`` a zoned (deformable) block with this mesh.

    points (n, 3): its gridpoints (any order); tets (m, 4) or (m, 10): zone node lists, local
    indices into ``points``, positively oriented (corners 0-3 right-handed, then mid-edge nodes
    of edges 01 12 20 03 13 23); tris (k, 3): the boundary triangles, counter-clockwise seen
    from outside; tri_source (k,): index (within the block, before zoning) of the polygon face
    each triangle lies on (its groups carry over); hexid/overlay (m,): mixed-discretization
    sets of hexahedral zoning (local hexahedron number and 0/1), or None; face_rows (k,): the
    face rows each triangle takes its groups from (default: the polygon faces ``tri_source``;
    re-zoning an already zoned block passes its old triangles); compact=False leaves the block's
    old vertex and face rows in place (unreferenced) for the caller to drop once, with
    ``compact_geometry`` and ``follow_geometry``, after installing many blocks.

    The block's vertices and faces are replaced (old rows compacted away, other stores
    follow), its kind becomes deformable, its gridpoints get lumped masses later (the
    deformable step). Returns the slice of the new zone rows. Links between joined blocks
    are set by the caller (``link`` field) after all blocks are installed.
    """
    from dec3d.geometry.assemble import compact_geometry, write_pieces
    from .model import KIND_DEFORMABLE

    zs = zone_stores(model)
    b, fs = model.blocks, model.faces
    points = np.ascontiguousarray(points, dtype=_F)
    tets = np.asarray(tets, dtype=_I)
    tris = np.asarray(tris, dtype=_I)
    f0 = int(b["face_start"][row])
    fsrc = f0 + np.asarray(tri_source, dtype=_I) if face_rows is None else np.asarray(face_rows, dtype=_I)
    write_pieces(model, np.array([row], _I), points, np.full(len(points), -1, _I),
                 np.array([len(points)], _I), np.full(len(tris), 3, _I), fsrc,
                 np.array([len(tris)], _I), tris.ravel())
    fst, fc = int(b["face_start"][row]), int(b["face_count"][row])
    fs["source"][fst:fst + fc] = tri_source
    if compact:
        follow_geometry(model, compact_geometry(model))
    vs = model.vertices
    v0, nv = int(b["vert_start"][row]), int(b["vert_count"][row])
    vs["zoned"][v0:v0 + nv] = True
    vs["link"][v0:v0 + nv] = -1
    b["kind"][row] = KIND_DEFORMABLE
    m = len(tets)
    sl = zs.append(m)
    nn = tets.shape[1]
    if nn == 10:
        ho_fields(zs)
    zs["gp"][sl, :nn] = tets + v0
    zs["nnode"][sl] = nn
    zs["block"][sl] = row
    start_id = int(zs["id"][: sl.start].max()) + 1 if sl.start else 1
    zs["id"][sl] = np.arange(start_id, start_id + m)
    if hexid is not None:
        base = int(zs["hex"][: sl.start].max()) + 1 if sl.start else 0
        zs["hex"][sl] = np.asarray(hexid, _I) + max(base, 0)
        zs["overlay"][sl] = np.asarray(overlay, np.int8)
    p = points[tets[:, :4]]
    zs["volume"][sl] = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6.0
    return sl
