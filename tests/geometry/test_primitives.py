"""Closed-form volumes, centroids and inertia of the block shapes, and refused input."""
import math

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.geometry.errors import GeometryError
from dec3d.geometry.polyhedron import brick, polyhedron_from_faces, prism, tetrahedron
from dec3d.geometry.tunnel import tunnel
from dec3d.model import ranges as R
from dec3d.model.blocks import add_blocks, delete_blocks
from dec3d.model.model import Model


def one_block(poly, density=1.0):
    m = Model()
    add_blocks(m, [poly], density=density)
    b = m.blocks
    return m, b["volume"][0], b["centroid"][0], b["inertia"][0]


def rotation(ax, ay, az):
    cx, sx, cy, sy, cz, sz = (math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay),
                              math.cos(az), math.sin(az))
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def test_brick_volume_centroid_inertia():
    m, vol, cen, inertia = one_block(brick(1, 3, -1, 2, 0.5, 4.5), density=2500)
    a, b, c = 2.0, 3.0, 4.0
    assert vol == pytest.approx(a * b * c, rel=1e-14)
    np.testing.assert_allclose(cen, [2, 0.5, 2.5], rtol=0, atol=1e-14)
    mass = 2500 * a * b * c
    want = np.diag([mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12, mass * (a * a + b * b) / 12])
    np.testing.assert_allclose(inertia, want, rtol=1e-13, atol=1e-9)
    assert m.blocks["mass"][0] == pytest.approx(mass)
    np.testing.assert_allclose(m.blocks["principal_moment"][0], np.sort(np.diag(want)), rtol=1e-13)
    axes = m.blocks["principal_axes"][0]
    np.testing.assert_allclose(np.abs(axes), np.eye(3)[:, [2, 1, 0]], atol=1e-12)
    assert np.linalg.det(axes) == pytest.approx(1.0)


def test_approximate_inertia_of_a_cube():
    # 2/5 m r̄² with r̄ the centroid-to-vertex distance (all equal in a cube)
    m, vol, cen, inertia = one_block(brick(0, 2, 0, 2, 0, 2), density=3.0)
    mass = 24.0
    assert m.blocks["inertia_approx"][0] == pytest.approx(0.4 * mass * 3.0, rel=1e-14)


def test_rotated_brick_principal_axes():
    q = rotation(0.3, -0.7, 1.1)
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 3)], dtype=float)
    quads = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    rc = corners @ q.T + np.array([5.0, -2.0, 1.0])
    m, vol, cen, inertia = one_block(polyhedron_from_faces([rc[qd] for qd in quads]), density=2.0)
    assert vol == pytest.approx(6.0, rel=1e-13)
    local = np.diag([2 * 6 * (4 + 9) / 12, 2 * 6 * (1 + 9) / 12, 2 * 6 * (1 + 4) / 12])
    np.testing.assert_allclose(inertia, q @ local @ q.T, atol=1e-12)
    axes = m.blocks["principal_axes"][0]
    # smallest moment about the longest side (local z), largest about local x
    np.testing.assert_allclose(np.abs(axes[:, 0]), np.abs(q[:, 2]), atol=1e-10)
    np.testing.assert_allclose(np.abs(axes[:, 2]), np.abs(q[:, 0]), atol=1e-10)


def test_tilted_tetrahedron_against_analytic_inertia():
    # right tetrahedron 0, a e1, a e2, a e3: ∫x² dV = a⁵/60, ∫xy dV = a⁵/120 (about 0)
    a = 2.0
    vol0 = a ** 3 / 6
    c0 = np.full(3, a / 4)
    second = np.full((3, 3), a ** 5 / 120) + np.eye(3) * (a ** 5 / 60 - a ** 5 / 120)
    j0 = second - vol0 * np.outer(c0, c0)
    i0 = np.trace(j0) * np.eye(3) - j0
    q = rotation(0.4, 0.9, -0.3)
    t = np.array([1.0, 2.0, -3.0])
    pts = [t, t + a * q[:, 0], t + a * q[:, 1], t + a * q[:, 2]]
    m, vol, cen, inertia = one_block(tetrahedron(*pts), density=1.0)
    assert vol == pytest.approx(vol0, rel=1e-13)
    np.testing.assert_allclose(cen, t + q @ c0, atol=1e-13)
    np.testing.assert_allclose(inertia, q @ i0 @ q.T, atol=1e-13)


