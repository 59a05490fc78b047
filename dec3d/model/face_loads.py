"""Applied face stresses on the boundary triangles of zoned blocks (``block face apply stress``).

Each loaded triangle keeps the stress applied to it (``faces.fstress``, 6 components xx yy zz xy
xz yz, tension positive); ``vertices.fface`` is recomputed from all of them: traction t = σ·n on
the triangle, force t·A shared equally (A/3) by its three gridpoints. Loads add (as 3DEC does);
``apply-remove`` clears the record of the faces in range and recomputes, so removal is exact.
Only triangles on the outside of a joined continuum take loads: a triangle whose gridpoints
(resolved to their link masters) are also a triangle of another block is interior.
"""
from __future__ import annotations

import numpy as np

from .store import Field
from .zones import zone_stores


def _ensure(model) -> None:
    zone_stores(model)
    if "fstress" not in model.faces:
        model.faces.add_field("fstress", Field((6,), np.float64, 0.0))


def _triangle_nodes(model, rows: np.ndarray) -> np.ndarray:
    f, fv = model.faces, model.face_vertices
    return fv["vertex"][f["vstart"][rows][:, None] + np.arange(3)[None, :]]


def loadable_faces(model) -> np.ndarray:
    """Mask over faces: triangles of zoned blocks on the outside of their (joined) continuum."""
    _ensure(model)
    f, v = model.faces, model.vertices
    out = np.zeros(f.n, bool)
    if not f.n:
        return out
    zoned_blk = np.zeros(model.blocks.n, bool)
    zoned_blk[v["block"][v["zoned"]]] = True
    cand = np.flatnonzero(zoned_blk[f["block"]] & (f["nvert"] == 3))
    if not len(cand):
        return out
    link = v["link"]
    master = np.where(link >= 0, link, np.arange(v.n))
    keys = np.sort(master[_triangle_nodes(model, cand)], axis=1)
    _, inv, cnt = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    out[cand[cnt[inv.ravel()] == 1]] = True
    return out


def recompute_fface(model) -> None:
    """``vertices.fface`` from the stresses recorded on the faces (current positions)."""
    _ensure(model)
    f, v = model.faces, model.vertices
    v["fface"][:] = 0.0
    rows = np.flatnonzero(np.any(f["fstress"] != 0.0, axis=1))
    if not len(rows):
        return
    nodes = _triangle_nodes(model, rows)
    p = v["pos"][nodes]
    an = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])      # outward normal times area
    s = f["fstress"][rows]
    sig = np.empty((len(rows), 3, 3))
    sig[:, 0, 0], sig[:, 1, 1], sig[:, 2, 2] = s[:, 0], s[:, 1], s[:, 2]
    sig[:, 0, 1] = sig[:, 1, 0] = s[:, 3]
    sig[:, 0, 2] = sig[:, 2, 0] = s[:, 4]
    sig[:, 1, 2] = sig[:, 2, 1] = s[:, 5]
    force = np.einsum("kij,kj->ki", sig, an) / 3.0
    for k in range(3):
        np.add.at(v["fface"], nodes[:, k], force)


def apply_face_stress(model, mask: np.ndarray, stress6: np.ndarray) -> int:
    """Add ``stress6`` to the loadable faces in ``mask``; returns how many faces took it."""
    _ensure(model)
    rows = np.flatnonzero(mask & loadable_faces(model))
    model.faces["fstress"][rows] += np.asarray(stress6, np.float64)
    recompute_fface(model)
    return len(rows)


def remove_face_stress(model, mask: np.ndarray) -> int:
    _ensure(model)
    rows = np.flatnonzero(mask & (np.any(model.faces["fstress"] != 0.0, axis=1)))
    model.faces["fstress"][rows] = 0.0
    recompute_fface(model)
    return len(rows)
