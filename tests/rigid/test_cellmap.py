"""Cell mapping neighbour search against the all-pairs twin in tests/reference/cellmap_ref.py."""
import numpy as np
import pytest

from dec3d.kernels.cellmap import cell_grid, cell_pairs, outside_grid
from reference.cellmap_ref import cell_pairs_ref


def _pairs(lo, hi, active, margin=0.1):
    origin, size, ncell = cell_grid(lo, hi, active, margin)
    assert size > 0.0
    assert not outside_grid(lo, hi, active, origin, size, ncell)
    return cell_pairs(lo, hi, active, origin, size, ncell), (origin, size, ncell)


def _random_boxes(seed, n=300):
    rng = np.random.default_rng(seed)
    c = rng.uniform(0.0, 10.0, size=(n, 3))
    h = rng.uniform(0.05, 1.0, size=(n, 3)) * rng.choice([0.3, 1.0, 2.0], size=(n, 1))
    lo, hi = c - h, c + h
    lo[0], hi[0] = (2.0, 3.0, -1.0), (9.0, 8.0, 12.0)          # one huge block
    lo[1], hi[1] = (1e4, -3e4, 5e3), (1e4 + 1.0, -3e4 + 1.0, 5e3 + 1.0)   # one far away
    return lo, hi


def _cubes(n, tol=0.005):
    g = np.stack(np.meshgrid(*(np.arange(n),) * 3, indexing="ij"), -1).reshape(-1, 3).astype(float)
    return g - tol, g + 1.0 + tol


@pytest.mark.parametrize("seed", range(8))
def test_random_boxes_match_all_pairs(seed):
    lo, hi = _random_boxes(seed)
    active = np.ones(len(lo), bool)
    got, _ = _pairs(lo, hi, active)
    ref = cell_pairs_ref(lo, hi, active)
    assert len(ref) > len(lo)             # the test has something to find
    np.testing.assert_array_equal(got, ref)


def test_cube_stack_all_face_edge_and_corner_neighbours():
    n = 8
    lo, hi = _cubes(n)
    active = np.ones(len(lo), bool)
    got, _ = _pairs(lo, hi, active)
    faces, edges, corners = 3 * n * n * (n - 1), 6 * n * (n - 1) ** 2, 4 * (n - 1) ** 3
    assert len(got) == faces + edges + corners
    np.testing.assert_array_equal(got, cell_pairs_ref(lo, hi, active))


def test_touching_boxes_count_as_overlapping():
    lo = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0 + 1e-12, 0, 0]])
    hi = lo + 1.0
    got, _ = _pairs(lo, hi, np.ones(3, bool))
    np.testing.assert_array_equal(got, [[0, 1]])


@pytest.mark.parametrize("seed", range(3))
def test_inactive_blocks_are_ignored(seed):
    lo, hi = _random_boxes(seed)
    rng = np.random.default_rng(100 + seed)
    active = rng.random(len(lo)) < 0.6
    active[0] = False                       # the huge one hidden
    got, (origin, size, ncell) = _pairs(lo, hi, active)
    np.testing.assert_array_equal(got, cell_pairs_ref(lo, hi, active))
    assert not np.isin(got, np.flatnonzero(~active)).any()
    # an inactive block far outside the grid does not count as outside
    lo2, hi2 = lo.copy(), hi.copy()
    i = np.flatnonzero(~active)[0]
    lo2[i] -= 1e6
    assert not outside_grid(lo2, hi2, active, origin, size, ncell)


@pytest.mark.parametrize("seed", range(4))
def test_boxes_partly_outside_the_grid_are_clamped(seed):
    lo, hi = _random_boxes(seed)
    active = np.ones(len(lo), bool)
    # a grid built for the boxes in the middle only: many envelopes stick out of it
    mid = np.all((lo > 3.0) & (hi < 7.0), axis=1)
    origin, size, ncell = cell_grid(lo, hi, mid, 0.0)
    assert outside_grid(lo, hi, active, origin, size, ncell)
    assert not outside_grid(lo, hi, mid, origin, size, ncell)
    got = cell_pairs(lo, hi, active, origin, size, ncell)
    np.testing.assert_array_equal(got, cell_pairs_ref(lo, hi, active))
    # moving a block just out of its grid is detected
    lo2, hi2 = lo.copy(), hi.copy()
    j = np.flatnonzero(mid)[0]
    top = origin + ncell * size
    lo2[j, 2] += top[2] - hi[j, 2] + 1e-6
    hi2[j, 2] = top[2] + 1e-6
    assert outside_grid(lo2, hi2, mid, origin, size, ncell)


def test_grid_is_capped_for_a_far_away_block():
    lo, hi = _cubes(4)
    lo = np.vstack([lo, [[1e7, 1e7, 1e7]]])
    hi = np.vstack([hi, [[1e7 + 1, 1e7 + 1, 1e7 + 1]]])
    active = np.ones(len(lo), bool)
    origin, size, ncell = cell_grid(lo, hi, active, 0.1)
    assert np.prod(ncell) <= 8 * len(lo) + 64
    assert not outside_grid(lo, hi, active, origin, size, ncell)
    np.testing.assert_array_equal(cell_pairs(lo, hi, active, origin, size, ncell),
                                  cell_pairs_ref(lo, hi, active))


def test_grid_cell_size_is_of_the_order_of_a_block_and_never_zero():
    lo, hi = _cubes(6)
    active = np.ones(len(lo), bool)
    origin, size, ncell = cell_grid(lo, hi, active, 0.1)
    assert 0.9 < size < 1.5
    assert np.all(origin < -0.005) and np.all(origin + ncell * size > 6.005)
    flat = lo.copy()
    flat[:, 2] = 0.0
    o, s, nc = cell_grid(flat, flat.copy() + [1.0, 1.0, 0.0], active, 0.1)   # zero volume
    assert s > 0.0 and np.all(nc >= 1)
    o, s, nc = cell_grid(lo[:1], lo[:1].copy(), active[:1], 0.1)              # a point
    assert s > 0.0 and np.all(nc >= 1)
    o, s, nc = cell_grid(lo, hi, np.zeros(len(lo), bool), 0.1)                # none active
    assert s > 0.0 and np.all(nc == 1)
    assert cell_pairs(lo, hi, np.zeros(len(lo), bool), o, s, nc).shape == (0, 2)


def test_deterministic_and_sorted():
    lo, hi = _random_boxes(5, n=500)
    active = np.ones(len(lo), bool)
    a, _ = _pairs(lo, hi, active)
    b, _ = _pairs(lo.copy(), hi.copy(), active.copy())
    np.testing.assert_array_equal(a, b)
    assert a.dtype == np.int64 and a.shape[1] == 2
    assert np.all(a[:, 0] < a[:, 1])
    key = a[:, 0] * len(lo) + a[:, 1]
    assert np.all(np.diff(key) > 0)


def test_empty_model():
    lo = np.zeros((0, 3))
    active = np.zeros(0, bool)
    o, s, nc = cell_grid(lo, lo, active, 0.1)
    assert cell_pairs(lo, lo, active, o, s, nc).shape == (0, 2)
