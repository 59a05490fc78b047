"""kernels/gather.py against a plain-python twin: the per-node entry lists are the order of a
serial element-by-element scatter, and the gathered sums are that scatter bit for bit."""
import numpy as np
import pytest

from dec3d.kernels.gather import node_lists, node_sums, scatter


def scatter_twin(nv, conn, rows, fe, ok, force0):
    """The serial scatter the gather must reproduce: element by element in rows order."""
    force = force0.copy()
    for k, e in enumerate(rows):
        if not ok[k]:
            continue
        for a in range(conn.shape[1]):
            force[conn[e, a]] += fe[k, a]
    return force


@pytest.mark.parametrize("nper", [4, 10, 20])
def test_node_lists_and_sums_match_the_serial_scatter(nper):
    rng = np.random.default_rng(nper)
    nv, ne = 40, 30
    conn = np.array([rng.choice(nv, nper, replace=False) for _ in range(ne)], dtype=np.int64)
    rows = rng.permutation(ne)[:25].astype(np.int64)
    nstart, nent = node_lists(nv, np.arange(nv), conn, rows, nper)
    # the lists: every entry once, each node's entries ascending and all touching that node
    assert nstart[0] == 0 and nstart[-1] == nper * len(rows)
    assert sorted(nent.tolist()) == list(range(nper * len(rows)))
    for r in range(nv):
        ent = nent[nstart[r]:nstart[r + 1]].tolist()
        assert ent == sorted(ent)
        assert all(conn[rows[q // nper], q % nper] == r for q in ent)
    fe = rng.normal(size=(len(rows), nper, 3)) * 10.0 ** rng.integers(-3, 4, size=(len(rows), nper, 1))
    ok = rng.random(len(rows)) > 0.2
    force0 = rng.normal(size=(nv, 3))
    want = scatter_twin(nv, conn, rows, fe, ok, force0)
    got = force0.copy()
    node_sums(got, fe, ok, nstart, nent)
    assert np.array_equal(got, want)
    # the serial scatter, element by element
    got = force0.copy()
    for k, e in enumerate(rows):
        if ok[k]:
            scatter(got, conn[e], fe[k])
    assert np.array_equal(got, want)


def test_node_lists_with_a_target_map_groups_nodes():
    """A target map sends several nodes to one target: its list holds all their entries, ascending."""
    conn = np.array([[0, 1, 2, 3], [2, 3, 4, 5]], dtype=np.int64)
    target = np.array([0, 0, 1, 1, 2, 2], dtype=np.int64)
    nstart, nent = node_lists(3, target, conn, np.array([1, 0], dtype=np.int64), 4)
    assert nstart.tolist() == [0, 2, 6, 8]
    # rows order (1, 0): entries 0-3 are element 1, 4-7 element 0
    assert nent.tolist() == [4, 5, 0, 1, 6, 7, 2, 3]
