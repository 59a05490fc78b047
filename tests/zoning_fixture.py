"""Zoning by hand for tests that need zones before (or without) the mesher: an axis-aligned
brick block split into five tetrahedra, or into both five-tetrahedron sets of a mixed
hexahedral zone. Written from the corner numbering alone (no mesher code)."""
from __future__ import annotations

import itertools

import numpy as np

from dec3d.geometry.assemble import block_poly
from dec3d.model.zones import install_block_mesh


def _corner_index(pts: np.ndarray) -> dict[tuple[int, int, int], int]:
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    out = {}
    for i, p in enumerate(pts):
        key = tuple(int(round((p[d] - lo[d]) / (hi[d] - lo[d]))) for d in range(3))
        out[key] = i
    assert len(out) == 8, "an axis-aligned brick has eight corners"
    return out


def _five(parity: int) -> list[tuple]:
    """Five tetrahedra of the unit cube on corner keys: four corner tetrahedra at the corners
    of the other parity, and the central one on the corners of this parity."""
    central = [c for c in itertools.product((0, 1), repeat=3) if sum(c) % 2 == parity]
    tets = [tuple(central)]
    for c in itertools.product((0, 1), repeat=3):
        if sum(c) % 2 != parity:
            nbrs = [tuple(c[d] ^ (d == k) for d in range(3)) for k in range(3)]
            tets.append((c, *nbrs))
    return tets


def _oriented(pts, t):
    a, b, c, d = (pts[i] for i in t)
    return t if np.dot(np.cross(b - a, c - a), d - a) > 0 else (t[0], t[2], t[1], t[3])


def zone_brick(model, row: int, mixed: bool = False):
    """Zone brick block ``row``: five tetrahedra, or (``mixed``) ten as two overlays."""
    poly = block_poly(model, row)
    pts = poly.vertices
    key = _corner_index(pts)
    tets, hexid, overlay = [], [], []
    for par in ((0, 1) if mixed else (0,)):
        for t in _five(par):
            tets.append(_oriented(pts, tuple(key[c] for c in t)))
            hexid.append(0)
            overlay.append(par)
    # boundary triangles: each quad face split along a diagonal joining even corners
    tris, src = [], []
    cen = pts.mean(axis=0)
    for f in range(poly.nfaces):
        loop = poly.face_idx[poly.face_ptr[f]:poly.face_ptr[f + 1]]
        inv = {v: k for k, v in key.items()}
        even = [v for v in loop if sum(inv[v]) % 2 == 0]
        odd = [v for v in loop if sum(inv[v]) % 2 == 1]
        for o in odd:
            t = (even[0], o, even[1])
            a, b, c = (pts[i] for i in t)
            if np.dot(np.cross(b - a, c - a), a - cen) < 0:
                t = (t[0], t[2], t[1])
            tris.append(t)
            src.append(f)
    sl = install_block_mesh(model, row, pts, np.array(tets), np.array(tris), np.array(src),
                            np.array(hexid) if mixed else None, np.array(overlay) if mixed else None)
    return sl
