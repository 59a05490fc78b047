"""The flow network's geometry, built from the contacts (issue 29 item 2; 3DEC theory, "Joint Fluid Flow").

Every contact is a flow plane. Its sub-contact points (projected on the contact plane) span its polygon; the
plane is cut into triangular flow zones:

- without a zone size, the Delaunay triangles of the sub-contact points themselves;
- with a zone size h (`block fluid zone-size`, dec3d's word), the points of a grid of spacing h laid along
  the polygon's longest edge, the polygon's edges split into ceil(length / h) equal parts, and the sub-contact
  points, triangulated (Delaunay) together. A shared full edge of two contacts is split at the same points on
  both, so their knots meet.

The triangle corners are flow knots. Knots of different planes closer than ``tol`` are one knot (a joint
intersection, or two contacts side by side in one joint): flow passes from plane to plane there.
The pipe between two knots of a triangle carries the linear finite-element (cotangent) weight
w = cot θ / 2 of that triangle (θ the angle opposite the edge): for a pressure linear over the triangle,
Σ_edges T w (p_i − p_j) is the exact flux of the transmissivity T over it, so the pipes reproduce the cubic
law for any triangulation. A pipe's conductance is the sum over its triangles of T_t w_t,
T_t = a_t³ / (12 μ) with a_t the triangle's hydraulic aperture; a negative sum (an obtuse angle on a
boundary edge of a Delaunay mesh) is taken as zero (``kernels.jointflow.zone_update``). A knot's volume is
Σ a_t A_t / 3 over its triangles.

Each triangle takes its mechanical normal displacement at its centroid from the sub-contacts of the
Delaunay triangle of sub-contact points that holds it (barycentric weights: rigid blocks' relative motion is
linear over a contact, so this is exact for them). Each sub-contact reads the pressure of its own knot.

Deterministic: the same contacts give the same knots, zones and pipes in the same order.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.spatial import Delaunay, cKDTree
from scipy.spatial import QhullError


#: the most knots a zone size may make (a guard against a size far too small for the model)
MAX_KNOTS = 2e6


def _axes(n):
    """In-plane unit axes t1, t2 ⟂ n (t1 from the global axis least along n)."""
    e = np.zeros(3)
    e[int(np.argmin(np.abs(n)))] = 1.0
    t1 = np.cross(n, e)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


def _distinct(uv, tol):
    """rep[i]: the first point at the place of point i (within tol)."""
    rep = np.arange(len(uv))
    if len(uv) > 1:
        for i, j in sorted(cKDTree(uv).query_pairs(tol)):
            ri, rj = rep[i], rep[j]
            while rep[ri] != ri:
                ri = rep[ri]
            while rep[rj] != rj:
                rj = rep[rj]
            if ri != rj:
                rep[max(ri, rj)] = min(ri, rj)
        for i in range(len(rep)):
            r = i
            while rep[r] != r:
                r = rep[r]
            rep[i] = r
    return rep


def _delaunay(uv):
    try:
        d = Delaunay(uv)
    except (QhullError, ValueError):
        return None
    return d


def _hull_loop(uv):
    """The convex hull's corners in order (counter-clockwise) as indices into uv."""
    from scipy.spatial import ConvexHull
    return ConvexHull(uv).vertices


def _refined_points(uv, loop, h, tol):
    """Edge points (each hull edge split into ceil(L/h) parts) and interior grid points of spacing h
    (aligned with the longest edge) at least h/2 from the boundary."""
    corners = uv[loop]
    m = len(corners)
    edges = [(corners[i], corners[(i + 1) % m]) for i in range(m)]
    lengths = [float(np.linalg.norm(b - a)) for a, b in edges]
    out = []
    for (a, b), ln in zip(edges, lengths):
        k = max(1, int(math.ceil(ln / h - 1e-9)))
        for j in range(1, k):
            out.append(a + (b - a) * (j / k))
    i0 = int(np.argmax(lengths))
    a, b = edges[i0]
    e1 = (b - a) / lengths[i0]
    e2 = np.array([-e1[1], e1[0]])
    loc = (corners - a) @ np.stack([e1, e2], axis=1)
    lo, hi = loc.min(axis=0), loc.max(axis=0)
    # inward normals of the (counter-clockwise) hull edges
    nrm = []
    for (p, q) in edges:
        t = (q - p) / max(np.linalg.norm(q - p), 1e-300)
        nrm.append((np.array([-t[1], t[0]]), p))
    for i in range(int(math.floor(lo[0] / h)), int(math.ceil(hi[0] / h)) + 1):
        for j in range(int(math.floor(lo[1] / h)), int(math.ceil(hi[1] / h)) + 1):
            x = a + i * h * e1 + j * h * e2
            if all(float((x - p) @ nv) >= 0.5 * h for nv, p in nrm):
                out.append(x)
    return np.asarray(out, dtype=np.float64).reshape(-1, 2)


