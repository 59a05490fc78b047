"""Zone measures (dec3d.model.zone_quality) against values known in closed form, and the stress
measures against the eigenvalues and the principal-stress form of von Mises."""
import numpy as np
import pytest

from dec3d.model import zone_quality as Q


def _regular():
    # alternate corners of a cube: a regular tetrahedron of edge √2, volume 1/3
    return np.array([[[0, 0, 0], [1, 0, 1], [1, 1, 0], [0, 1, 1]]], float)


def _rot(p, seed):
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return p @ q.T + rng.normal(size=3)


def test_regular_tetrahedron():
    p = _regular()
    assert Q.volumes(p)[0] == pytest.approx(1 / 3, rel=1e-14)
    np.testing.assert_allclose(Q.edge_lengths(p), np.sqrt(2), rtol=1e-14)
    np.testing.assert_allclose(Q.dihedral_angles(p), np.arccos(1 / 3), rtol=1e-13)


def test_corner_tetrahedron_angles_by_edge():
    # corner at the origin with unit legs: 90° on the three legs, arctan(√2) on the far edges
    p = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]], float)
    d = np.degrees(Q.dihedral_angles(p)[0])
    by_edge = dict(zip(map(tuple, Q.EDGES), d))
    for e in ((0, 1), (2, 0), (0, 3)):
        assert by_edge[e] == pytest.approx(90.0, abs=1e-12)
    for e in ((1, 2), (1, 3), (2, 3)):
        assert by_edge[e] == pytest.approx(np.degrees(np.arctan(np.sqrt(2))), rel=1e-13)
    assert Q.volumes(p)[0] == pytest.approx(1 / 6, rel=1e-14)
    # a left-handed tetrahedron has negative volume; the angles do not care
    assert Q.volumes(p[:, [0, 2, 1, 3]])[0] == pytest.approx(-1 / 6, rel=1e-14)
    np.testing.assert_allclose(np.sort(Q.dihedral_angles(p[:, [0, 2, 1, 3]])[0]), np.sort(np.radians(d)), rtol=1e-13)


def test_measures_are_invariant_under_rigid_motion():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(50, 4, 3))
    for seed in range(3):
        q = _rot(p.reshape(-1, 3), seed).reshape(p.shape)
        np.testing.assert_allclose(Q.volumes(q), Q.volumes(p), rtol=1e-10, atol=1e-13)
        np.testing.assert_allclose(Q.edge_lengths(q), Q.edge_lengths(p), rtol=1e-12)
        np.testing.assert_allclose(Q.dihedral_angles(q), Q.dihedral_angles(p), rtol=1e-8, atol=1e-10)


def test_sliver_has_a_small_angle():
    # the four corners of a square, one lifted by h: a flat sliver whose angle at two edges → 0 with h
    for h in (1e-1, 1e-2, 1e-3):
        p = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, h], [0, 1, 0]]], float)
        assert Q.dihedral_angles(p).min() < 4 * h
        assert abs(Q.volumes(p)[0]) == pytest.approx(h / 6, rel=1e-12)


def test_stress_measures():
    rng = np.random.default_rng(7)
    s = rng.normal(size=(40, 6)) * 1e6
    full = np.array([[[a[0], a[3], a[4]], [a[3], a[1], a[5]], [a[4], a[5], a[2]]] for a in s])
    ev = np.array([np.sort(np.linalg.eigvals(t).real) for t in full])
    np.testing.assert_allclose(Q.principal_stresses(s), ev, rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(Q.mean_stress(s), ev.sum(axis=1) / 3, rtol=1e-9, atol=1e-6)
    vm = np.sqrt(((ev[:, 0] - ev[:, 1]) ** 2 + (ev[:, 1] - ev[:, 2]) ** 2 + (ev[:, 2] - ev[:, 0]) ** 2) / 2)
    np.testing.assert_allclose(Q.von_mises(s), vm, rtol=1e-9)
    # uniaxial σ: von Mises is |σ|; hydrostatic: zero
    np.testing.assert_allclose(Q.von_mises(np.array([[-5e6, 0, 0, 0, 0, 0], [3, 3, 3, 0, 0, 0]])), [5e6, 0], atol=1e-9)
