"""Joint-set cutting: exact volumes, convex pieces, coincident shared faces, snapping,
visibility and range, joins."""
import math

import numpy as np
import pytest

from dec3d.geometry.assemble import block_poly
from dec3d.geometry.cutting import cut_by_planes, cut_joint_set, joint_set_offsets
from dec3d.geometry.errors import GeometryError
from dec3d.geometry.polyhedron import brick
from dec3d.model.blocks import add_blocks, hide_blocks
from dec3d.model.model import Model

D = math.radians


def cube(size=10.0, **kw):
    m = Model()
    add_blocks(m, [brick(0, size, 0, size, 0, size)], **kw)
    return m


def assert_convex_closed(m, tol=1e-9):
    """Every block: closed manifold with consistently oriented faces, every vertex behind
    every face's plane, positive volume."""
    for r in range(m.blocks.n):
        p = block_poly(m, r)
        directed = set()
        for loop in p.faces():
            for a, b in zip(loop, np.roll(loop, -1)):
                assert (a, b) not in directed
                directed.add((a, b))
        assert all((b, a) in directed for a, b in directed)
        for f, loop in enumerate(p.faces()):
            n = m.faces["normal"][m.blocks["face_start"][r] + f]
            d = (p.vertices - p.vertices[loop].mean(axis=0)) @ n
            assert d.max() <= tol
        assert m.blocks["volume"][r] > 0


def test_cube_into_8000_blocks_keeps_volume():
    m = cube(density=2000.0)
    for dip, dd in ((90, 90), (90, 0), (0, 0)):
        cut_joint_set(m, D(dip), D(dd), origin=(0, 0, 0), spacing=0.5)
    b = m.blocks
    assert b.n == 8000
    assert abs(b["volume"].sum() - 1000.0) <= 1e-12 * 1000.0
    np.testing.assert_allclose(b["volume"], 0.125, rtol=1e-12)
    assert (b["face_count"] == 6).all() and (b["vert_count"] == 8).all()
    assert sorted(b["id"]) == list(range(1, 8001))
    assert b["mass"].sum() == pytest.approx(2.0e6, rel=1e-12)
    # every vertex sits on the 0.5 m grid
    pos = m.vertices["pos"]
    np.testing.assert_allclose(pos * 2, np.round(pos * 2), atol=1e-12)


def oblique_cut(m):
    cut_joint_set(m, D(63), D(31), origin=(0.1, 0.2, 0.3), spacing=2.3)
    cut_joint_set(m, D(48), D(207), origin=(1, 1, 1), spacing=3.1)
    cut_joint_set(m, D(12), D(120), origin=(0, 0, 0.4), spacing=2.7)


def test_oblique_joint_sets_give_convex_pieces_and_exact_volume():
    m = cube()
    oblique_cut(m)
    assert m.blocks.n > 60
    assert abs(m.blocks["volume"].sum() - 1000.0) <= 1e-12 * 1000.0
    assert_convex_closed(m)


def face_key(m, f):
    loop = m.face_vertices["vertex"][m.faces["vstart"][f]:m.faces["vstart"][f] + m.faces["nvert"][f]]
    return tuple(sorted(map(tuple, m.vertices["pos"][loop])))


def test_shared_faces_coincide_vertex_for_vertex():
    m = cube()
    oblique_cut(m)
    keys = {}
    for f in range(m.faces.n):
        keys.setdefault(face_key(m, f), []).append(f)
    inner = [f for f in range(m.faces.n)
             if not np.any(np.isclose(m.faces["centroid"][f], 0.0) | np.isclose(m.faces["centroid"][f], 10.0))]
    assert inner
    for f in inner:
        partners = [g for g in keys[face_key(m, f)] if g != f]
        assert len(partners) == 1, f"face {f} has no partner with the same corners"
        g = partners[0]
        assert m.faces["block"][g] != m.faces["block"][f]
        np.testing.assert_allclose(m.faces["normal"][g], -m.faces["normal"][f], atol=1e-12)


def test_pieces_keep_parent_attributes_and_first_piece_keeps_id():
    m = Model()
    add_blocks(m, [brick(0, 1, 0, 1, 0, 1), brick(2, 3, 0, 1, 0, 1)], density=2650.0, group="rock")
    cut_by_planes(m, (0, 0, 1), [0.25, 0.5])
    b = m.blocks
    assert b.n == 6
    assert list(b["id"]) == [1, 2, 3, 4, 5, 6]
    # block 1 (row 0) is the lowest piece of the first brick
    assert b["centroid"][0, 2] == pytest.approx(0.125)
    assert (b["density"] == 2650.0).all()
    assert (b["group"][:, 0] == m.groups.code("rock")).all()
    np.testing.assert_allclose(sorted(b["volume"]), [0.25, 0.25, 0.25, 0.25, 0.5, 0.5])
    assert (b["leader"] == np.arange(6)).all()


