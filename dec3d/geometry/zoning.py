"""Zoning of blocks (issue 10): convex polyhedra into 4-node tetrahedra at a target edge
length.

Tetrahedra (``mesh_convex``): boundary points (vertices, edge subdivisions, a square grid on
each face kept off its edges), an interior lattice kept off the boundary, and the regular
(weighted Delaunay) triangulation of them all as the lower hull of the lifted points. The
weights are tiny and keyed on each point's position alone (a hash of its coordinates, scaled
by the edge length the point was made for), so the same points on a shared face give the
same facet triangles in both blocks: the restriction of a regular triangulation to a facet of
the convex hull is the regular triangulation of the points on that facet, and positive
scaling of the lifting or adding an affine function of position does not change it. Points of
already zoned joined neighbours are taken over on the shared part of the boundary
(``neighbours``), the block's own boundary points there dropped; where faces of joined blocks
still to be zoned end inside this block's faces, points are put along those lines
(``imprint``). Interior lattice points carry parity weights instead, which make the regular
triangulation the five-tetrahedron split of every lattice cell: cells deep inside are split
directly and only the boundary band goes through qhull (``triangulate``; eight far "cap"
points keep the block's coplanar face points off the 4-D hull, where qhull would merge them
into huge facets). Slivers (smallest dihedral angle below SLIVER_DEG) get interior points at
their circumcentres or lose an interior corner near the boundary, for a few rounds, the best
round kept; interior changes leave every facet triangulation as it was.

Hexahedral zones and 10-node tetrahedra: ``dec3d.geometry.zoning_hex``."""
from __future__ import annotations

import numpy as np

#: tetrahedra with a smallest dihedral angle below this (degrees) are broken up (``_sliver_fix``)
SLIVER_DEG = 15.0
#: at most this many rounds of adding points and triangulating again
SLIVER_PASSES = 5

#: weight of a point in the regular triangulation: this fraction of (its edge length)², times a
#: hash of its position in [0, 1)
WEIGHT_FRACTION = 1e-3


def position_hash(p: np.ndarray) -> np.ndarray:
    """A number in [0, 1) for each point (n, 3), from the bits of its coordinates only
    (splitmix-style mixing; -0.0 and 0.0 hash alike)."""
    b = np.ascontiguousarray(np.asarray(p, np.float64).reshape(-1, 3) + 0.0).view(np.uint64)
    h = np.full(len(b), 0x9E3779B97F4A7C15, np.uint64)
    with np.errstate(over="ignore"):
        for k in range(3):
            h ^= b[:, k]
            h *= np.uint64(0xBF58476D1CE4E5B9)
            h ^= h >> np.uint64(29)
            h *= np.uint64(0x94D049BB133111EB)
            h ^= h >> np.uint64(32)
    return (h >> np.uint64(11)).astype(np.float64) / float(2 ** 53)


def _face_frame(p: np.ndarray):
    n = np.zeros(3)
    for i in range(len(p)):
        a, b = p[i], p[(i + 1) % len(p)]
        n += np.cross(a, b)
    n /= np.linalg.norm(n)
    u = p[1] - p[0]
    u -= n * np.dot(u, n)
    u /= np.linalg.norm(u)
    return n, u, np.cross(n, u)


def face_planes(verts: np.ndarray, ptr: np.ndarray, loops: np.ndarray):
    """Outward unit normals (f, 3) and offsets (f,) of a polyhedron's faces (Newell's normal of
    each loop, offset the mean over its corners)."""
    verts = np.asarray(verts, float)
    ptr = np.asarray(ptr, np.int64)
    loops = np.asarray(loops, np.int64)
    cnt = np.diff(ptr)
    pos = np.arange(len(loops))
    face = np.repeat(np.arange(len(cnt)), cnt)
    nxt = np.where(pos + 1 < ptr[face + 1], pos + 1, ptr[face])
    a, b = verts[loops], verts[loops[nxt]]
    n = np.add.reduceat(np.cross(a, b), ptr[:-1], axis=0)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    d = np.add.reduceat(np.einsum("ij,ij->i", a, n[face]), ptr[:-1]) / cnt
    return n, d


