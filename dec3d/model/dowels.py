"""The dowels of hybrid bolts (``structure hybrid …``): shear springs where a bolt (a cable,
``dec3d.model.cables``) crosses the contact between two blocks. Physics ``dec3d.physics.dowels``,
kernel ``dec3d.kernels.dowel``.

``cable_dowels``  one row per joint crossing
    id (), cable ()   int64  dowel id (from 1), the bolt's cable id
    seg ()            int64  row of the cable element that holds the crossing (its axis is the bolt's)
    blk (2,)          int64  block rows of side A (where the bolt comes from) and side B
    hz (2,)           int8   0: that side is rigid; else the code of its element (``model.hosts``: a 4-node
                      or 10-node zone, an FE brick), hzone (2,) its row, hgp (2, NHOST) its node rows,
                      hw (2, NHOST) the weights (shape functions) of a point just inside it
    pos (3,)          m      the dowel point (on the contact, moved with the mean of its sides)
    axis (3,)                the bolt's unit axis as created (the shear is what is across it)
    prop (3,)         dowel-stiffness [N/m], dowel-yield [N], dowel-rupture [m]
    fs (3,)           N      shear force on side B (A carries −fs)
    us (3,)           m      accumulated shear displacement of B against A across the bolt
    moment (2, 3)     N·m    moments of the forces on A and B about their centroids (last step)
    state ()          int32  1 yielding now, 2 yielded, 4 ruptured
    group (1,)        int32
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.dowel import NDPROP

from .groups import group_field
from .hosts import NHOST, host_element, widen
from .model import KIND_RIGID, Model
from .store import Field, Store

DOWELS = "cable_dowels"
#: dowel property names, in ``prop`` column order
DPROPS = ("dowel-stiffness", "dowel-yield", "dowel-rupture")
assert len(DPROPS) == NDPROP


def _fields() -> dict[str, Field]:
    v3 = Field((3,), np.float64, 0.0)
    return {"id": Field((), np.int64, 0), "cable": Field((), np.int64, 0), "seg": Field((), np.int64, -1),
            "blk": Field((2,), np.int64, -1), "hz": Field((2,), np.int8, 0), "hzone": Field((2,), np.int64, -1),
            "hgp": Field((2, NHOST), np.int64, -1), "hw": Field((2, NHOST), np.float64, 0.0), "pos": v3, "axis": v3,
            "prop": Field((NDPROP,), np.float64, 0.0), "fs": v3, "us": v3, "moment": Field((2, 3), np.float64, 0.0),
            "state": Field((), np.int32, 0), "group": group_field()}


def dowel_store(model: Model) -> Store:
    if DOWELS not in model.stores:
        model.add_store(Store(DOWELS, _fields()))
    widen(model.stores[DOWELS])
    return model.stores[DOWELS]


def has_dowels(model: Model) -> bool:
    return DOWELS in model.stores and model.stores[DOWELS].n > 0


def line_intervals(model: Model, p1, p2, tol: float) -> list[tuple[float, float, int]]:
    """(t_in, t_out, block row) of each visible block the segment p1 → p2 (t in [0, 1]) passes
    through over more than ``tol``, sorted by t_in."""
    b, f = model.blocks, model.faces
    fb = f["block"]
    ok = fb >= 0
    d = np.asarray(p2, float) - np.asarray(p1, float)
    size = float(np.linalg.norm(d))
    n = f["normal"][ok]
    nd = n @ d
    s = np.einsum("fk,fk->f", f["centroid"][ok] - np.asarray(p1, float)[None, :], n)
    rows = fb[ok]
    tin = np.zeros(b.n)
    tout = np.ones(b.n)
    empty = np.zeros(b.n, bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = s / nd
    ent, ext, par = nd < -1e-300, nd > 1e-300, np.abs(nd) <= 1e-300
    np.maximum.at(tin, rows[ent], t[ent])
    np.minimum.at(tout, rows[ext], t[ext])
    np.logical_or.at(empty, rows[par], s[par] < -tol)
    keep = ~empty & ~b["hidden"] & (b["face_count"] > 0) & ((tout - tin) * size > tol)
    out = [(float(tin[r]), float(tout[r]), int(r)) for r in np.flatnonzero(keep)]
    return sorted(out)


def crossings(model: Model, p1, p2, tol: float) -> list[tuple[float, int, int]]:
    """(t, block A, block B) where the segment p1 → p2 leaves block A into block B across their
    common face (the one's t_out and the other's t_in within ``tol``)."""
    size = float(np.linalg.norm(np.asarray(p2, float) - np.asarray(p1, float)))
    iv = line_intervals(model, p1, p2, tol)
    out = []
    for ta, (a_in, a_out, a) in enumerate(iv):
        for b_in, b_out, b in iv:
            if b != a and abs(b_in - a_out) * size <= max(tol, 1e-9) and b_out > a_out and a_out < 1.0:
                out.append((0.5 * (a_out + b_in), a, b))
                break
    return out


def add_dowels(model: Model, cable_id: int, p1, p2, seg_rows: np.ndarray, tol: float, group: str | None):
    """Dowels at every joint crossing of the straight bolt p1 → p2 whose elements are ``seg_rows``
    (equal, in order). Returns (number added, message or None when a crossing side has no element
    there that can hold it)."""
    st = dowel_store(model)
    p1, p2 = np.asarray(p1, float), np.asarray(p2, float)
    d = p2 - p1
    size = float(np.linalg.norm(d))
    eps = max(10 * tol, 1e-6 * size) / size
    found = crossings(model, p1, p2, tol)
    if not found:
        return 0, None
    b = model.blocks
    sl = st.append(len(found))
    rows = np.arange(sl.start, sl.stop)
    did0 = int(st["id"][: sl.start].max(initial=0)) + 1
    nseg = len(seg_rows)
    for k, (t, ba, bb) in enumerate(found):
        r = rows[k]
        st["id"][r] = did0 + k
        st["cable"][r] = cable_id
        st["seg"][r] = seg_rows[min(int(t * nseg), nseg - 1)]
        st["blk"][r] = (ba, bb)
        x = p1 + t * d
        st["pos"][r] = x
        st["axis"][r] = d / size
        for side, (blk, tt) in enumerate(((ba, t - eps), (bb, t + eps))):
            if b["kind"][blk] == KIND_RIGID:
                continue
            z = host_element(model, blk, p1 + tt * d, max(tol, 1e-9))
            if z is None:
                st.compact(np.arange(st.n) < sl.start)
                return 0, ("the bolt crosses a joint into a deformable block but no zone or FE element of it "
                           "holds the crossing (is the block zoned or meshed?)")
            st["hz"][r, side], st["hzone"][r, side], st["hgp"][r, side], st["hw"][r, side] = z
    if group:
        model.groups.assign(st, rows, group)
    return len(found), None


def _side_host(model: Model, st, i: int, side: int):
    """``host_element`` of side ``side`` of dowel ``i`` at the point ``add_dowels`` took: just inside that
    side of the joint, by its tolerance and offset from the bolt's length as made (its end nodes' first
    positions)."""
    nodes = model.stores.get("cable_nodes")
    at = np.flatnonzero(nodes["cable"] == st["cable"][i]) if nodes is not None else np.zeros(0, np.int64)
    p0 = nodes["pos"][at] - nodes["disp"][at] if at.size else np.zeros((1, 3))
    size = float(np.linalg.norm(p0[-1] - p0[0]))
    tol = max(float(model.tolerance), 1e-9 * size)
    off = max(10 * tol, 1e-6 * size)
    x = st["pos"][i] + (off if side else -off) * st["axis"][i]
    return host_element(model, int(st["blk"][i, side]), x, max(tol, 1e-9))


def rehost_dowels(model: Model) -> int:
    """After blocks were zoned (or made FE blocks): a dowel side held by such a block as a rigid body
    (``hz`` 0) takes the zone or element holding a point just inside that side of the joint (as
    ``add_dowels`` does), and the load it left in the block's applied force and moment is taken back
    (from the next step it goes to the element's nodes). Returns the sides moved; a side no element
    holds stays as it was."""
    if not has_dowels(model):
        return 0
    st = dowel_store(model)
    b = model.blocks
    moved = 0
    for i in range(st.n):
        for side in range(2):
            blk = int(st["blk"][i, side])
            if blk < 0 or st["hz"][i, side] != 0 or b["kind"][blk] == KIND_RIGID:
                continue
            z = _side_host(model, st, i, side)
            if z is None:
                continue
            sg = -1.0 if side == 0 else 1.0
            b["fapp"][blk] -= sg * st["fs"][i]
            b["mapp"][blk] -= st["moment"][i, side]
            st["hz"][i, side], st["hzone"][i, side], st["hgp"][i, side], st["hw"][i, side] = z
            moved += 1
    return moved


def remap_dowels(model: Model, remap: np.ndarray) -> int:
    """After blocks are deleted (old row -> new row, -1 gone): dowels with a side gone are dropped
    (their last forces stay with the surviving block's applied loads: removed here). Returns how many."""
    if not has_dowels(model):
        return 0
    st = dowel_store(model)
    blk = st["blk"]
    new = remap[blk]
    gone = (new < 0).any(axis=1)
    b = model.blocks
    for i in np.flatnonzero(gone):
        for side in range(2):
            r = new[i, side]
            if r >= 0 and st["hz"][i, side] == 0:
                sg = -1.0 if side == 0 else 1.0
                b["fapp"][r] -= sg * st["fs"][i]
                b["mapp"][r] -= st["moment"][i, side]
    blk[:] = np.where(new >= 0, new, -1)
    for i in np.flatnonzero(~gone):
        for side in range(2):
            if st["hz"][i, side]:
                z = _side_host(model, st, i, side)
                if z is not None:
                    st["hz"][i, side], st["hzone"][i, side], st["hgp"][i, side], st["hw"][i, side] = z
    if gone.any():
        st.compact(~gone)
    return int(gone.sum())
