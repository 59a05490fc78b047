"""``kernels.bodyscale.body_row_sums`` against its twin (tests/reference/bodyscale_ref.py, spring by
spring) on random bodies — joined ones of several blocks, blocks of no body, held degrees of
freedom, contacts of several sub-contacts — far from the origin too, and its parallel twin bit for
bit on one and two threads. (Also run with NUMBA_DISABLE_JIT=1 by tests/test_kernel_cache.py.)"""
import numba
import numpy as np
import pytest

from dec3d.kernels import bodyscale
from dec3d.kernels.bodyscale import body_row_sums, body_row_sums_parallel
from reference.bodyscale_ref import row_sums_assembled, row_sums_ref


def _kernel(*args, kernel=body_row_sums):
    ng = len(args[1])
    rt, rr = np.zeros(ng), np.zeros(ng)
    kernel(*args, rt, rr)
    return rt, rr


def _random_case(rng, ng=6, extra=2, p_contact=0.5, offset=0.0, most=3):
    """ng bodies of 1-``most`` blocks each (joined) and ``extra`` blocks of no body (gid −1), block rows
    shuffled. A contact per pair of blocks with probability ``p_contact``, plus one inside a body
    (skipped by both), one between two blocks of no body and one without sub-contacts. Each
    contact has 1-6 sub-contacts within about 0.3 m of a point between its blocks' bodies;
    everything shifted by ``offset`` [m]."""
    sizes = rng.integers(1, most + 1, ng)
    gid = np.concatenate([np.full(k, g) for g, k in enumerate(sizes)] + [np.full(extra, -1)]).astype(np.int64)
    gid = gid[rng.permutation(len(gid))]
    nb = len(gid)
    gcen = rng.normal(scale=2.0, size=(ng, 3))
    rho = rng.uniform(0.2, 2.0, ng)
    held = rng.choice([0, 0, 0, 7, 56, 5, 40, 63], ng).astype(np.int64)
    pairs = [(a, b) for a in range(nb) for b in range(a + 1, nb) if rng.random() < p_contact]
    joined = [g for g in range(ng) if sizes[g] > 1]
    if joined:
        pairs.append(tuple(np.flatnonzero(gid == joined[0])[:2]))      # inside one body
    if extra >= 2:
        pairs.append(tuple(np.flatnonzero(gid < 0)[:2]))              # between two blocks of no body
    pairs.append((0, nb - 1) if gid[0] != gid[nb - 1] else (0, 1))   # (no sub-contacts: below)
    ca = np.array([p[0] for p in pairs], np.int64)
    cb = np.array([p[1] for p in pairs], np.int64)
    nc = len(pairs)
    cn = rng.normal(size=(nc, 3))
    cn /= np.linalg.norm(cn, axis=1)[:, None]
    kn = rng.uniform(1e7, 1e9, nc)
    ks = rng.uniform(1e6, 1e9, nc)
    counts = rng.integers(1, 7, nc)
    counts[-1] = 0
    sc = np.repeat(np.arange(nc), counts).astype(np.int64)
    where = np.array([0.5 * (gcen[max(gid[a], 0)] + gcen[max(gid[b], 0)]) for a, b in pairs])
    pos = where[sc] + rng.normal(scale=0.3, size=(len(sc), 3))
    area = rng.uniform(0.01, 1.0, len(sc))
    return gid, gcen + offset, rho, held, ca, cb, cn, kn, ks, sc, pos + offset, area


@pytest.mark.parametrize("seed", range(8))
def test_row_sums_match_the_twin(seed):
    args = _random_case(np.random.default_rng(seed), ng=8)
    rt, rr = _kernel(*args)
    rt0, rr0 = row_sums_ref(*args)
    assert (rt0 > 0).sum() >= 2 and (rr0 > 0).sum() >= 2
    np.testing.assert_allclose(rt, rt0, rtol=1e-12, atol=0)
    np.testing.assert_allclose(rr, rr0, rtol=1e-12, atol=0)