def _edge_points(pa: np.ndarray, pb: np.ndarray, L: float) -> np.ndarray:
    """Interior subdivision points of segment pa-pb at about L, the same whichever end is
    given first (ends ordered by position, so two blocks sharing the edge make equal points)."""
    if tuple(pb) < tuple(pa):
        pa, pb = pb, pa
    n = int(np.ceil(np.linalg.norm(pb - pa) / L - 1e-9))
    if n <= 1:
        return np.zeros((0, 3))
    t = np.arange(1, n)[:, None] / n
    return pa + t * (pb - pa)


def boundary_points(verts: np.ndarray, ptr: np.ndarray, loops: np.ndarray, L: float) -> np.ndarray:
    """Vertices, edge subdivisions at about L, and face interior points on a square grid of
    step L kept at least L/2 from the face's edges."""
    pts = [verts]
    seen = set()
    for f in range(len(ptr) - 1):
        loop = loops[ptr[f]:ptr[f + 1]]
        p = verts[loop]
        for i in range(len(loop)):
            a, b = int(loop[i]), int(loop[(i + 1) % len(loop)])
            key = (min(a, b), max(a, b))
            if key in seen:
                continue
            seen.add(key)
            pts.append(_edge_points(verts[a], verts[b], L))
        n, u, v = _face_frame(p)
        q = np.c_[(p - p[0]) @ u, (p - p[0]) @ v]
        lo, hi = q.min(axis=0), q.max(axis=0)
        gu = np.arange(lo[0] + L, hi[0] - 0.5 * L + 1e-12, L)
        gv = np.arange(lo[1] + L, hi[1] - 0.5 * L + 1e-12, L)
        if len(gu) == 0 or len(gv) == 0:
            continue
        G = np.array(np.meshgrid(gu, gv, indexing="ij")).reshape(2, -1).T
        keep = np.ones(len(G), bool)
        m = len(q)
        for i in range(m):
            e = q[(i + 1) % m] - q[i]
            en = np.array([e[1], -e[0]]) / np.linalg.norm(e)
            d = (G - q[i]) @ en  # outward normal for counterclockwise loops
            keep &= d < -0.5 * L
        G = G[keep]
        pts.append(p[0] + G[:, :1] * u + G[:, 1:] * v)
    return np.concatenate(pts)


def regular_tets(pts: np.ndarray, L: float, scale: np.ndarray | float | None = None,
                 weight: np.ndarray | None = None) -> np.ndarray:
    """The regular triangulation of ``pts`` as the lower hull of the lifted points
    ``|p - c|² + W(p)`` (in units of L²). ``W`` is ``weight`` [m²] when given, else
    ``WEIGHT_FRACTION · scale² · position_hash(p)``: lattice input is cospherical everywhere
    and the weights break the ties without moving any point; coplanar points never form a
    tetrahedron (their lifted facet would be vertical)."""
    from scipy.spatial import ConvexHull
    if weight is None:
        scale = L if scale is None else scale
        weight = WEIGHT_FRACTION * np.asarray(scale, float) ** 2 * position_hash(pts)
    c = pts.mean(axis=0)
    q = (pts - c) / L
    lifted = np.c_[q, np.einsum("ij,ij->i", q, q) + np.asarray(weight, float) / L ** 2]
    # eight far points, lifted far above every sphere through the real points: they join no
    # tetrahedron of the real points, but they keep the block's faces (thousands of coplanar points)
    # off the hull, where qhull would merge them into huge vertical facets (3x faster)
    ext = 3.0 * float(np.abs(q).max()) + 1.0
    far = np.array([[a, b, d] for a in (-ext, ext) for b in (-ext, ext) for d in (-ext, ext)])
    lifted = np.r_[lifted, np.c_[far, 100.0 * np.einsum("ij,ij->i", far, far)]]
    hull = ConvexHull(lifted, qhull_options="Qt Qbb")
    s = hull.simplices[hull.equations[:, 3] < 0]
    return s[(s < len(pts)).all(axis=1)].astype(np.int64)


