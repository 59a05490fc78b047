"""``block face triangulate radial | radial-8 | edge-max <f>``: triangular faces for more
sub-contacts on rigid blocks.

* ``radial``: each face becomes a fan of triangles around its area centroid (k triangles
  for a k-gon);
* ``radial-8``: the mid-point of every edge is added too (shared by the two faces on the
  edge), giving 2k triangles (8 for a quadrilateral);
* ``edge-max f``: ``radial``, then every triangle of the block is split into four at its
  edge mid-points as many times as needed for no edge to exceed f.

Mid-points are shared between neighbouring triangles and faces of a block, so the surface
stays closed. The block's shape, volume and mass properties do not change. Triangles keep
the groups of the face they came from.
"""
from __future__ import annotations

import math

import numpy as np

from .assemble import compact_geometry, write_pieces
from .errors import GeometryError


class _Builder:
    """Vertices of one block being re-faced, with mid-points made once per edge."""

    def __init__(self, pos: np.ndarray, src: np.ndarray):
        self.pos = [p for p in pos]
        self.src = list(src)
        self.mid: dict[tuple[int, int], int] = {}

    def add(self, p, src: int) -> int:
        self.pos.append(np.asarray(p, dtype=np.float64))
        self.src.append(src)
        return len(self.pos) - 1

    def midpoint(self, a: int, b: int) -> int:
        key = (a, b) if a < b else (b, a)
        if key not in self.mid:
            self.mid[key] = self.add(0.5 * (self.pos[key[0]] + self.pos[key[1]]), self.src[key[0]])
        return self.mid[key]


def _refine(tris: list[tuple[int, int, int]], owner: list[int], bld: _Builder, levels: int):
    for _ in range(levels):
        new, new_owner = [], []
        for (a, b, c), o in zip(tris, owner):
            ab, bc, ca = bld.midpoint(a, b), bld.midpoint(b, c), bld.midpoint(c, a)
            new += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
            new_owner += [o] * 4
        tris, owner = new, new_owner
    return tris, owner


def triangulate_blocks(model, rows, mode: str = "radial", edge_max: float | None = None) -> int:
    """Replace the faces of blocks ``rows`` by triangles; returns the number of faces made."""
    if mode not in ("radial", "radial-8", "edge-max"):
        raise GeometryError(f"face triangulate: unknown mode '{mode}' (radial, radial-8, edge-max)")
    if mode == "edge-max" and not (edge_max and edge_max > 0):
        raise GeometryError("face triangulate edge-max: the maximum edge length must be positive")
    b, f = model.blocks, model.faces
    loops = model.face_vertices["vertex"]
    vpos = model.vertices["pos"]
    rows = np.asarray(rows, dtype=np.int64)
    batch_pos, batch_vsrc, batch_fsrc, batch_fv = [], [], [], []
    pnv, pnf = [], []
    for r in rows:
        vs, vc = int(b["vert_start"][r]), int(b["vert_count"][r])
        bld = _Builder(vpos[vs:vs + vc], np.arange(vs, vs + vc))
        tris: list[tuple[int, int, int]] = []
        owner: list[int] = []
        for face in range(int(b["face_start"][r]), int(b["face_start"][r] + b["face_count"][r])):
            loop = [int(i) - vs for i in loops[f["vstart"][face]:f["vstart"][face] + f["nvert"][face]]]
            if mode == "radial-8":
                ring = []
                for a, c in zip(loop, loop[1:] + loop[:1]):
                    ring += [a, bld.midpoint(a, c)]
                loop = ring
            centre = bld.add(f["centroid"][face], vs + loop[0])
            for a, c in zip(loop, loop[1:] + loop[:1]):
                tris.append((centre, a, c))
                owner.append(face)
        if mode == "edge-max":
            p = np.array(bld.pos)
            t = np.array(tris)
            longest = max(np.linalg.norm(p[t[:, i]] - p[t[:, (i + 1) % 3]], axis=1).max()
                          for i in range(3))
            levels = max(0, math.ceil(math.log2(longest / edge_max))) if longest > edge_max else 0
            tris, owner = _refine(tris, owner, bld, levels)
        batch_pos.append(np.array(bld.pos))
        batch_vsrc.append(np.array(bld.src, dtype=np.int64))
        batch_fsrc.append(np.array(owner, dtype=np.int64))
        batch_fv.append(np.array(tris, dtype=np.int64).ravel())
        pnv.append(len(bld.pos))
        pnf.append(len(tris))
    if not pnv:
        return 0
    fn = np.full(sum(pnf), 3, dtype=np.int64)
    write_pieces(model, rows, np.concatenate(batch_pos), np.concatenate(batch_vsrc),
                 np.array(pnv, dtype=np.int64), fn, np.concatenate(batch_fsrc),
                 np.array(pnf, dtype=np.int64), np.concatenate(batch_fv))
    compact_geometry(model)
    return int(sum(pnf))
