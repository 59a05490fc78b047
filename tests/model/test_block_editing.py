"""Deleting, hiding, density, joining and ids of blocks."""
import numpy as np
import pytest

from dec3d.geometry.polyhedron import brick
from dec3d.model.blocks import (add_blocks, delete_blocks, group_blocks, hide_blocks, join_blocks,
                                joined_groups, set_density, summary)
from dec3d.model.model import Model


def row_of_bricks(n=5):
    m = Model()
    add_blocks(m, [brick(i, i + 1, 0, 1, 0, 1) for i in range(n)])
    return m


def test_ids_are_stable_and_geometry_stays_consistent_after_delete():
    m = row_of_bricks()
    assert delete_blocks(m, np.array([False, True, False, True, False])) == 2
    b = m.blocks
    assert list(b["id"]) == [1, 3, 5]
    assert m.vertices.n == 24 and m.faces.n == 18 and m.face_vertices.n == 72
    np.testing.assert_allclose(b["centroid"][:, 0], [0.5, 2.5, 4.5])
    for r in range(b.n):
        v = slice(b["vert_start"][r], b["vert_start"][r] + b["vert_count"][r])
        assert (m.vertices["block"][v] == r).all()
        np.testing.assert_allclose(m.vertices["pos"][v].mean(axis=0), b["centroid"][r])
        f = slice(b["face_start"][r], b["face_start"][r] + b["face_count"][r])
        assert (m.faces["block"][f] == r).all()
    assert list(m.block_rows([5, 2, 1])) == [2, -1, 0]
    add_blocks(m, [brick(0, 1, 2, 3, 0, 1)])
    assert b["id"][-1] == 6                     # ids are never reused


def test_density_sets_mass_and_inertia():
    m = row_of_bricks(2)
    set_density(m, np.array([True, False]), 2000.0)
    np.testing.assert_allclose(m.blocks["mass"], [2000.0, 0.0], rtol=1e-14)
    assert m.blocks["inertia"][0, 0, 0] == pytest.approx(2000.0 * 2 / 12)


def test_hide_and_group():
    m = row_of_bricks(3)
    hide_blocks(m, np.array([True, False, True]))
    assert m.blocks["hidden"].tolist() == [True, False, True]
    hide_blocks(m, np.ones(3, bool), on=False)
    assert not m.blocks["hidden"].any()
    group_blocks(m, np.array([True, True, False]), "wall", slot="kind")
    group_blocks(m, np.array([True, False, False]), "wall", slot="kind", remove=True)
    col = m.groups.slot_index(m.blocks, "kind")
    assert m.blocks["group"][:, col].tolist() == [-1, 0, -1]


def test_join_on_off_and_leader_reelection_on_delete():
    m = row_of_bricks(5)
    join_blocks(m, np.array([False, True, True, False, False]))
    join_blocks(m, np.array([False, False, True, True, False]))   # merges with the group of row 2
    assert m.blocks["leader"].tolist() == [0, 1, 1, 1, 4]
    assert [g.tolist() for g in joined_groups(m)] == [[1, 2, 3]]
    assert summary(m)["joined"] == 3
    delete_blocks(m, np.array([False, True, False, False, False]))  # the leader goes
    assert m.blocks["leader"].tolist() == [0, 1, 1, 3]
    join_blocks(m, np.array([False, True, False, False]), on=False)  # release the new leader
    assert m.blocks["leader"].tolist() == [0, 1, 2, 3]


def test_summary():
    m = row_of_bricks(2)
    s = summary(m)
    assert s["blocks"] == 2 and s["volume"] == pytest.approx(2.0)
    assert s["extent"] == ([0.0, 0.0, 0.0], [2.0, 1.0, 1.0])