#: weight of the even lattice points ((i + j + k) even), in L²: makes the regular triangulation of
#: the lattice the five-tetrahedron split of every cell (the central tetrahedron on the odd corners)
PARITY_WEIGHT = 0.05
#: plus this much (in L²) times the position hash: equal parity weights leave exact ties (an even
#: pair and three odd points in a plane along the pair lift onto one hyperplane) that become hull
#: facets next to the boundary, where qhull would split them into flat tetrahedra; far below the
#: 2·PARITY_WEIGHT margin of the five-tetrahedron split, so that split stays exact
LATTICE_JITTER = 1e-4
#: lattice points farther than this (in L) from every other point are triangulated by that
#: split directly (no hull computation); the test compares with the full hull
DEEP = 2.5


def _five(parity: int):
    """The five tetrahedra of a unit cell on local corner keys (i, j, k): the central one on
    the corners with (i + j + k) % 2 == parity, and one at each other corner with its three
    edge neighbours."""
    import itertools
    cube = list(itertools.product((0, 1), repeat=3))
    out = [tuple(c for c in cube if sum(c) % 2 == parity)]
    for c in cube:
        if sum(c) % 2 != parity:
            out.append((c,) + tuple(tuple(c[d] ^ (d == k) for d in range(3)) for k in range(3)))
    return out


def _five_split(cells: np.ndarray, lat_id: np.ndarray) -> np.ndarray:
    """The five tetrahedra of each lattice cell (i, j, k) (m, 3): the central one on the corners of
    odd parity, one at each even corner with its three edge neighbours. ``lat_id`` maps a lattice
    index to a point row."""
    out = []
    for par_cell in (0, 1):
        c = cells[cells.sum(axis=1) % 2 == par_cell]
        # local corners (a, b, d) of odd global parity: (par_cell + a + b + d) odd
        for tet in _five(1 - par_cell):
            out.append(np.stack([lat_id[c[:, 0] + a, c[:, 1] + b, c[:, 2] + d] for a, b, d in tet], axis=1))
    return np.concatenate(out) if out else np.zeros((0, 4), np.int64)


