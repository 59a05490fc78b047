"""FE-block state: the ``feblocks`` store (one row per 20-node brick element).

FE blocks (FE-block text, shared/seeds/003_*; ``model configure feblock``, ``feblock generate``)
are blocks of kind ``KIND_FE`` whose vertex range holds their element nodes, which are
gridpoints in the sense of ``dec3d.model.zones`` (``zoned`` True, the same ``link imass fapp
fface vapp apply_fix`` fields, so ``block gridpoint …`` conditions act on them), and whose
faces are the triangles of their surface: every boundary element face is split into eight
triangles fanned around a mid-face *slave* node (text, "Element Implementation in 3DEC").
Slave nodes are vertex rows with ``feslave`` True: they carry no mass; their motion is
interpolated from the element's 20 masters and forces put on them (contacts, loads) go to the
masters by the text's Eq. (9) (``kernels.feblock.feb_slave_interp`` / ``feb_slave_forces``).
The deformable step (``dec3d.physics.zones``) is to move masters only and call those two.

``feblocks``  one row per element
    id ()            int64  user-visible number, from 1
    block ()         int64  row of its block
    nodes (20,)      int64  node rows (vertices store) in the corrected Table 1 order (VTK 25 / C3D20)
    slaves (7,)      int64  rows of slave nodes 21-27 (mid-faces y3 = -1, 1, y2 = -1, 1, y1 = -1, 1,
                            centre); -1 where not made (inner faces; the centre is never made)
    nq ()            int8   Gauss rule: 2 (2 x 2 x 2, the text's default) or 3 (3 x 3 x 3)
    volume ()        m³     volume (reference configuration)
    centroid (3,)    m      mean of the 8 corners (reference configuration): the point range elements test
    stress (6,)      Pa     xx yy zz xy xz yz, tension positive: volume-weighted mean of gstress
    gstress (27, 6)  Pa     Gauss-point stresses (the first nq³ rows used), y1 fastest; with
                            hourglass control, rows 8-13 hold its stresses (``kernels.feblock_hg``)
    hourglass ()     -      eps_h of the hourglass control of a 2 x 2 x 2 element (0: none). Set
                            to ``HOURGLASS`` when the element is made if its mesh leaves it exposed
                            (``exposed_elements``), else 0; ``feblock change hourglass`` sets it
    cmodel ()        int8   constitutive model code (``zones.ZMODEL_*``); 0: none assigned
    prop (NZPROP,)   SI     constitutive properties by ``zones.ZP_*`` column
    state ()         int32  plastic state bits
    gravity ()       uint8  1: the element carries its consistent gravity forces (Eq. 8) under
                            `model gravity`; 0: not (`feblock gravity delete`, dec3d's reading)
    group (nslots,)  int32  group codes per slot, -1 none

Vertex field added:
    feslave ()       bool   True for the slave nodes of FE blocks
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.feblock import FACES, feb_volume
from dec3d.kernels.feblock_hg import HOURGLASS

from .groups import group_field
from .store import Field, Store
from .zones import NZPROP, ZMODEL_NULL, follow_block_rows, zone_stores

_F = np.float64
_I = np.int64

NGAUSS_MAX = 27


def _fields() -> dict[str, Field]:
    return {
        "id": Field((), _I, 0),
        "block": Field((), _I, -1),
        "nodes": Field((20,), _I, -1),
        "slaves": Field((7,), _I, -1),
        "nq": Field((), np.int8, 2),
        "volume": Field((), _F, 0.0),
        "centroid": Field((3,), _F, 0.0),
        "stress": Field((6,), _F, 0.0),
        "gstress": Field((NGAUSS_MAX, 6), _F, 0.0),
        "hourglass": Field((), _F, 0.0),
        "cmodel": Field((), np.int8, ZMODEL_NULL),
        "prop": Field((NZPROP,), _F, 0.0),
        "state": Field((), np.int32, 0),
        "gravity": Field((), np.uint8, 1),
        "group": group_field(),
    }


def feblock_store(model) -> Store:
    """The model's ``feblocks`` store, made (with the gridpoint fields of ``zones`` and the
    ``feslave`` vertex field) on first use. Idempotent."""
    zone_stores(model)
    if "feblocks" in model.stores:
        es = model.store("feblocks")
        if "gravity" not in es:                  # (a model saved before `feblock gravity`)
            es.add_field("gravity", Field((), np.uint8, 1))
        return es
    if "feslave" not in model.vertices:
        model.vertices.add_field("feslave", Field((), np.bool_, False))
    return model.add_store(Store("feblocks", _fields(), capacity=64))


def set_material(model, rows: np.ndarray, cmodel: int | None = None, young=None, poisson=None, bulk=None,
                 shear=None, density=None) -> None:
    """Constitutive model and properties of FE elements ``rows`` (``zones.ZP_*`` columns; moduli
    kept as bulk and shear, young/poisson converted by K = E / (3 (1 - 2 nu)), G = E / (2 (1 + nu));
    one of young/poisson alone keeps the other as the element's present K, G give it). The caller
    has checked the values; raises ValueError when young or poisson alone meets an element
    without moduli."""
    from .zones import ZMODEL_NULL, ZP_BULK, ZP_DENSITY, ZP_SHEAR

    es = model.store("feblocks")
    rows = np.asarray(rows, _I)
    if (young is None) != (poisson is None) and len(rows):
        have = (es["prop"][rows, ZP_BULK] > 0) & (es["prop"][rows, ZP_SHEAR] > 0)
        if not have.all():
            raise ValueError(f"element {int(es['id'][rows[~have][0]])} has no elastic moduli yet")
    if cmodel is not None:
        es["cmodel"][rows] = cmodel
        if cmodel == ZMODEL_NULL:
            es["stress"][rows] = 0.0
            es["gstress"][rows] = 0.0
    prop = es["prop"]
    if (young is not None or poisson is not None) and len(rows):
        K, G = prop[rows, ZP_BULK], prop[rows, ZP_SHEAR]
        with np.errstate(divide="ignore", invalid="ignore"):
            E = young if young is not None else 9.0 * K * G / (3.0 * K + G)
            nu = poisson if poisson is not None else (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G))
        prop[rows, ZP_BULK] = E / (3.0 * (1.0 - 2.0 * np.asarray(nu)))
        prop[rows, ZP_SHEAR] = E / (2.0 * (1.0 + np.asarray(nu)))
    if bulk is not None:
        prop[rows, ZP_BULK] = bulk
    if shear is not None:
        prop[rows, ZP_SHEAR] = shear
    if density is not None:
        prop[rows, ZP_DENSITY] = density


def has_feblocks(model) -> bool:
    return "feblocks" in model.stores and model.store("feblocks").n > 0


def follow_feblocks(model, vmap: np.ndarray | None, block_map: np.ndarray | None = None) -> None:
    """Keep element node and block rows valid after ``compact_geometry`` / ``Store.compact``
    (called by ``zones.follow_geometry``): elements of dropped blocks go away."""
    es = model.store("feblocks")
    if block_map is not None:
        follow_block_rows(es, block_map)
    if vmap is not None and es.n:
        for key in ("nodes", "slaves"):
            a = es[key]
            a[:] = np.where(a >= 0, vmap[np.maximum(a, 0)], -1)


def element_volumes(points: np.ndarray, elems: np.ndarray) -> tuple[np.ndarray, int]:
    """Volumes of elements given by local node lists; the first element (local index) whose
    det J is not positive at a Gauss point, -1 if none."""
    vol = np.zeros(len(elems))
    bad = feb_volume(np.ascontiguousarray(points, _F), np.ascontiguousarray(elems, _I),
                     np.arange(len(elems), dtype=_I), vol)
    return vol, int(bad)


def install_feblock_mesh(model, row: int, points: np.ndarray, elems: np.ndarray, slaves: np.ndarray,
                         tris: np.ndarray, tri_source: np.ndarray, nmaster: int, nq: int = 2) -> slice:
    """Make block ``row`` an FE block with this mesh (``geometry.febmesh.brick_mesh``).

    points (m, 3): master nodes (the first ``nmaster``) then slave nodes; elems (ne, 20) and
    slaves (ne, 7) local indices (-1 none); tris (k, 3) the surface triangles (counter-clockwise
    from outside); tri_source (k,) the block face (index within the block, before meshing) each
    lies on, whose groups carry over. The block's vertices and faces are replaced (other stores
    follow), its kind becomes ``KIND_FE``. The caller has checked the elements (positive det J).
    Returns the slice of the new element rows."""
    from dec3d.geometry.assemble import compact_geometry, write_pieces

    from .zones import follow_geometry

    feblock_store(model)
    b, fs = model.blocks, model.faces
    points = np.ascontiguousarray(points, dtype=_F)
    tris = np.asarray(tris, dtype=_I)
    f0 = int(b["face_start"][row])
    write_pieces(model, np.array([row], _I), points, np.full(len(points), -1, _I),
                 np.array([len(points)], _I), np.full(len(tris), 3, _I), f0 + np.asarray(tri_source, _I),
                 np.array([len(tris)], _I), tris.ravel())
    fst, fc = int(b["face_start"][row]), int(b["face_count"][row])
    fs["source"][fst:fst + fc] = tri_source
    follow_geometry(model, compact_geometry(model))
    return _attach(model, row, points, elems, slaves, nmaster, nq)


def exposed_elements(elems: np.ndarray) -> np.ndarray:
    """Elements (local node lists (ne, 20)) whose 2 x 2 x 2 zero-energy modes their mesh does not
    hold: those with no neighbour across any of the four faces normal to two of their master axes
    (a row of elements one element across in two directions, as the FE-block text's cantilever).
    Measured on regular meshes (free, reduced rule): 1 x 1 x 1 elements have 6 spurious modes,
    2 x 1 x 1 three, n x 1 x 1 more with n; 2 x 2 x 1, 3 x 3 x 1 and 2 x 2 x 2 none (the face
    neighbours lock the modes), so elements with neighbours across faces of two axes need no
    control. Returns a bool (ne,) mask."""
    elems = np.asarray(elems, _I)
    ne = len(elems)
    if not ne:
        return np.zeros(0, bool)
    keys = np.sort(elems[:, FACES[:, :4]], axis=2).reshape(ne * 6, 4)
    _, inv, cnt = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inner = (cnt[inv.ravel()] > 1).reshape(ne, 6)
    # FACES: 0, 1 normal to y3; 2, 3 normal to y2; 4, 5 normal to y1
    held = np.stack([inner[:, 4] | inner[:, 5], inner[:, 2] | inner[:, 3], inner[:, 0] | inner[:, 1]], axis=1)
    return held.sum(axis=1) <= 1


def _attach(model, row, points, elems, slaves, nmaster, nq) -> slice:
    """Gridpoint fields of block ``row``'s (new) vertices and its element rows."""
    from .model import KIND_FE

    es = feblock_store(model)
    b = model.blocks
    vs = model.vertices
    v0, nv = int(b["vert_start"][row]), int(b["vert_count"][row])
    vs["zoned"][v0:v0 + nv] = True
    vs["link"][v0:v0 + nv] = -1
    vs["feslave"][v0:v0 + nv] = False
    vs["feslave"][v0 + nmaster:v0 + nv] = True
    b["kind"][row] = KIND_FE
    m = len(elems)
    sl = es.append(m)
    es["nodes"][sl] = np.asarray(elems, _I) + v0
    sv = np.asarray(slaves, _I)
    es["slaves"][sl] = np.where(sv >= 0, sv + v0, -1)
    es["block"][sl] = row
    es["nq"][sl] = nq
    es["hourglass"][sl] = np.where(exposed_elements(elems), HOURGLASS, 0.0) if nq == 2 else 0.0
    start_id = int(es["id"][: sl.start].max()) + 1 if sl.start else 1
    es["id"][sl] = np.arange(start_id, start_id + m)
    vol, _ = element_volumes(points, elems)
    es["volume"][sl] = vol
    es["centroid"][sl] = np.asarray(points)[np.asarray(elems)[:, :8]].mean(axis=1)
    return sl


def add_feblock(model, points: np.ndarray, elems: np.ndarray, slaves: np.ndarray, tris: np.ndarray,
                nmaster: int, nq: int = 2) -> int:
    """A new FE block (``feblock read``) from a mesh and its surface (``geometry.febmesh.
    mesh_surface``): every point is a vertex of the block, the triangles its faces. Returns its row."""
    from dec3d.geometry.polyhedron import Poly

    from .blocks import add_blocks
    from .model import KIND_FE

    feblock_store(model)
    tris = np.asarray(tris, _I)
    poly = Poly(np.ascontiguousarray(points, _F), np.arange(0, 3 * len(tris) + 1, 3, dtype=_I), tris.ravel())
    row = int(add_blocks(model, [poly], kind=KIND_FE)[0])
    _attach(model, row, points, elems, slaves, nmaster, nq)
    return row