def test_planes_within_tolerance_of_a_face_snap_instead_of_making_slivers():
    m = cube(size=1.0)
    tol = m.tolerance
    cut_by_planes(m, (0, 0, 1), [0.5 * tol, 1.0 - 0.5 * tol])
    assert m.blocks.n == 1
    cut_by_planes(m, (0, 0, 1), [3 * tol])
    assert m.blocks.n == 2
    assert m.blocks["volume"].min() == pytest.approx(3 * tol, rel=1e-6)
    # a plane through a corner within tolerance: the vertex stays, no new vertex next to it
    m = cube(size=1.0)
    cut_by_planes(m, np.array([1.0, 1.0, 0.0]) / math.sqrt(2), [0.5 * tol / math.sqrt(2)])
    assert m.blocks.n == 1
    cut_by_planes(m, np.array([1.0, 1.0, 1.0]) / math.sqrt(3), [1.0 / math.sqrt(3) + 0.3 * tol])
    assert m.blocks.n == 2
    assert abs(m.blocks["volume"].sum() - 1.0) < 1e-15
    pos = m.vertices["pos"]
    dist = np.linalg.norm(pos[:, None] - pos[None, :], axis=2)
    assert dist[(dist > 0)].min() > tol


def test_hidden_blocks_and_blocks_out_of_range_are_not_cut():
    m = Model()
    add_blocks(m, [brick(0, 1, 0, 1, 0, 1), brick(1, 2, 0, 1, 0, 1), brick(2, 3, 0, 1, 0, 1)])
    hide_blocks(m, np.array([False, True, False]))
    in_range = np.array([True, True, False])
    cut_joint_set(m, 0.0, 0.0, origin=(0, 0, 0.5), mask=in_range)
    ids_cut = m.blocks["id"][m.blocks["volume"] < 0.9]
    assert m.blocks.n == 4 and sorted(ids_cut) == [1, 4]


def test_spacing_and_number():
    n = np.array([0.0, 0.0, 1.0])
    np.testing.assert_allclose(joint_set_offsets(n, (0, 0, 1), None, None, 0, 10), [1.0])
    np.testing.assert_allclose(joint_set_offsets(n, (0, 0, 1), 2.0, 3, 0, 10), [1, 3, 5])
    offs = joint_set_offsets(n, (0, 0, 1), 2.0, None, 0.0, 10.0)
    assert offs.min() <= 0.0 and offs.max() >= 10.0 and np.allclose(np.diff(offs), 2.0)
    with pytest.raises(GeometryError, match="spacing must be positive"):
        joint_set_offsets(n, (0, 0, 0), -1.0, None, 0, 1)
    m = cube()
    cut_joint_set(m, 0.0, 0.0, origin=(0, 0, 1), spacing=2.0, number=3)
    assert m.blocks.n == 4
    np.testing.assert_allclose(sorted(m.blocks["volume"]), [100, 200, 200, 500])


def test_join_keyword_and_joined_parents():
    m = cube(size=1.0)
    cut_joint_set(m, 0.0, 0.0, origin=(0, 0, 0), spacing=0.25, join=True)
    assert m.blocks.n == 4 and (m.blocks["leader"] == 0).all()
    # pieces of joined blocks stay joined; pieces of free blocks are free
    cut_joint_set(m, D(90), D(90), origin=(0.5, 0, 0))
    assert m.blocks.n == 8 and (m.blocks["leader"] == 0).all()
    m = cube(size=1.0)
    cut_joint_set(m, D(90), D(90), origin=(0.5, 0, 0))
    assert (m.blocks["leader"] == np.arange(2)).all()


def test_dip_direction_convention():
    # dip 90, dip-direction 90: the plane's normal is +x, so the cut is at x = 0.3
    m = cube(size=1.0)
    cut_joint_set(m, D(90), D(90), origin=(0.3, 0.0, 0.0))
    np.testing.assert_allclose(sorted(m.blocks["volume"]), [0.3, 0.7], rtol=1e-14)
    # dip 45, dip-direction 0: normal (0, √½, √½), dipping towards +y
    m = cube(size=1.0)
    cut_joint_set(m, D(45), D(0), origin=(0.0, 0.0, 1.0))
    np.testing.assert_allclose(sorted(m.blocks["volume"]), [0.5, 0.5], rtol=1e-14)
    low = np.argmin(m.blocks["centroid"][:, 1] + m.blocks["centroid"][:, 2])
    assert m.blocks["centroid"][low, 2] < 0.5
