"""Convex polyhedra from user input, validated, with the reason when they are refused.

``Poly`` is the small interchange form between the shape generators and the model:
vertices (nv, 3) and CSR faces whose loops run counter-clockwise seen from outside
(right-hand rule gives the outward normal). 3DEC asks for clockwise input; either
winding is accepted here and each face is turned outward.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.spatial import cKDTree

from .errors import GeometryError


@dataclass(frozen=True)
class Poly:
    """A convex polyhedron: ``vertices`` (nv, 3) m; face f is
    ``face_idx[face_ptr[f]:face_ptr[f+1]]`` (indices into ``vertices``)."""

    vertices: np.ndarray
    face_ptr: np.ndarray
    face_idx: np.ndarray

    @property
    def nfaces(self) -> int:
        return len(self.face_ptr) - 1

    def face(self, f: int) -> np.ndarray:
        return self.face_idx[self.face_ptr[f]:self.face_ptr[f + 1]]

    def faces(self) -> list[np.ndarray]:
        return [self.face(f) for f in range(self.nfaces)]


def _fmt(p) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in p) + ")"


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product (faster than np.cross on the small arrays met here)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def _newell(pts: np.ndarray) -> np.ndarray:
    """Area vector (3,) of a closed polygon loop: area times the unit normal."""
    m = pts.mean(axis=0)
    return 0.5 * _cross(pts - m, np.roll(pts, -1, axis=0) - m).sum(axis=0)


def _merge_points(pts: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Unique points (in order of first appearance) and the index of each input point's.

    A point joins the earliest point within ``tol`` (max-norm) of it, or of that point."""
    first = np.arange(len(pts))
    pairs = cKDTree(pts).query_pairs(tol, p=np.inf, output_type="ndarray")
    if len(pairs):
        np.minimum.at(first, pairs[:, 1], pairs[:, 0])
        np.minimum.at(first, pairs[:, 0], pairs[:, 1])
        first = first[first]                         # chains: follow to the representative
    reps, index = np.unique(first, return_inverse=True)
    return pts[reps], index


#: a face may be warped (its corners off its plane) by up to this fraction of its block's size (the
#: bounding-box diagonal): the rule `block generate from-vrml` uses too (dec3d.io.vrml.RELATIVE_TOLERANCE)
WARP_RELATIVE = 0.005