def test_row_sums_far_from_the_origin():
    """The same model 10 km from the origin: the kernel's moments (about each contact's first point,
    not the origin) keep the row sums to round-off of the arms (about 1e-12 here; moments about the
    origin would lose 1e-8)."""
    rng = np.random.default_rng(11)
    args = _random_case(rng, ng=8, offset=np.array([1.0e4, -7.0e3, 5.0e3]))
    rt, rr = _kernel(*args)
    rt0, rr0 = row_sums_ref(*args)
    np.testing.assert_allclose(rt, rt0, rtol=1e-10, atol=0)
    np.testing.assert_allclose(rr, rr0, rtol=1e-10, atol=0)


def test_twin_per_contact_bound_against_the_assembled_matrix():
    """The twin's (and kernel's) coupling rows per contact: equal to the assembled matrix's row sums
    when each pair of bodies shares one contact, larger (never smaller) when joined bodies share
    several (the triangle inequality), so the stability bound still holds."""
    lone = _random_case(np.random.default_rng(3), ng=7, extra=0, most=1)
    gid, ca, cb, sc = lone[0], lone[4], lone[5], lone[9]
    used = np.unique(sc)
    assert len({(gid[ca[c]], gid[cb[c]]) for c in used}) == len(used)      # no pair of bodies twice
    for got, want in zip(row_sums_ref(*lone), row_sums_assembled(*lone)):
        np.testing.assert_allclose(got, want, rtol=1e-12)
    joined = _random_case(np.random.default_rng(5), ng=4, p_contact=0.9)
    per_contact, assembled = row_sums_ref(*joined), row_sums_assembled(*joined)
    for got, low in zip(per_contact, assembled):
        assert np.all(got >= low * (1 - 1e-12))
    assert np.any(per_contact[0] > 1.01 * assembled[0]) or np.any(per_contact[1] > 1.01 * assembled[1])


def test_parallel_twin_is_bit_identical_on_one_and_two_threads():
    args = _random_case(np.random.default_rng(21), ng=100, extra=5, p_contact=0.03)
    assert len(args[4]) > 3 * bodyscale.CHUNK and len(args[1]) > bodyscale.CHUNK    # several work items
    serial = _kernel(*args)
    before = numba.get_num_threads()
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            par = _kernel(*args, kernel=body_row_sums_parallel)
            assert np.array_equal(par[0], serial[0]) and np.array_equal(par[1], serial[1])
    finally:
        numba.set_num_threads(before)
    assert serial[0].max() > 0


def test_threaded_picks_the_parallel_twin_for_large_models_only():
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        assert bodyscale.threaded(10 ** 6) is body_row_sums
        if numba.config.NUMBA_NUM_THREADS > 1:
            numba.set_num_threads(2)
            assert bodyscale.threaded(bodyscale.PARALLEL_FROM) is body_row_sums_parallel
            assert bodyscale.threaded(bodyscale.PARALLEL_FROM - 1) is body_row_sums
    finally:
        numba.set_num_threads(before)


def test_sub_contacts_out_of_contact_order_are_refused():
    args = list(_random_case(np.random.default_rng(2)))
    args[9] = args[9][::-1].copy()
    with pytest.raises(ValueError, match="grouped by contact"):
        _kernel(*args)


def test_row_sums_of_a_body_without_contacts_or_fully_held_are_zero():
    args = list(_random_case(np.random.default_rng(7)))
    args[3] = np.full(len(args[1]), 63, np.int64)            # every degree of freedom held
    rt, rr = _kernel(*args)
    assert np.all(rt == 0) and np.all(rr == 0)
    args = list(_random_case(np.random.default_rng(8)))
    args[9], args[10], args[11] = args[9][:0], args[10][:0], args[11][:0]     # no sub-contacts
    rt, rr = _kernel(*args)
    assert np.all(rt == 0) and np.all(rr == 0)
