"""The kernels that decide what a detection keeps (``kernels.kept``) against plain numpy twins
written from their definitions, on random data with the edge cases planted."""
import numpy as np
import pytest

from dec3d.kernels.kept import add_turns, as_they_are, pairs_to_look_at, take_defaults


def _blocks(rng, nb=40):
    count = rng.integers(4, 12, nb)
    start = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.int64)
    return start, count.astype(np.int64), int(count.sum())


def test_add_turns_is_the_largest_vertex_motion_besides_the_centroid():
    rng = np.random.default_rng(3)
    start, count, nv = _blocks(rng)
    nb = len(start)
    vblock = np.repeat(np.arange(nb), count)
    tpos = rng.normal(size=(nv, 3))
    tcen = rng.normal(size=(nb, 3))
    cen = tcen + rng.normal(scale=0.1, size=(nb, 3))
    vpos = tpos + (cen - tcen)[vblock] + rng.normal(scale=1e-3, size=(nv, 3))
    vpos[vblock == 5] = tpos[vblock == 5] + (cen - tcen)[5]        # a block that only translated
    turn0 = rng.uniform(0, 1e-2, nb)
    # twin: per vertex, then the largest per block
    d = np.linalg.norm((vpos - tpos) - (cen - tcen)[vblock], axis=1)
    want = turn0 + np.array([d[vblock == b].max() for b in range(nb)])
    turn, tp, tc = turn0.copy(), tpos.copy(), tcen.copy()
    add_turns(turn, tp, tc, vpos, cen, start, count)
    assert np.allclose(turn, want, rtol=1e-13, atol=1e-18)
    assert turn[5] == pytest.approx(turn0[5], abs=1e-15)
    assert np.array_equal(tp, vpos) and np.array_equal(tc, cen)          # the references move on


def test_pairs_to_look_at_follow_moved_blocks_or_the_relative_rule():
    rng = np.random.default_rng(7)
    nb, ncand, nold = 30, 200, 120
    ra = rng.integers(0, nb, ncand)
    rb = rng.integers(0, nb, ncand)
    prev = np.full(ncand, -1, np.int64)
    prev[rng.choice(ncand, nold, replace=False)] = np.arange(nold)
    moved = rng.random(nb) < 0.3
    relative = rng.random(nb) < 0.7
    cen = rng.normal(size=(nb, 3))
    ref_ca = rng.normal(scale=0.01, size=(nold, 3))
    ref_cb = rng.normal(scale=0.01, size=(nold, 3))
    turn = rng.uniform(0, 0.01, nb)
    ref_ta = rng.uniform(0, 0.01, nold)
    ref_tb = rng.uniform(0, 0.01, nold)
    lim = 0.02
    # a pair exactly on the limit is looked at (drift < lim keeps it)
    i = int(np.flatnonzero(prev >= 0)[0])
    ra[i], rb[i] = 0, 1
    relative[[0, 1]] = True
    p = prev[i]
    cen[1] = cen[0] + ref_cb[p] - ref_ca[p] + [lim / 2, 0.0, 0.0]
    turn[[0, 1]] = ref_ta[p] + lim / 4, ref_tb[p] + lim / 4
    want = np.empty(ncand, bool)
    for j in range(ncand):
        a, b, q = ra[j], rb[j], prev[j]
        if q >= 0 and relative[a] and relative[b]:
            drift = (np.linalg.norm((cen[b] - ref_cb[q]) - (cen[a] - ref_ca[q]))
                     + (turn[a] - ref_ta[q]) + (turn[b] - ref_tb[q]))
            want[j] = drift >= lim
        else:
            want[j] = moved[a] or moved[b]
    look = np.zeros(ncand, bool)
    k = pairs_to_look_at(ra, rb, prev, moved, relative, cen, ref_ca, ref_cb, turn, ref_ta, ref_tb, lim, look)
    assert np.array_equal(look, want) and k == want.sum()
    assert look[i]
    assert 0 < k < ncand


def test_as_they_are_needs_every_contact_in_its_row_and_the_subcontacts_in_order():
    ra = np.array([0, 0, 1, 2, 3], np.int64)
    rb = np.array([1, 2, 2, 3, 4], np.int64)
    prev = np.array([0, -1, 1, 2, -1], np.int64)       # pairs 1 and 4 are new candidates
    ca, cb = np.array([0, 1, 2], np.int64), np.array([1, 2, 3], np.int64)
    count = np.array([2, 0, 3], np.int64)
    start = np.array([0, 2, 2], np.int64)
    assert as_they_are(prev, ra, rb, ca, cb, start, count, 5)
    assert not as_they_are(prev, ra, rb, ca, cb, start, count, 6)             # a sub-contact row more
    assert not as_they_are(prev, ra, rb, ca, cb, np.array([0, 2, 3]), count, 5)    # out of order
    assert not as_they_are(np.array([0, -1, 2, 1, -1]), ra, rb, ca, cb, start, count, 5)  # rows swapped
    assert not as_they_are(np.array([0, -1, 1, -1, -1]), ra, rb, ca, cb, start, count, 5)  # a contact lost
    assert not as_they_are(prev, ra, np.array([1, 2, 2, 4, 4]), ca, cb, start, count, 5)  # on another block


def test_take_defaults_writes_the_rows_that_differ_and_counts_them():
    table = np.array([[np.nan, 0.0, 0.0], [1e9, 2e9, np.nan], [3.0, 4.0, 5.0]])
    jmodel = np.array([1, 2, 1, 2, 1], np.int64)
    own = np.array([0, 0, 1, 0, 0], np.uint8)
    prop = np.array([[1e9, 2e9, np.nan],          # equal, NaN included: unchanged
                     [3.0, 4.0, 6.0],              # one column differs
                     [7.0, 7.0, 7.0],              # owns its properties: left alone
                     [3.0, 4.0, 5.0],
                     [1e9, 1e9, 1.0]])
    want = prop.copy()
    for c in range(len(own)):
        if own[c] == 0:
            want[c] = table[jmodel[c]]
    assert take_defaults(own, jmodel, prop, table) == 2
    assert np.array_equal(prop, want, equal_nan=True)
    assert take_defaults(own, jmodel, prop, table) == 0