@pytest.mark.parametrize("flip", [(), (0,), (1, 3, 5), (0, 1, 2, 3, 4, 5)])
def test_polyhedron_accepts_either_winding(flip):
    c = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    faces = [c[q[::-1]] if i in flip else c[q] for i, q in enumerate(quads)]
    m, vol, cen, _ = one_block(polyhedron_from_faces(faces))
    assert vol == pytest.approx(1.0, rel=1e-14)
    np.testing.assert_allclose(cen, [0.5, 0.5, 0.5], atol=1e-15)


def test_pyramid_volume_and_centroid():
    base = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0)]
    apex = (1, 1, 3)
    faces = [base] + [[base[i], base[(i + 1) % 4], apex] for i in range(4)]
    m, vol, cen, _ = one_block(polyhedron_from_faces(faces))
    assert vol == pytest.approx(4.0 * 3 / 3, rel=1e-14)
    np.testing.assert_allclose(cen, [1, 1, 0.75], atol=1e-14)


def test_oblique_prism_volume_and_centroid():
    tri = np.array([[0, 0, 0], [3, 0, 0], [0, 2, 0]], dtype=float)
    shift = np.array([1.0, 0.5, 4.0])
    m, vol, cen, _ = one_block(prism(tri, tri + shift))
    assert vol == pytest.approx(3.0 * 4.0, rel=1e-14)        # base area 3, height 4
    np.testing.assert_allclose(cen, tri.mean(axis=0) + shift / 2, atol=1e-14)


def test_tunnel_volumes_and_quarter_model():
    r, b, length = 1.0, 9.0, 1.0
    polys = tunnel(0.0, 0.0, r, (0.0, length), 1, 10, 5, b, 1.4)
    m = Model()
    add_blocks(m, polys)
    assert m.blocks.n == 40 * 11
    half = r + b
    assert m.blocks["volume"].sum() == pytest.approx((2 * half) ** 2 * length, rel=1e-13)
    # the 40-gon opening, then the quarter x ≥ 0, z ≥ 0 (as the elastic-hole decks do)
    delete_blocks(m, R.mask_cylinder(m, "block", (0, 0, 0), (0, 1, 0), 0, 1))
    hole = 0.5 * 40 * math.sin(2 * math.pi / 40) * r * r
    assert m.blocks["volume"].sum() == pytest.approx((2 * half) ** 2 * length - hole, rel=1e-13)
    delete_blocks(m, R.mask_plane(m, "block", "below", dip=0.0, dip_direction=0.0))
    delete_blocks(m, R.mask_plane(m, "block", "below", dip=math.pi / 2, dip_direction=math.pi / 2))
    assert m.blocks.n == 100
    assert m.blocks["volume"].sum() == pytest.approx(half * half * length - hole / 4, rel=1e-13)
    np.testing.assert_allclose(m.blocks["centroid"][:, 1], 0.5, atol=1e-14)
    assert R.mask_position_x(m, "face", half).sum() == 5
    assert R.mask_position_z(m, "face", half).sum() == 5
    # the outer blocks widen outwards by the radius ratio along the +x ray
    on_axis = np.flatnonzero(R.mask_position_z(m, "vertex", 0.0) & R.mask_position_y(m, "vertex", 0.0))
    xs = np.unique(np.round(m.vertices["pos"][on_axis, 0], 12))
    widths = np.diff(xs)
    np.testing.assert_allclose(widths[1:] / widths[:-1], 1.4, rtol=1e-9)