def triangulate(pts: np.ndarray, W: np.ndarray, L: float, lat: tuple | None = None, fast: bool = True):
    """Regular triangulation of ``pts`` with absolute weights ``W``. ``lat``: ``(start, index, shape)``
    when rows ``start .. start + len(index)`` are lattice points with integer indices ``index`` in a
    lattice of ``shape`` cells of size L (their weights the parity weights). With ``fast`` the cells
    around lattice points far (``DEEP`` L) from every non-lattice point take the five-tetrahedron
    split directly and only the rest goes through the hull: the same triangulation, faster."""
    if lat is None or not fast:
        return regular_tets(pts, L, weight=W)
    from scipy.spatial import cKDTree
    start, idx, shape = lat
    ng = len(idx)
    other = np.r_[np.arange(start), np.arange(start + ng, len(pts))]
    if ng == 0 or len(other) == 0:
        return regular_tets(pts, L, weight=W)
    present = np.zeros(shape, bool)
    present[idx[:, 0], idx[:, 1], idx[:, 2]] = True
    lat_id = np.full(shape, -1, np.int64)
    lat_id[idx[:, 0], idx[:, 1], idx[:, 2]] = start + np.arange(ng)
    # complete cells: all eight corners present
    sx, sy, sz = shape
    cell = np.ones((sx - 1, sy - 1, sz - 1), bool) if min(shape) > 1 else np.zeros((0, 0, 0), bool)
    if cell.size:
        for a in (0, 1):
            for b in (0, 1):
                for d in (0, 1):
                    cell &= present[a:sx - 1 + a, b:sy - 1 + b, d:sz - 1 + d]
    far = cKDTree(pts[other]).query(pts[start:start + ng], distance_upper_bound=DEEP * L)[0] > DEEP * L
    deep = np.zeros(shape, bool)
    deep[idx[:, 0], idx[:, 1], idx[:, 2]] = far
    # a deep point needs its eight cells complete
    cp = np.zeros((sx + 1, sy + 1, sz + 1), bool)
    if cell.size:
        cp[1:sx, 1:sy, 1:sz] = cell
    allc = np.ones(shape, bool)
    for a in (0, 1):
        for b in (0, 1):
            for d in (0, 1):
                allc &= cp[a:sx + a, b:sy + b, d:sz + d]
    deep &= allc
    # keep every third deep point in each direction in the hull, so that the hull fills the
    # structured region with a coarse lattice instead of long tetrahedra across an empty hole
    # (the kept ones are real points of the block: the argument below holds for any removed subset)
    ii, jj, kk = np.meshgrid(*[np.arange(n) % 3 == 1 for n in shape], indexing="ij")
    deep &= ~(ii & jj & kk)
    if not deep.any():
        return regular_tets(pts, L, weight=W)
    # structured cells: complete cells with a removed (deep) corner. The hull of the other points
    # holds every tetrahedron of the full triangulation without a removed corner (empty power
    # spheres stay empty in a subset), and these tile the block outside the structured cells, so
    # the hull's tetrahedra with a centroid outside them are exactly the full triangulation there
    scell = np.zeros(cell.shape, bool)
    for a in (0, 1):
        for b in (0, 1):
            for d in (0, 1):
                scell |= deep[a:sx - 1 + a, b:sy - 1 + b, d:sz - 1 + d]
    scell &= cell
    keep_pt = np.ones(len(pts), bool)
    keep_pt[lat_id[deep]] = False
    rows = np.flatnonzero(keep_pt)
    t = rows[regular_tets(pts[rows], L, weight=W[rows])]
    # drop the hull's tetrahedra spanning the structured region (their centroid lies in it)
    origin = pts[start] - idx[0] * L
    ci = np.floor((pts[t].mean(axis=1) - origin) / L).astype(np.int64)
    inr = ((ci >= 0) & (ci < np.array(scell.shape))).all(axis=1)
    drop = np.zeros(len(t), bool)
    drop[inr] = scell[ci[inr, 0], ci[inr, 1], ci[inr, 2]]
    return np.concatenate([t[~drop], _five_split(np.argwhere(scell), lat_id)])


def inside(pts: np.ndarray, N: np.ndarray, D: np.ndarray, tol: float) -> np.ndarray:
    """Mask of points inside the closed convex polyhedron {x: N x <= D} within ``tol``."""
    if len(pts) == 0:
        return np.zeros(0, bool)
    return (pts @ N.T - D <= tol).all(axis=1)


