"""``kernels.bodyscale.body_row_sums`` against its dense twin (tests/reference/bodyscale_ref.py) on
random bodies, contacts and fixities. (Also run with NUMBA_DISABLE_JIT=1 by tests/test_kernel_cache.py.)"""
import numpy as np
import pytest

from dec3d.kernels.bodyscale import body_row_sums
from reference.bodyscale_ref import row_sums_ref


def _kernel(*args):
    ng = len(args[1])
    rt, rr = np.zeros(ng), np.zeros(ng)
    body_row_sums(*args, rt, rr)
    return rt, rr


def _random_case(rng, ng=6, nblock_extra=2):
    """ng lone bodies (blocks 0..ng-1) and a few blocks that are no body (gid −1); one contact per
    pair of blocks (some pairs with a held block, one inside a body: skipped), 1-4 sub-contacts each."""
    nb = ng + nblock_extra
    gid = np.concatenate((np.arange(ng), -np.ones(nblock_extra, np.int64))).astype(np.int64)
    gcen = rng.normal(size=(ng, 3))
    rho = rng.uniform(0.2, 2.0, ng)
    held = rng.choice([0, 0, 0, 7, 56, 5, 63], ng).astype(np.int64)
    pairs = [(a, b) for a in range(nb) for b in range(a + 1, nb) if rng.random() < 0.5]
    pairs.append((0, 0))                         # a contact inside one body: no spring between bodies
    ca = np.array([p[0] for p in pairs], np.int64)
    cb = np.array([p[1] for p in pairs], np.int64)
    cn = rng.normal(size=(len(pairs), 3))
    cn /= np.linalg.norm(cn, axis=1)[:, None]
    kn = rng.uniform(1e7, 1e9, len(pairs))
    ks = rng.uniform(1e6, 1e9, len(pairs))
    sc = np.concatenate([np.full(rng.integers(1, 5), c) for c in range(len(pairs))]).astype(np.int64)
    pos = rng.normal(size=(len(sc), 3))
    area = rng.uniform(0.01, 1.0, len(sc))
    return gid, gcen, rho, held, ca, cb, cn, kn, ks, sc, pos, area


@pytest.mark.parametrize("seed", range(6))
def test_row_sums_match_dense_twin(seed):
    args = _random_case(np.random.default_rng(seed))
    rt, rr = _kernel(*args)
    rt0, rr0 = row_sums_ref(*args)
    assert rt0.max() > 0 and rr0.max() > 0
    np.testing.assert_allclose(rt, rt0, rtol=1e-12, atol=0)
    np.testing.assert_allclose(rr, rr0, rtol=1e-12, atol=0)


def test_row_sums_of_a_body_without_contacts_or_fully_held_are_zero():
    args = list(_random_case(np.random.default_rng(7)))
    args[3] = np.full(len(args[1]), 63, np.int64)            # every degree of freedom held
    rt, rr = _kernel(*args)
    assert np.all(rt == 0) and np.all(rr == 0)