def test_tunnel_axis_follows_dip_and_dip_direction():
    polys = tunnel(math.radians(30), math.radians(90), 1.0, (0.0, 2.0), 2, 2, 1, 2.0, 1.0)
    m = Model()
    add_blocks(m, polys)
    axis = np.array([math.cos(math.radians(30)), 0.0, -math.sin(math.radians(30))])
    assert m.blocks["volume"].sum() == pytest.approx(36.0 * 2.0, rel=1e-13)
    np.testing.assert_allclose(m.vertices["pos"].mean(axis=0) @ axis, 1.0, atol=1e-12)


@pytest.mark.parametrize("faces, words", [
    ([[(0, 0, 0), (1, 0, 0), (1, 1, 0.2), (0, 1, 0)], [(0, 0, 0), (0, 0, 1), (1, 0, 0)],
      [(0, 0, 0), (0, 1, 0), (0, 0, 1)], [(1, 0, 0), (0, 0, 1), (1, 1, 0.2)]], "face 1 is not planar"),
    ([[(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 0, 0), (1, 0, 0), (0, 0, 1)],
      [(0, 0, 0), (0, 1, 0), (0, 0, 1)], [(1, 0, 0), (0, 1, 0), (0.2, 0.2, 0.2)]], "open"),
    ([[(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 0, 0), (1, 0, 0), (0, 0, 1)]], "at least 4 faces"),
    ([[(0, 0, 0), (0, 0, 0), (1, 0, 0)]] * 4, "fewer than 3 distinct corners"),
])
def test_bad_polyhedra_are_refused_with_the_reason(faces, words):
    with pytest.raises(GeometryError, match=words) as info:
        polyhedron_from_faces(faces)
    assert isinstance(info.value, Dec3dError)


def test_non_convex_polyhedron_is_refused():
    # a cube with a dent: the top face's centre pushed down (4 triangles on top)
    c = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
    dent = np.array([0.5, 0.5, 0.6])
    quads = [[0, 2, 3, 1], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    faces = [c[q] for q in quads] + [[c[4], c[5], dent], [c[5], c[7], dent], [c[7], c[6], dent],
                                     [c[6], c[4], dent]]
    with pytest.raises(GeometryError, match="not convex"):
        polyhedron_from_faces(faces)


def test_zero_volume_shapes_are_refused():
    tri = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    with pytest.raises(GeometryError, match="prism: zero volume"):
        prism(tri, tri)
    with pytest.raises(GeometryError, match="zero"):
        tetrahedron((0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0))
    with pytest.raises(GeometryError, match="zero thickness in z"):
        brick(0, 1, 0, 1, 2, 2)
    with pytest.raises(GeometryError, match="face-1 has 3 corners but face-2 has 4"):
        prism(tri, [(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)])


def test_non_planar_prism_side_is_refused():
    with pytest.raises(GeometryError, match="not planar"):
        prism([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)],
              [(0, 0, 1), (1, 0, 1), (1, 1, 1.5), (0, 1, 1)])


def test_joined_blocks_have_the_mass_properties_of_their_union():
    from dec3d.geometry.mass import joined_properties
    from dec3d.model.blocks import join_blocks

    m = Model()
    add_blocks(m, [brick(0, 1, 0, 1, 0, 1), brick(1, 3, 0, 1, 0, 1), brick(5, 6, 0, 1, 0, 1)],
               density=10.0)
    join_blocks(m, np.array([True, True, False]))
    leaders, mass, cen, inertia = joined_properties(m)
    whole = Model()
    add_blocks(whole, [brick(0, 3, 0, 1, 0, 1)], density=10.0)
    assert list(leaders) == [0, 2]
    assert mass[0] == pytest.approx(30.0)
    np.testing.assert_allclose(cen[0], whole.blocks["centroid"][0], atol=1e-14)
    np.testing.assert_allclose(inertia[0], whole.blocks["inertia"][0], atol=1e-12)
    np.testing.assert_allclose(inertia[1], m.blocks["inertia"][2], atol=1e-14)