def mesh_convex(verts: np.ndarray, ptr: np.ndarray, loops: np.ndarray, L: float, neighbours=(), fast: bool = True,
                imprint=()):
    """points (n,3), tets (m,4) positive, boundary tris (k,3), tri_source (k,) face index.

    ``neighbours``: already zoned joined blocks as ``(N, D, points, length)`` (face planes, all
    gridpoints, the edge length their weights were made with). Their points on this block's
    boundary are taken over (same coordinates, same weights), this block's own boundary points
    inside them dropped (but never a corner of the block the neighbour lacks), so the shared facets
    are triangulated alike. ``imprint``: segments (k, 2, 3) on this block's faces where faces of
    joined blocks still to be zoned end (see ``dec3d.model.zone_mesh``). ``fast``: see
    ``triangulate`` (False: one hull over all points, the slow twin of the tests)."""
    verts = np.asarray(verts, float)
    bp = boundary_points(verts, ptr, loops, L)
    N, D = face_planes(verts, ptr, loops)
    tol = 1e-6 * L
    corner = np.zeros(len(bp), bool)
    corner[:len(verts)] = True
    if len(imprint):
        # lines where unzoned joined neighbours' faces end on this block's faces: points along them
        # (so that the later neighbours find them and the triangles do not cross the lines), and
        # this block's other boundary points kept 0.6 L away from them
        segs = np.asarray(imprint, float).reshape(-1, 2, 3)
        # ends that are this block's own corners add nothing
        pointlike = np.linalg.norm(segs[:, 1] - segs[:, 0], axis=1) <= tol
        at_corner = np.linalg.norm(segs[:, None, 0] - verts[None], axis=2).min(axis=1) <= tol
        segs = segs[~(pointlike & at_corner)]
    if len(imprint) and len(segs):
        ip = [segs.reshape(-1, 3)] + [_edge_points(a, b, L) for a, b in segs]
        ip = np.concatenate(ip)
        near = _segment_distance(bp, segs) < 0.6 * L
        keep = ~near | corner
        bp, corner = np.concatenate([bp[keep], ip]), np.r_[corner[keep], np.zeros(len(ip), bool)]
    scale = [np.full(len(bp), L)]
    own = [bp]
    adopted = []
    for nN, nD, npts, nlen in neighbours:
        q = npts[inside(npts, N, D, tol)]
        gone = inside(own[0], nN, nD, tol)
        if len(q):
            adopted.append((q, np.full(len(q), float(nlen))))
            # a corner of this block inside the neighbour stays unless the neighbour has it
            from scipy.spatial import cKDTree
            has = cKDTree(q).query(own[0][corner], distance_upper_bound=tol)[0] <= tol
            gone[np.flatnonzero(corner)[~has]] = False
        else:
            gone &= ~corner
        own[0], scale[0], corner = own[0][~gone], scale[0][~gone], corner[~gone]
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    axes = [np.arange(lo[d] + 0.5 * L, hi[d], L) for d in range(3)]
    shape = tuple(len(a) for a in axes)
    I = np.array(np.meshgrid(*[np.arange(n) for n in shape], indexing="ij")).reshape(3, -1).T
    G = np.array(np.meshgrid(*axes, indexing="ij")).reshape(3, -1).T
    inner = np.all(G @ N.T - D < -0.5 * L, axis=1)
    G, I = G[inner], I[inner]
    B = np.concatenate([q for q, _ in adopted] + own)
    sc = np.concatenate([s for _, s in adopted] + scale)
    _, first = np.unique(np.round(B / (1e-9 * L)).astype(np.int64), axis=0, return_index=True)
    first = np.sort(first)
    B, sc = B[first], sc[first]
    pts = np.concatenate([B, G])
    W = np.concatenate([WEIGHT_FRACTION * sc ** 2 * position_hash(B),
                        L ** 2 * (PARITY_WEIGHT * (I.sum(axis=1) % 2 == 0) + LATTICE_JITTER * position_hash(G))])
    nb, ng = len(B), len(G)
    alive = np.ones(len(pts), bool)

    def run():
        sel = np.flatnonzero(alive)
        lat = (nb, I[alive[nb:nb + ng]], shape)
        t = _positive(pts[sel], triangulate(pts[sel], W[sel], L, lat, fast), L)
        return sel[t]

    tets = run()
    best = (_quality(pts, tets), alive.copy(), tets)
    for _ in range(SLIVER_PASSES):
        extra, drop = _sliver_fix(pts, tets, nb, N, D, L)
        if not len(extra) and not len(drop):
            break
        alive[drop] = False
        pts = np.concatenate([pts, extra])
        W = np.concatenate([W, WEIGHT_FRACTION * L ** 2 * position_hash(extra)])
        alive = np.r_[alive, np.ones(len(extra), bool)]
        tets = run()
        q = _quality(pts, tets)
        if q > best[0]:
            best = (q, alive.copy(), tets)
    _, alive, tets = best               # the best round (fewest slivers, then largest smallest angle)
    keep = np.flatnonzero(alive[:len(pts)] if len(alive) >= len(pts) else np.r_[alive, np.zeros(len(pts) - len(alive), bool)])
    newrow = np.full(len(pts), -1, np.int64)
    newrow[keep] = np.arange(len(keep))
    pts, tets = pts[keep], newrow[tets]
    tris = boundary_tris(tets)
    cen = pts[tris].mean(axis=1)
    src = np.argmin(np.abs(cen @ N.T - D), axis=1)
    return pts, tets, tris, src


