"""Mesher checks on a convex block: positive tetrahedra, volumes summing to the block volume,
boundary triangles lying on block faces and covering the surface area."""
import numpy as np

from dec3d.geometry.zoning import mesh_convex, min_dihedral_deg


def _brick(a, b, c):
    v = np.array([[x, y, z] for z in (0, c) for y in (0, b) for x in (0, a)], float)
    # outward counterclockwise loops
    loops = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    return v, np.arange(0, 25, 4), np.array(loops).ravel()


def test_brick_volume_and_positivity():
    v, ptr, loops = _brick(1.0, 0.7, 1.3)
    pts, tets, tris, src = mesh_convex(v, ptr, loops, 0.2)
    a, b, c, d = (pts[tets[:, k]] for k in range(4))
    vol = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6
    assert (vol > 0).all()
    assert abs(vol.sum() - 0.91) < 1e-12 * 0.91
    area = 0.5 * np.linalg.norm(np.cross(pts[tris[:, 1]] - pts[tris[:, 0]],
                                         pts[tris[:, 2]] - pts[tris[:, 0]]), axis=1)
    assert abs(area.sum() - 2 * (0.7 + 0.91 + 1.3)) < 1e-10
    cen = pts[tris].mean(axis=1)
    on_face = np.isclose(cen, 0).any(axis=1) | np.isclose(cen, [1.0, 0.7, 1.3]).any(axis=1)
    assert on_face.all()
    # closed surface: every boundary edge in two triangles; Euler V - E + F - T = 1 for a ball
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    _, cnt = np.unique(e, axis=0, return_counts=True)
    assert (cnt == 2).all()
    te = np.sort(tets[:, [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]].reshape(-1, 2), axis=1)
    tf = np.sort(tets[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    E, F = len(np.unique(te, axis=0)), len(np.unique(tf, axis=0))
    assert len(np.unique(tets)) - E + F - len(tets) == 1
    assert min_dihedral_deg(pts, tets) > 5.0


def test_min_dihedral_regular_tet():
    # regular tetrahedron: arccos(1/3) = 70.5288 degrees
    p = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    assert abs(min_dihedral_deg(p, np.array([[0, 1, 2, 3]])) - np.degrees(np.arccos(1 / 3))) < 1e-9


def _parallelepiped(a, b, c):
    v = np.array([i * a + j * b + k * c for k in (0, 1) for j in (0, 1) for i in (0, 1)], float)
    loops = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    return v, np.arange(0, 25, 4), np.array(loops).ravel()


def test_sliver_removal_keeps_surface_and_volume(monkeypatch):
    """A sheared block: the plain regular triangulation has a sliver of 0.27 degrees; interior points
    added at the slivers raise the smallest dihedral angle above 15 degrees without touching the
    surface triangles (so joined neighbours stay conforming)."""
    import dec3d.geometry.zoning as z
    a, b, c = np.array([1.3, 0, 0]), np.array([0.37, 1.1, 0.1]), np.array([0.15, 0.3, 0.9])
    v, ptr, loops = _parallelepiped(a, b, c)
    V = float(np.dot(a, np.cross(b, c)))
    monkeypatch.setattr(z, "SLIVER_PASSES", 0)
    p0, t0, s0, _ = z.mesh_convex(v, ptr, loops, 0.23)
    monkeypatch.undo()
    p1, t1, s1, _ = mesh_convex(v, ptr, loops, 0.23)
    assert min_dihedral_deg(p0, t0) < 1.0
    assert min_dihedral_deg(p1, t1) > 15.0
    for p, t in ((p0, t0), (p1, t1)):
        a_, b_, c_, d_ = (p[t[:, k]] for k in range(4))
        vol = np.einsum("ij,ij->i", np.cross(b_ - a_, c_ - a_), d_ - a_) / 6
        assert (vol > 0).all() and abs(vol.sum() - V) < 1e-12 * V
    key = lambda p, s: {tuple(sorted(map(tuple, p[x].tolist()))) for x in s}
    assert len(p1) > len(p0) and key(p0, s0) == key(p1, s1)


def _tet_keys(p, t):
    return {tuple(sorted(map(tuple, np.round(p[x] / 1e-12).astype(np.int64).tolist()))) for x in t}


def test_structured_interior_equals_one_hull(monkeypatch):
    """The fast path (cells deep inside take the five-tetrahedron split, the hull only for the
    rest) against its slow twin (one hull over all points): the same tetrahedra, for a brick and
    a sheared block, before sliver removal (which then acts on the same mesh)."""
    import dec3d.geometry.zoning as z
    monkeypatch.setattr(z, "SLIVER_PASSES", 0)
    cases = [(_brick(1.0, 0.7, 1.3), 0.09),
             (_parallelepiped(np.array([1.3, 0, 0]), np.array([0.37, 1.1, 0.1]), np.array([0.15, 0.3, 0.9])), 0.07)]
    for (v, ptr, loops), L in cases:
        pf, tf, sf, _ = z.mesh_convex(v, ptr, loops, L, fast=True)
        ps, ts, ss, _ = z.mesh_convex(v, ptr, loops, L, fast=False)
        assert len(tf) > 3000
        assert _tet_keys(pf, tf) == _tet_keys(ps, ts)
        assert _tet_keys(pf, sf) == _tet_keys(ps, ss)


def test_five_split_of_the_lattice():
    """Deep inside a brick every lattice cell is split in five: the central tetrahedron on the
    corners of odd parity (a regular tetrahedron of edge L*sqrt(2), volume L^3/3) and four corner
    tetrahedra (volume L^3/6 each)."""
    L = 0.1
    v, ptr, loops = _brick(1.0, 1.0, 1.0)
    pts, tets, _, _ = mesh_convex(v, ptr, loops, L)
    p = pts[tets]
    deep = (np.abs(p - 0.5) < 0.2).all(axis=(1, 2))
    vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6
    assert deep.sum() >= 5 * 27
    v_deep = np.sort(vol[deep])
    assert np.allclose(np.unique(np.round(v_deep / L ** 3, 12)), [1 / 6, 1 / 3])
    assert abs((np.isclose(v_deep, L ** 3 / 3)).sum() * 4 - (np.isclose(v_deep, L ** 3 / 6)).sum()) <= 8
    assert min_dihedral_deg(pts, tets[deep]) > 54.7   # arccos(1/sqrt 3) = 54.74 at the corner tetrahedra


def test_regular_tets_against_plain_lower_hull():
    """regular_tets (with its far cap points) against a plain lower hull of the lifted points,
    written here from the definition: the same tetrahedra once flat ones are dropped."""
    from scipy.spatial import ConvexHull

    from dec3d.geometry.zoning import boundary_points, position_hash, regular_tets
    v, ptr, loops = _brick(1.0, 0.6, 0.8)
    L = 0.15
    pts = boundary_points(v, ptr, loops, L)
    g = np.arange(0.1, 0.95, L)
    inner = np.array([[x, y, z] for x in g for y in g if y < 0.5 for z in g if z < 0.7])
    pts = np.unique(np.r_[pts, inner], axis=0)
    W = 1e-3 * L ** 2 * position_hash(pts)
    mine = regular_tets(pts, L, weight=W)
    lift = np.c_[pts, (pts ** 2).sum(axis=1) + W]
    h = ConvexHull(lift, qhull_options="Qt")
    plain = h.simplices[h.equations[:, 3] < 0]

    def solid(t):
        p = pts[t]
        vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0])
        return {tuple(sorted(x)) for x in t[np.abs(vol) > 1e-9].tolist()}
    assert len(solid(mine)) > 500
    assert solid(mine) == solid(plain)