def _locate(pts, tris, q):
    """Barycentric weights (nq, 3) of the points q in the triangle of ``tris`` (corners in pts) each is most
    inside of (the largest smallest weight), clipped to ≥ 0, and that triangle's index (nq,)."""
    v = pts[tris]                                            # (nt, 3, 2)
    lam = np.empty((len(q), len(tris), 3))
    for j in range(3):
        p1, p2 = v[None, :, (j + 1) % 3], v[None, :, (j + 2) % 3]
        qq = q[:, None, :]
        lam[:, :, j] = ((p1[..., 0] - qq[..., 0]) * (p2[..., 1] - qq[..., 1])
                        - (p1[..., 1] - qq[..., 1]) * (p2[..., 0] - qq[..., 0]))
    tot = lam.sum(axis=2, keepdims=True)
    lam = lam / np.where(tot != 0.0, tot, 1.0)
    best = np.argmax(lam.min(axis=2), axis=1)
    w = np.clip(lam[np.arange(len(q)), best], 0.0, None)
    return w / w.sum(axis=1, keepdims=True), best


def build_geometry(sub_start, sub_count, normal, sc_pos, size: float, tol: float) -> dict:
    """The network (module docstring) of the contacts (CSR sub_start/sub_count into sc_pos, normal (nc, 3)).

    Returns arrays: ``pos`` (nk, 3) knots; ``zk`` (nz, 3) zone knots; ``zcontact`` (nz,); ``zarea`` (nz,);
    ``zcot`` (nz, 3) the weight cot θ / 2 of the edge opposite each corner; ``zsub`` (nz, 3) and ``zw`` (nz, 3)
    sub-contact rows and weights of the zone's centroid; ``zpipe`` (nz, 3) the pipe of the edge opposite each
    corner (−1: none); ``pa``, ``pb`` (np,) pipe knots; ``sknot`` (ns,) each sub-contact's knot (−1: its
    contact has no zone); ``srep`` (ns,) the first sub-contact of its contact at the same place (itself when
    none is before it; ``zsub`` names only these)."""
    ns = sc_pos.shape[0]
    budget = [float(MAX_KNOTS)]
    sknot_local = np.full(ns, -1, dtype=np.int64)
    srep = np.arange(ns, dtype=np.int64)
    allpts, zk_l, zc_l, za_l, zcot_l, zsub_l, zw_l = [], [], [], [], [], [], []
    base = 0
    for c in range(len(sub_start)):
        s0, k = int(sub_start[c]), int(sub_count[c])
        if k < 3:
            continue
        n = np.asarray(normal[c], dtype=np.float64)
        t1, t2 = _axes(n)
        p0 = sc_pos[s0]
        rel = sc_pos[s0:s0 + k] - p0
        uv = np.stack([rel @ t1, rel @ t2], axis=1)
        rep = _distinct(uv, tol)
        keep = np.flatnonzero(rep == np.arange(k))
        if len(keep) < 3:
            continue
        cd = _delaunay(uv[keep])
        if cd is None or not len(cd.simplices):
            continue
        if size > 0.0:
            ext = np.ptp(uv[keep], axis=0)
            budget[0] -= (ext[0] / size + 2.0) * (ext[1] / size + 2.0)
            if budget[0] < 0.0:
                raise ValueError(f"flow zones of {size:g} m would make more than {MAX_KNOTS:.0e} knots: "
                                 "give a larger `block fluid zone-size`")
            loop = keep[_hull_loop(uv[keep])]
            extra = _refined_points(uv, loop, size, tol)
            if len(extra):
                # drop refinement points at a sub-contact's place
                d, _ = cKDTree(uv[keep]).query(extra)
                extra = extra[d > tol]
            fuv = np.concatenate([uv[keep], extra]) if len(extra) else uv[keep]
            fd = _delaunay(fuv)
            if fd is None:
                continue
            tris = fd.simplices
        else:
            fuv = uv[keep]
            tris = cd.simplices
        # orient counter-clockwise and drop slivers
        a, b, cc = fuv[tris[:, 0]], fuv[tris[:, 1]], fuv[tris[:, 2]]
        cross = (b[:, 0] - a[:, 0]) * (cc[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (cc[:, 0] - a[:, 0])
        tris = np.where((cross < 0)[:, None], tris[:, [0, 2, 1]], tris)
        ext = float(np.ptp(fuv, axis=0).max())
        ok = np.abs(cross) > 1e-12 * ext * ext
        tris = tris[ok]
        if not len(tris):
            continue
        area = 0.5 * np.abs(cross[ok])
        # cot θ_j / 2 at each corner j (the weight of the opposite edge)
        cot = np.empty((len(tris), 3))
        for j in range(3):
            o = fuv[tris[:, j]]
            p = fuv[tris[:, (j + 1) % 3]] - o
            q = fuv[tris[:, (j + 2) % 3]] - o
            cot[:, j] = 0.5 * (p[:, 0] * q[:, 0] + p[:, 1] * q[:, 1]) / (2.0 * area)
        # each zone's centroid in the sub-contact triangulation: barycentric weights
        cen = fuv[tris].mean(axis=1)
        # (by the sub-triangles' areas, each centroid in the coarse triangle it is most inside of: scipy's
        # ``find_simplex`` and ``transform`` go through LAPACK, whose thread pool took seconds to start on a
        # loaded machine)
        bary, simp = _locate(uv[keep], cd.simplices, cen)
        zsub = s0 + keep[cd.simplices[simp]]
        # the knots' 3-D positions: sub-contact points exactly, refinement points on the plane
        xyz = p0 + fuv[:, :1] * t1 + fuv[:, 1:] * t2
        xyz[: len(keep)] = sc_pos[s0 + keep]
        allpts.append(xyz)
        sknot_local[s0:s0 + k] = base + np.searchsorted(keep, rep)
        srep[s0:s0 + k] = s0 + rep
        zk_l.append(base + tris)
        zc_l.append(np.full(len(tris), c, dtype=np.int64))
        za_l.append(area)
        zcot_l.append(cot)
        zsub_l.append(zsub)
        zw_l.append(bary)
        base += len(fuv)
    if not allpts:
        z3i = np.zeros((0, 3), dtype=np.int64)
        return {"pos": np.zeros((0, 3)), "zk": z3i, "zcontact": np.zeros(0, np.int64), "zarea": np.zeros(0),
                "zcot": np.zeros((0, 3)), "zsub": z3i, "zw": np.zeros((0, 3)), "zpipe": z3i,
                "pa": np.zeros(0, np.int64), "pb": np.zeros(0, np.int64), "sknot": sknot_local, "srep": srep}
    pts = np.concatenate(allpts)
    rep = _distinct(pts, tol)                     # knots of different planes at one place are one knot
    first = np.flatnonzero(rep == np.arange(len(pts)))
    newid = np.full(len(pts), -1, dtype=np.int64)
    newid[first] = np.arange(len(first))
    kid = newid[rep]
    zk = kid[np.concatenate(zk_l)]
    sknot = np.where(sknot_local >= 0, kid[np.maximum(sknot_local, 0)], -1)
    # pipes: the distinct edges; the edge opposite corner j joins corners j+1 and j+2
    ea = np.stack([zk[:, 1], zk[:, 2], zk[:, 0]], axis=1)
    eb = np.stack([zk[:, 2], zk[:, 0], zk[:, 1]], axis=1)
    lo, hi = np.minimum(ea, eb).ravel(), np.maximum(ea, eb).ravel()
    good = lo != hi
    key = lo * len(first) + hi
    uniq, inv = np.unique(key[good], return_inverse=True)
    zpipe = np.full(lo.shape, -1, dtype=np.int64)
    zpipe[good] = inv
    return {"pos": pts[first], "zk": zk, "zcontact": np.concatenate(zc_l), "zarea": np.concatenate(za_l),
            "zcot": np.concatenate(zcot_l), "zsub": np.concatenate(zsub_l), "zw": np.concatenate(zw_l),
            "zpipe": zpipe.reshape(-1, 3), "pa": uniq // len(first), "pb": uniq % len(first), "sknot": sknot,
            "srep": srep}