def _segment_distance(p: np.ndarray, segs: np.ndarray) -> np.ndarray:
    """Distance of each point (n, 3) to the nearest of the segments (k, 2, 3)."""
    best = np.full(len(p), np.inf)
    for a, b in segs:
        d = b - a
        t = np.clip((p - a) @ d / max(float(d @ d), 1e-300), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(p - (a + t[:, None] * d), axis=1))
    return best


def imprint_segments(verts, ptr, loops, other_verts, other_ptr, other_loops, tol: float) -> np.ndarray:
    """Segments (k, 2, 3) of the edges of another convex polyhedron's faces lying on this one's
    faces (coplanar, opposite normals), clipped to the face, leaving out those along this face's own
    edges; a clipped end on this face's boundary is kept as a zero-length segment (a point)."""
    N, D = face_planes(verts, ptr, loops)
    oN, oD = face_planes(other_verts, other_ptr, other_loops)
    out = []
    for f in range(len(ptr) - 1):
        for g in range(len(other_ptr) - 1):
            if N[f] @ oN[g] > -1 + 1e-9 or abs(D[f] + oD[g]) > tol:
                continue
            P = verts[loops[ptr[f]:ptr[f + 1]]]
            m = len(P)
            inward = [np.cross(N[f], P[(i + 1) % m] - P[i]) for i in range(m)]
            inward = [w / np.linalg.norm(w) for w in inward]
            Q = other_verts[other_loops[other_ptr[g]:other_ptr[g + 1]]]
            for i in range(len(Q)):
                a, b = Q[i], Q[(i + 1) % len(Q)]
                t0, t1 = 0.0, 1.0
                for k in range(m):
                    da, db = inward[k] @ (a - P[k]), inward[k] @ (b - P[k])
                    if da < -tol and db < -tol:
                        t0, t1 = 1.0, 0.0
                        break
                    if (da < -tol) != (db < -tol):
                        t = da / (da - db)
                        if da < -tol:
                            t0 = max(t0, t)
                        else:
                            t1 = min(t1, t)
                if t1 < t0:
                    continue
                pa = a if t0 == 0.0 else a + t0 * (b - a)
                pb = b if t1 == 1.0 else a + t1 * (b - a)
                on_edge = any(abs(inward[k] @ (pa - P[k])) <= tol and abs(inward[k] @ (pb - P[k])) <= tol
                              for k in range(m))
                if on_edge:
                    out += [(pa, pa), (pb, pb)]
                else:
                    out.append((pa, pb))
    if not out:
        return np.zeros((0, 2, 3))
    return np.array(out, float)


def _positive(pts, tets, L):
    """Drop flat tetrahedra (volume below 1e-10 L³) and orient the rest positive."""
    a, b, c, d = (pts[tets[:, k]] for k in range(4))
    vol = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6.0
    keep = np.abs(vol) > 1e-10 * L ** 3
    tets, vol = tets[keep], vol[keep]
    neg = vol < 0
    tets[neg] = tets[neg][:, [0, 2, 1, 3]]
    return tets


