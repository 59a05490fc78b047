"""Every range element against a selection made by hand on a 4 × 4 × 4 grid of unit cubes.

Block id = 1 + 16 i + 4 j + k for the cube [i, i+1] × [j, j+1] × [k, k+1].
"""
import math

import numpy as np
import pytest

from dec3d.geometry.polyhedron import brick
from dec3d.model import ranges as R
from dec3d.model.blocks import add_blocks, group_blocks
from dec3d.model.model import Model

IJK = [(i, j, k) for i in range(4) for j in range(4) for k in range(4)]


def ids_where(pred):
    return sorted(1 + 16 * i + 4 * j + k for i, j, k in IJK if pred(i, j, k))


@pytest.fixture(scope="module")
def grid():
    m = Model()
    add_blocks(m, [brick(i, i + 1, j, j + 1, k, k + 1) for i, j, k in IJK])
    k = np.array([c[2] for c in IJK])
    i = np.array([c[0] for c in IJK])
    group_blocks(m, k % 2 == 0, "even")
    group_blocks(m, k == 3, "Top", slot="layer")
    group_blocks(m, i == 0, "left", slot="side")
    return m


def selected(m, mask):
    assert mask.dtype == bool and mask.shape == (m.blocks.n,)
    return sorted(m.blocks["id"][mask].tolist())


def test_position_box(grid):
    got = selected(grid, R.mask_position(grid, "block", (2, 2, 1), (0, 0, 0)))
    assert got == [1, 5, 17, 21]


def test_position_axes(grid):
    assert selected(grid, R.mask_position_x(grid, "block", 0, 1)) == ids_where(lambda i, j, k: i == 0)
    assert selected(grid, R.mask_position_x(grid, "block", 2.5)) == ids_where(lambda i, j, k: i == 2)
    assert selected(grid, R.mask_position_y(grid, "block", 3, 1)) == ids_where(lambda i, j, k: j in (1, 2))
    assert selected(grid, R.mask_position_z(grid, "block", 3.5)) == ids_where(lambda i, j, k: k == 3)
    assert selected(grid, R.mask_position_z(grid, "block", 3.4)) == []


def test_position_on_faces_and_vertices(grid):
    faces = R.mask_position_x(grid, "face", 4.0)
    assert faces.sum() == 16
    np.testing.assert_allclose(grid.faces["normal"][faces], [[1, 0, 0]] * 16)
    assert R.mask_position_x(grid, "gridpoint", 0.0).sum() == 16 * 4


def test_plane(grid):
    above = R.mask_plane(grid, "block", "above", origin=(2, 2, 2), normal=(1, 1, 1))
    assert selected(grid, above) == ids_where(lambda i, j, k: i + j + k >= 5)
    below = R.mask_plane(grid, "block", "below", origin=(1, 0, 0), dip=math.pi / 2,
                         dip_direction=math.pi / 2)
    assert selected(grid, below) == ids_where(lambda i, j, k: i == 0)
    flat = R.mask_plane(grid, "block", "above", origin=(0, 0, 3), dip=0.0, dip_direction=0.0)
    assert selected(grid, flat) == ids_where(lambda i, j, k: k == 3)
    band = R.mask_plane(grid, "block", None, origin=(0, 0, 1.5), dip=0.0, dip_direction=0.0, distance=0.2)
    assert selected(grid, band) == ids_where(lambda i, j, k: k == 1)


def test_cylinder_and_annulus(grid):
    cyl = R.mask_cylinder(grid, "block", (2, 2, 0), (2, 2, 4), 1.0)
    assert selected(grid, cyl) == ids_where(lambda i, j, k: i in (1, 2) and j in (1, 2))
    ann = R.mask_cylinder(grid, "block", (2, 2, 0), (2, 2, 4), 1.0, 2.0)
    assert selected(grid, ann) == ids_where(
        lambda i, j, k: sorted((abs(i - 1.5), abs(j - 1.5))) == [0.5, 1.5])
    short = R.mask_cylinder(grid, "block", (2, 2, 0), (2, 2, 2), 1.0)
    assert selected(grid, short) == ids_where(lambda i, j, k: i in (1, 2) and j in (1, 2) and k < 2)


def test_sphere(grid):
    assert selected(grid, R.mask_sphere(grid, "block", (0, 0, 0), 1.0)) == [1]
    assert selected(grid, R.mask_sphere(grid, "block", (0, 0, 0), 1.7)) == [1, 2, 5, 17]


def test_group_elements(grid):
    assert selected(grid, R.mask_group(grid, "block", "even")) == ids_where(lambda i, j, k: k % 2 == 0)
    assert selected(grid, R.mask_group(grid, "block", "top", slot="LAYER")) == ids_where(lambda i, j, k: k == 3)
    assert selected(grid, R.mask_group(grid, "block", "top", slot="Default")) == []
    assert selected(grid, R.mask_group(grid, "block", ["even", "top"])) == ids_where(lambda i, j, k: k != 1)
    assert selected(grid, R.mask_group(grid, "block", "nothing")) == []
    both = R.mask_group_intersection(grid, "block", "even", "left")
    assert selected(grid, both) == ids_where(lambda i, j, k: k % 2 == 0 and i == 0)


def test_ids(grid):
    assert selected(grid, R.mask_id(grid, "block", 5)) == [5]
    assert selected(grid, R.mask_id_list(grid, "block", [64, 1, 2, 99])) == [1, 2, 64]
    with pytest.raises(KeyError):
        R.mask_id(grid, "face", 1)


def test_not_and_union(grid):
    left = R.mask_position_x(grid, "block", 0, 1)
    top = R.mask_group(grid, "block", "top")
    assert selected(grid, R.combine([(left, False), (top, False)])) == \
        ids_where(lambda i, j, k: i == 0 and k == 3)
    assert selected(grid, R.combine([(left, False), (top, True)])) == \
        ids_where(lambda i, j, k: i == 0 and k != 3)
    assert selected(grid, R.combine([(left, False), (top, False)], union=True)) == \
        ids_where(lambda i, j, k: i == 0 or k == 3)
    assert selected(grid, R.combine([(left, True)])) == ids_where(lambda i, j, k: i != 0)
    assert R.combine([], n=grid.blocks.n).all()


def test_registry_lists_every_element():
    assert set(R.RANGE_ELEMENTS) == {"position", "position-x", "position-y", "position-z", "plane",
                                     "cylinder", "sphere", "group", "group-intersection", "id", "id-list", "region"}
