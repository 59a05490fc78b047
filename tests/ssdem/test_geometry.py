"""Shared edges, including partial overlaps, and mesh checks."""
import numpy as np

from dec3d.ssdem import geometry


def csr(polys):
    verts = np.concatenate(polys).astype(float)
    return verts, np.concatenate([[0], np.cumsum([len(p) for p in polys])])


def test_hanging_vertex_gives_two_partial_interfaces():
    """A 2x1 block under two 1x1 blocks: two interfaces of length 1, normals up."""
    polys = [np.array([[0, 0], [2, 0], [2, 1], [0, 1]]),
             np.array([[0, 1], [1, 1], [1, 2], [0, 2]]),
             np.array([[1, 1], [2, 1], [2, 2], [1, 2]])]
    se = geometry.shared_edges(*csr(polys), tol=1e-9)
    pairs = sorted(zip(se.a.tolist(), se.b.tolist()))
    assert pairs == [(0, 1), (0, 2), (1, 2)] or sorted(tuple(sorted(p)) for p in pairs) == [(0, 1), (0, 2), (1, 2)]
    lengths = np.hypot(*(se.p1 - se.p0).T)
    np.testing.assert_allclose(lengths, 1.0)
    assert se.same_side == []


def test_overlaps_are_reported():
    polys = [np.array([[0, 0], [2, 0], [2, 1], [0, 1]]), np.array([[1, 0.5], [3, 0.5], [3, 2], [1, 2]]),
             np.array([[5, 0], [6, 0], [6, 1], [5, 1]])]
    assert geometry.overlapping_pairs(*csr(polys), tol=1e-9) == [(0, 1)]
    # same-orientation collinear edges (blocks stacked on one another) come out of shared_edges
    polys = [np.array([[0, 0], [2, 0], [2, 1], [0, 1]]), np.array([[1, 0], [3, 0], [3, 1], [1, 1]])]
    assert geometry.shared_edges(*csr(polys), tol=1e-9).same_side == [(0, 1)]


def test_area_centroid_and_convexity():
    polys = [np.array([[0, 0], [2, 0], [2, 1], [0, 1]]), np.array([[0, 0], [2, 0], [1, 0.2], [1, 2]])]
    area, cen = geometry.polygon_area_centroid(*csr(polys))
    assert area[0] == 2.0 and np.allclose(cen[0], [1.0, 0.5])
    assert geometry.convexity_defect(*csr(polys), tol=1e-12).tolist() == [False, True]