def tet_min_dihedral(pts: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Smallest dihedral angle (radians) of each tetrahedron."""
    p = pts[tets[:, :4]]
    opp = [(1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1)]
    n = np.stack([np.cross(p[:, b] - p[:, a], p[:, c] - p[:, a]) for a, b, c in opp], axis=1)
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    best = np.full(len(tets), np.pi)
    for i in range(4):
        for j in range(i + 1, 4):
            cosang = np.clip(np.einsum("ij,ij->i", n[:, i], n[:, j]), -1, 1)
            best = np.minimum(best, np.pi - np.arccos(cosang))
    return best


def _quality(pts, tets):
    """Ordering of meshes for sliver removal: fewer tetrahedra below SLIVER_DEG first, then a
    larger smallest angle."""
    d = tet_min_dihedral(pts, tets)
    return (float(d.min(initial=np.pi)), -int((d < np.radians(SLIVER_DEG)).sum()))


def _sliver_fix(pts, tets, nb, N, D, L):
    """Changes that break up the tetrahedra whose smallest dihedral angle is below SLIVER_DEG,
    touching interior points only (rows from ``nb`` on), so the facet triangulations (and the
    conformity of joined blocks) stay: a sliver gets a point at its circumcentre, or its centroid
    when the circumcentre is not well inside, kept only when at least 0.15 L inside the block and
    0.3 L from every point; failing that, it loses its interior corner nearest the boundary when
    that is within 1.5 L of it. Returns (new points, rows to drop)."""
    from scipy.spatial import cKDTree
    bad = np.flatnonzero(tet_min_dihedral(pts, tets) < np.radians(SLIVER_DEG))
    if not len(bad):
        return np.zeros((0, 3)), np.zeros(0, np.int64)
    tb = tets[bad]
    p = pts[tb]
    a = p[:, 0]
    A = p[:, 1:] - a[:, None, :]
    rhs = 0.5 * np.einsum("ijk,ijk->ij", A, A)
    ok = np.abs(np.linalg.det(A)) > 1e-14 * L ** 3
    cc = p.mean(axis=1)
    cc[ok] = a[ok] + np.linalg.solve(A[ok], rhs[ok][..., None])[..., 0]
    cand = np.where(((cc @ N.T - D) < -0.15 * L).all(axis=1)[:, None], cc, p.mean(axis=1))
    good = ((cand @ N.T - D) < -0.15 * L).all(axis=1)
    good[good] = cKDTree(pts).query(cand[good])[0] > 0.3 * L
    cand = cand[good]
    # the rest lose their interior corner nearest the boundary, when it is within 1.5 L of it
    depth = -(p[~good] @ N.T - D).max(axis=2)
    depth = np.where(tb[~good] >= nb, depth, np.inf)
    near = depth.min(axis=1) < 1.5 * L
    drop = np.unique(tb[~good][near, np.argmin(depth[near], axis=1)])
    if len(cand):
        # one point per cluster: greedy in a fixed order, via neighbour lists
        cand = cand[np.lexsort(cand.T[::-1])]
        taken = np.ones(len(cand), bool)
        for i, js in enumerate(cKDTree(cand).query_ball_point(cand, 0.3 * L)):
            if taken[i]:
                for j in js:
                    if j > i:
                        taken[j] = False
        cand = cand[taken]
    return cand.reshape(-1, 3), drop


def _row_keys(rows: np.ndarray) -> np.ndarray:
    """One int64 per row of small non-negative integers (sorted rows of 2 or 3), equal rows alike."""
    n = int(rows.max(initial=0)) + 1
    k = rows[:, 0].astype(np.int64)
    if n ** rows.shape[1] >= 2 ** 62:
        _, inv = np.unique(rows, axis=0, return_inverse=True)
        return inv.ravel().astype(np.int64)
    for j in range(1, rows.shape[1]):
        k = k * n + rows[:, j]
    return k


def boundary_tris(tets: np.ndarray) -> np.ndarray:
    """Faces of positive tetrahedra that belong to one tetrahedron only, counter-clockwise seen
    from outside."""
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]])
    key = _row_keys(np.sort(faces, axis=1))
    order = np.argsort(key, kind="stable")
    ks = key[order]
    single = np.ones(len(ks), bool)
    same = ks[1:] == ks[:-1]
    single[1:] &= ~same
    single[:-1] &= ~same
    return faces[np.sort(order[single])]


def min_dihedral_deg(pts: np.ndarray, tets: np.ndarray) -> float:
    """Smallest dihedral angle (degrees) over all tetrahedra: the angle between the two faces at
    each of the six edges, from the outward face normals n_i, n_j as pi - angle(n_i, n_j)."""
    p = pts[tets[:, :4]]
    opp = [(1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1)]
    n = np.stack([np.cross(p[:, b] - p[:, a], p[:, c] - p[:, a]) for a, b, c in opp], axis=1)
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    best = np.pi
    for i in range(4):
        for j in range(i + 1, 4):
            cosang = np.clip(np.einsum("ij,ij->i", n[:, i], n[:, j]), -1, 1)
            best = min(best, float((np.pi - np.arccos(cosang)).min()))
    return np.degrees(best)