def polyhedron_from_faces(faces: Sequence, tol: float = 1e-6, what: str = "polyhedron",
                          warp: float = 0.0, warped: list | None = None) -> Poly:
    """Build and check a convex polyhedron from its faces.

    ``faces``: one (k, 3) array-like of corner coordinates per face, k ≥ 3, in either
    winding. Points closer than ``tol`` are merged. Raises ``GeometryError`` naming the
    first face (counted from 1) that is too small, not planar, open, not convex, or when
    the volume is zero.

    With ``warp`` > 0 a face whose corners lie off its plane by more than ``tol`` but at most
    max(tol, warp × the bounding-box diagonal) is accepted: the block is built as the convex hull of
    its corners, so that the warped face is split into the triangles of its convex side and the
    volume is that of the faces as built. Each such face is appended to ``warped`` as
    (face number, corner number, distance off the plane, the limit).
    """
    tol = float(tol)
    arrays = []
    for fi, face in enumerate(faces, start=1):
        pts = np.asarray(face, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise GeometryError(f"{what}: face {fi} must be a list of 3-D points")
        if not np.all(np.isfinite(pts)):
            raise GeometryError(f"{what}: face {fi} has a coordinate that is not a finite number")
        arrays.append(pts)
    if not arrays:
        raise GeometryError(f"{what}: no faces given")
    v, index = _merge_points(np.concatenate(arrays), tol)
    loops: list[list[int]] = []
    start = 0
    for fi, pts in enumerate(arrays, start=1):
        loop: list[int] = []
        for idx in index[start:start + len(pts)].tolist():
            if not loop or loop[-1] != idx:
                loop.append(idx)
        start += len(pts)
        if len(loop) > 1 and loop[0] == loop[-1]:
            loop.pop()
        if len(loop) < 3:
            raise GeometryError(f"{what}: face {fi} has fewer than 3 distinct corners")
        if len(set(loop)) != len(loop):
            raise GeometryError(f"{what}: face {fi} passes through the same corner twice")
        loops.append(loop)
    if len(loops) < 4:
        raise GeometryError(f"{what}: a closed polyhedron needs at least 4 faces, {len(loops)} given")

    # planarity and area of each face
    limit = tol
    if warp > 0:
        limit = max(tol, warp * float(np.linalg.norm(v.max(axis=0) - v.min(axis=0))))
    bent = []
    normals = []
    areas = []
    for fi, loop in enumerate(loops, start=1):
        pts = v[loop]
        av = _newell(pts)
        area = np.linalg.norm(av)
        if area <= tol * tol:
            raise GeometryError(f"{what}: face {fi} has zero area")
        n = av / area
        dist = (pts - pts.mean(axis=0)) @ n
        j = int(np.argmax(np.abs(dist)))
        if abs(dist[j]) > limit:
            rule = (f"; a warp is accepted up to {100 * warp:g} % of the block's size, {limit:.3g} m"
                    if warp > 0 else "")
            raise GeometryError(
                f"{what}: face {fi} is not planar: corner {j + 1} {_fmt(pts[j])} lies "
                f"{abs(dist[j]):.3g} m off the face's plane (tolerance {tol:g} m{rule})")
        if abs(dist[j]) > tol:
            bent.append((fi, j + 1, float(abs(dist[j])), limit))
        normals.append(n)
        areas.append(area)

    # closed: every edge in exactly two faces
    edges: dict[tuple[int, int], list[int]] = {}
    for fi, loop in enumerate(loops):
        for a, b in zip(loop, loop[1:] + loop[:1]):
            edges.setdefault((min(a, b), max(a, b)), []).append(fi)
    for (a, b), owners in edges.items():
        if len(owners) == 1:
            raise GeometryError(
                f"{what}: the surface is open: edge {_fmt(v[a])}-{_fmt(v[b])} of face "
                f"{owners[0] + 1} belongs to no other face")
        if len(owners) > 2:
            raise GeometryError(
                f"{what}: edge {_fmt(v[a])}-{_fmt(v[b])} is shared by faces "
                f"{', '.join(str(o + 1) for o in owners)}; a solid has two faces per edge")

    # all corners in one plane: nothing is enclosed, and no face can be turned outward
    if np.abs((v - v[loops[0]].mean(axis=0)) @ normals[0]).max() <= tol:
        raise GeometryError(f"{what}: zero volume: all corners lie in one plane")

    # turn every face outward, seen from the mean of the corners
    inside = v.mean(axis=0)
    centres = np.array([v[loop].mean(axis=0) for loop in loops])
    normals = np.array(normals)
    flip = np.einsum("ij,ij->i", normals, centres - inside) < 0
    normals[flip] *= -1.0
    for fi in np.flatnonzero(flip):
        loops[fi].reverse()

    # convex: no corner in front of any face's plane
    d = np.einsum("fvk,fk->fv", v[None, :, :] - centres[:, None, :], normals)
    bad = np.flatnonzero(d.max(axis=1) > (limit if bent else tol))
    if bad.size:
        fi = int(bad[0])
        j = int(np.argmax(d[fi]))
        raise GeometryError(
            f"{what}: not convex: corner {_fmt(v[j])} lies {d[fi, j]:.3g} m outside the "
            f"plane of face {fi + 1} (tolerance {tol:g} m)")

    # consistent orientation: each directed edge once
    seen: set[tuple[int, int]] = set()
    for fi, loop in enumerate(loops, start=1):
        for a, b in zip(loop, loop[1:] + loop[:1]):
            if (a, b) in seen:
                raise GeometryError(f"{what}: faces cannot be oriented consistently (face {fi})")
            seen.add((a, b))

    if bent:
        if warped is not None:
            warped.extend(bent)
        return polyhedron_from_faces(_hull_faces(v, tol), tol, what)

    ptr = np.zeros(len(loops) + 1, dtype=np.int64)
    ptr[1:] = np.cumsum([len(lp) for lp in loops])
    idx = np.array([i for lp in loops for i in lp], dtype=np.int64)
    poly = Poly(v, ptr, idx)
    vol = poly_volume(poly)
    if vol <= tol * sum(areas):
        raise GeometryError(f"{what}: zero volume ({vol:.3g} m^3): the faces enclose no space")
    return poly


def _hull_faces(v: np.ndarray, tol: float) -> list[np.ndarray]:
    """The faces of the convex hull of the points ``v``: the hull's triangles merged where they lie in
    one plane (every corner within ``tol`` of it), each face's corners in order around it."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(v)
    extreme = np.zeros(len(v), dtype=bool)
    extreme[hull.vertices] = True
    faces, used = [], np.zeros(len(hull.simplices), dtype=bool)
    for k, eq in enumerate(hull.equations):
        if used[k]:
            continue
        n, off = eq[:3], eq[3]
        members = np.flatnonzero(extreme & (np.abs(v @ n + off) <= tol))
        near = np.all(np.abs(v[hull.simplices] @ n + off) <= tol, axis=1)
        used |= near
        p = v[members]
        c = p.mean(axis=0)
        u = p[0] - c
        u /= np.linalg.norm(u)
        w = np.cross(n, u)
        faces.append(p[np.argsort(np.arctan2((p - c) @ w, (p - c) @ u))])
    return faces


def poly_volume(poly: Poly) -> float:
    """Volume [m³] by the divergence theorem (faces fanned from their mean)."""
    v = poly.vertices - poly.vertices.mean(axis=0)
    nv = np.diff(poly.face_ptr)
    face_of = np.repeat(np.arange(poly.nfaces), nv)
    pts = v[poly.face_idx]
    nxt_idx = np.arange(len(poly.face_idx)) + 1
    ends = poly.face_ptr[1:] - 1
    nxt_idx[ends] = poly.face_ptr[:-1]
    nxt = v[poly.face_idx[nxt_idx]]
    means = np.zeros((poly.nfaces, 3))
    np.add.at(means, face_of, pts)
    means /= nv[:, None]
    m = means[face_of]
    return float(np.einsum("ij,ij->", _cross(pts, nxt), m)) / 6.0


# ------------------------------------------------------------------ primitives
# Each shape has a ``*_faces`` form, (corners (n, 3), corners per face), which ``build_many``
# takes, and a ``Poly`` form that builds and checks it at once.
_BRICK_QUADS = np.array([(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)])
_BRICK_FN = np.full(6, 4, dtype=np.int64)
_TET_TRIS = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]


def brick_faces(x1: float, x2: float, y1: float, y2: float, z1: float, z2: float,
                tol: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Faces of the axis-aligned box [x1, x2] × [y1, y2] × [z1, z2] (bounds in either order)."""
    xs, ys, zs = sorted((x1, x2)), sorted((y1, y2)), sorted((z1, z2))
    for name, (a, b) in (("x", xs), ("y", ys), ("z", zs)):
        if b - a <= tol:
            raise GeometryError(f"brick: zero thickness in {name} ({a:g} to {b:g})")
    c = np.array([[xs[i], ys[j], zs[k]] for k in (0, 1) for j in (0, 1) for i in (0, 1)], dtype=np.float64)
    return c[_BRICK_QUADS.ravel()], _BRICK_FN


def tetrahedron_faces(v1, v2, v3, v4) -> tuple[np.ndarray, np.ndarray]:
    """Faces of the tetrahedron on four corners (any order)."""
    p = np.array([np.asarray(x, dtype=np.float64) for x in (v1, v2, v3, v4)])
    return p[np.array(_TET_TRIS).ravel()], np.full(4, 3, dtype=np.int64)


def prism_faces(face1, face2, tol: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Faces of the prism between two polygons with the same number of corners, corner i of
    ``face1`` joined to corner i of ``face2`` (the side faces must be planar)."""
    a = np.asarray(face1, dtype=np.float64).reshape(-1, 3)
    b = np.asarray(face2, dtype=np.float64).reshape(-1, 3)
    if len(a) != len(b):
        raise GeometryError(f"prism: face-1 has {len(a)} corners but face-2 has {len(b)}")
    if len(a) < 3:
        raise GeometryError("prism: the end faces need at least 3 corners")
    n = _newell(a)
    if np.linalg.norm(n) > tol * tol:
        h = np.abs((b - a.mean(axis=0)) @ (n / np.linalg.norm(n)))
        if h.max() <= tol:
            raise GeometryError("prism: zero volume: face-2 lies in the plane of face-1")
    k = len(a)
    i = np.arange(k)
    j = (i + 1) % k
    sides = np.stack([a[i], a[j], b[j], b[i]], axis=1).reshape(-1, 3)
    return np.concatenate([a, b, sides]), np.array([k, k] + [4] * k, dtype=np.int64)


def split_faces(pts: np.ndarray, fn: np.ndarray) -> list[np.ndarray]:
    """The face arrays of a (corners, corners per face) shape, as ``polyhedron_from_faces`` takes them."""
    return np.split(pts, np.cumsum(fn)[:-1])


def brick(x1: float, x2: float, y1: float, y2: float, z1: float, z2: float,
          tol: float = 1e-6) -> Poly:
    """Axis-aligned box [x1, x2] × [y1, y2] × [z1, z2] (bounds in either order)."""
    return polyhedron_from_faces(split_faces(*brick_faces(x1, x2, y1, y2, z1, z2, tol)), tol, "brick")


def tetrahedron(v1, v2, v3, v4, tol: float = 1e-6) -> Poly:
    """Tetrahedron on four corners (any order)."""
    return polyhedron_from_faces(split_faces(*tetrahedron_faces(v1, v2, v3, v4)), tol, "tetrahedron")


def prism(face1, face2, tol: float = 1e-6) -> Poly:
    """Prism between two polygons with the same number of corners, corner i of
    ``face1`` joined to corner i of ``face2``; the side faces must be planar."""
    return polyhedron_from_faces(split_faces(*prism_faces(face1, face2, tol)), tol, "prism")


def build_many(shapes: Sequence[tuple[np.ndarray, np.ndarray]], tol: float = 1e-6):
    """Build many polyhedra, each given as (corners (n, 3), corners per face), with the compiled
    checks of ``dec3d.kernels.polybuild`` (the same as ``polyhedron_from_faces``).

    Returns (built, batch): the polyhedra before the first refused one are built, and ``batch`` is
    their (pos, vsrc, piece_nv, fn, fsrc, piece_nf, fv), what ``polys_to_batch`` makes, for
    ``dec3d.geometry.assemble.write_pieces``. The refused one (index ``built``) gets its reason from
    ``polyhedron_from_faces``."""
    from dec3d.kernels.polybuild import build_polyhedra

    if not shapes:
        return 0, None
    pts = np.ascontiguousarray(np.concatenate([s[0] for s in shapes]), dtype=np.float64)
    fn_in = np.concatenate([s[1] for s in shapes]).astype(np.int64)
    piece_nf = np.array([len(s[1]) for s in shapes], dtype=np.int64)
    pos = np.empty_like(pts)
    piece_nv = np.zeros(len(shapes), dtype=np.int64)
    fn = np.zeros(len(fn_in), dtype=np.int64)
    fv = np.empty(len(pts), dtype=np.int64)
    built, nv, nl = build_polyhedra(pts, fn_in, piece_nf, float(tol), pos, piece_nv, fn, fv)
    if built == 0:
        return 0, None
    nf = int(piece_nf[:built].sum())
    batch = (pos[:nv], np.full(nv, -1, dtype=np.int64), piece_nv[:built], fn[:nf],
             np.full(nf, -1, dtype=np.int64), piece_nf[:built], fv[:nl])
    return int(built), batch
