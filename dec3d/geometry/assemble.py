"""Writing polyhedra into the model's stores, and dropping geometry no block uses.

Pieces arrive as one batch of flat arrays (what the cutting kernel returns, or what
``polys_to_batch`` makes from ``Poly`` objects):

    pos (V, 3)        vertex positions, piece after piece
    vsrc (V,)         vertex row each new vertex copies its state from, -1 for defaults
    piece_nv (k,)     vertices per piece
    fn (F,)           vertices per face, face after face
    fsrc (F,)         face row each new face copies its groups from, -1 for none
    piece_nf (k,)     faces per piece
    fv (Σfn,)         face loops, vertex indices local to their piece

Each piece gets contiguous rows in ``vertices``, ``faces`` and ``face_vertices``.
A block whose geometry is replaced leaves its old rows behind as garbage until
``compact_geometry`` runs. Duck-typed on the model (no import of ``dec3d.model``).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from .mass import range_index, update_face_geometry, update_mass_properties
from .polyhedron import Poly

_KEEP_VERTEX = ("pos", "block", "origin")
_KEEP_FACE = ("block", "vstart", "nvert", "normal", "area", "centroid")


def polys_to_batch(polys: Sequence[Poly]):
    """Flatten ``Poly`` objects to (pos, vsrc, piece_nv, fn, fsrc, piece_nf, fv)."""
    pos = np.concatenate([p.vertices for p in polys]).astype(np.float64)
    piece_nv = np.array([len(p.vertices) for p in polys], dtype=np.int64)
    piece_nf = np.array([p.nfaces for p in polys], dtype=np.int64)
    fn = np.concatenate([np.diff(p.face_ptr) for p in polys]).astype(np.int64)
    fv = np.concatenate([p.face_idx for p in polys]).astype(np.int64)
    vsrc = np.full(len(pos), -1, dtype=np.int64)
    fsrc = np.full(len(fn), -1, dtype=np.int64)
    return pos, vsrc, piece_nv, fn, fsrc, piece_nf, fv


def _copy_rows(store, dst: np.ndarray, src: np.ndarray, skip: tuple[str, ...]) -> None:
    has = src >= 0
    if not has.any():
        return
    d, s = dst[has], src[has]
    for key in store.fields:
        if key not in skip:
            arr = store.full(key)
            arr[d] = arr[s]


def _set_origins(model, block_rows, new_v, vsrc, piece_nv) -> None:
    """Origins of new vertices (where each was when its block was made; see ``dec3d.model.kinematics``).

    A vertex where its source vertex is keeps the source's origin. Any other vertex of a piece of an
    existing block (made by a cut or a refinement) is taken back through that block's rigid motion:
    origin = x̄₀ + Rᵀ (x − x̄), fitted (Kabsch) on the old block's vertices and their origins, x̄ and x̄₀
    their means. A vertex of a fresh block is its own origin (less the block's ``disp``, zero then).
    Runs before the pieces' vertex ranges replace the old block's."""
    vs, b = model.vertices, model.blocks
    vpos, origin, vblock = vs.full("pos"), vs.full("origin"), vs.full("block")
    src_ok = vsrc >= 0
    same = src_ok.copy()
    same[src_ok] = (vpos[new_v[src_ok]] == vpos[vsrc[src_ok]]).all(axis=1)
    origin[new_v[same]] = origin[vsrc[same]]
    rest = ~same
    if not rest.any():
        return
    piece = np.repeat(np.arange(len(block_rows)), piece_nv)
    parent = np.full(len(block_rows), -1, dtype=np.int64)
    first = np.flatnonzero(src_ok)[::-1]                 # reversed: the first sourced vertex of a piece wins
    parent[piece[first]] = vblock[vsrc[first]]
    fresh = new_v[rest]
    origin[fresh] = vpos[fresh] - b["disp"][block_rows[piece[rest]]]
    for pr in np.unique(parent[piece[rest]]):
        if pr < 0:
            continue
        sel = new_v[rest & (parent[piece] == pr)]
        st, c = int(b["vert_start"][pr]), int(b["vert_count"][pr])
        p_old, o_old = vpos[st:st + c], origin[st:st + c]
        if (p_old == o_old).all():                      # the old block has not moved
            origin[sel] = vpos[sel]
            continue
        mp, mo = p_old.mean(axis=0), o_old.mean(axis=0)
        u, _, vt = np.linalg.svd((p_old - mp).T @ (o_old - mo))
        d = np.sign(np.linalg.det(u @ vt)) or 1.0
        rot = u @ np.diag([1.0, 1.0, d]) @ vt              # origin arms -> current arms
        origin[sel] = mo + (vpos[sel] - mp) @ rot


def write_pieces(model, block_rows, pos, vsrc, piece_nv, fn, fsrc, piece_nf, fv) -> None:
    """Give blocks ``block_rows`` (one per piece, rows already live) the pieces' geometry,
    then recompute their faces' geometry and their mass properties."""
    vs, fs, fvs = model.vertices, model.faces, model.face_vertices
    block_rows = np.asarray(block_rows, dtype=np.int64)
    k = len(block_rows)
    vsl = vs.append(len(pos))
    new_v = np.arange(vsl.start, vsl.stop, dtype=np.int64)
    vs.full("pos")[vsl] = pos
    vs.full("block")[vsl] = np.repeat(block_rows, piece_nv)
    vsrc = np.asarray(vsrc, dtype=np.int64)
    _copy_rows(vs, new_v, vsrc, _KEEP_VERTEX)
    _set_origins(model, block_rows, new_v, vsrc, piece_nv)

    piece_vstart = vsl.start + np.concatenate(([0], np.cumsum(piece_nv)[:-1])).astype(np.int64)
    fsl = fs.append(len(fn))
    new_f = np.arange(fsl.start, fsl.stop, dtype=np.int64)
    fvsl = fvs.append(int(np.sum(fn)))
    piece_of_face = np.repeat(np.arange(k), piece_nf)
    fs.full("block")[fsl] = block_rows[piece_of_face]
    fs.full("nvert")[fsl] = fn
    fs.full("vstart")[fsl] = fvsl.start + np.concatenate(([0], np.cumsum(fn)[:-1])).astype(np.int64)
    _copy_rows(fs, new_f, np.asarray(fsrc, dtype=np.int64), _KEEP_FACE)
    fvs.full("vertex")[fvsl] = np.asarray(fv, dtype=np.int64) + np.repeat(piece_vstart[piece_of_face], fn)

    b = model.blocks
    b["vert_start"][block_rows] = piece_vstart
    b["vert_count"][block_rows] = piece_nv
    b["face_start"][block_rows] = fsl.start + np.concatenate(([0], np.cumsum(piece_nf)[:-1])).astype(np.int64)
    b["face_count"][block_rows] = piece_nf
    update_face_geometry(model, new_f)
    update_mass_properties(model, block_rows)


def compact_geometry(model) -> np.ndarray | None:
    """Drop vertex, face and face-loop rows that no live block's ranges cover. Returns the
    old-row -> new-row map of the vertices (-1: dropped), or None when nothing moved, so
    that stores holding vertex rows (zones, gridpoint links) can follow."""
    b, vs, fs, fvs = model.blocks, model.vertices, model.faces, model.face_vertices
    vkeep = np.zeros(vs.n, dtype=bool)
    vkeep[range_index(b["vert_start"], b["vert_count"])] = True
    fkeep = np.zeros(fs.n, dtype=bool)
    fkeep[range_index(b["face_start"], b["face_count"])] = True
    if vkeep.all() and fkeep.all():
        return None
    fvkeep = np.zeros(fvs.n, dtype=bool)
    fvkeep[range_index(fs["vstart"][fkeep], fs["nvert"][fkeep])] = True
    vmap = vs.compact(vkeep)
    fmap = fs.compact(fkeep)
    fvmap = fvs.compact(fvkeep)
    fvs["vertex"][:] = vmap[fvs["vertex"]]
    fs["vstart"][:] = fvmap[fs["vstart"]]
    b["vert_start"][:] = vmap[b["vert_start"]]
    b["face_start"][:] = fmap[b["face_start"]]
    return vmap


def block_poly(model, row: int) -> Poly:
    """The current geometry of one block as a ``Poly`` (vertex indices local to the block)."""
    b, f = model.blocks, model.faces
    vs, vc = int(b["vert_start"][row]), int(b["vert_count"][row])
    fs, fc = int(b["face_start"][row]), int(b["face_count"][row])
    nvert = f["nvert"][fs:fs + fc]
    loops = model.face_vertices["vertex"][range_index(f["vstart"][fs:fs + fc], nvert)] - vs
    ptr = np.concatenate(([0], np.cumsum(nvert))).astype(np.int64)
    return Poly(model.vertices["pos"][vs:vs + vc].copy(), ptr, loops.astype(np.int64))
