"""Fixed-order gathers for the threaded steps of the zone and FE-block kernels.

A serial step scatters each element's nodal forces into ``force`` element by element, so the
sum at a node is taken in the order of the element rows. The threaded steps keep that order
(bit for bit the same result for any thread count): the element pass writes each element's
forces into its own scratch rows, then a pass over nodes adds, for each node, the entries of
the elements that touch it in ascending entry order. ``node_lists`` makes those per-node entry
lists once per mesh; ``node_sums`` does the gather.
"""
import numpy as np
from numba import njit, prange


@njit(cache=True)
def node_lists(ntarget, target, conn, rows, nper):
    """Per target t, the (element entry, local node) pairs that add to it, in a fixed order
    (CSR): the entries of t are nent[nstart[t]:nstart[t + 1]], each nper k + a (local node a of
    element rows[k], a < nper), ascending: the order of the serial scatter. ``target`` maps a
    node row conn[e, a] to its target: the row itself (nodal forces) or e.g. an averaging node.
    Returns (nstart (ntarget + 1,), nent (nper len(rows),)) int64."""
    m = rows.shape[0]
    nstart = np.zeros(ntarget + 1, dtype=np.int64)
    for k in range(m):
        for a in range(nper):
            nstart[target[conn[rows[k], a]] + 1] += 1
    for t in range(ntarget):
        nstart[t + 1] += nstart[t]
    fill = nstart[:ntarget].copy()
    nent = np.empty(nper * m, dtype=np.int64)
    for k in range(m):
        for a in range(nper):
            t = target[conn[rows[k], a]]
            nent[fill[t]] = nper * k + a
            fill[t] += 1
    return nstart, nent


@njit(cache=True, parallel=True)
def node_sums(force, fe, ok, nstart, nent):
    """force[r] += the element forces fe (len(rows), nper, 3) of node r's entries
    (``node_lists``) in their fixed order, in parallel over nodes: the sums do not depend on the
    thread count and equal the serial scatter. Entries of elements with ok False are skipped."""
    nper = fe.shape[1]
    for r in prange(nstart.shape[0] - 1):
        f0 = force[r, 0]; f1 = force[r, 1]; f2 = force[r, 2]
        for q in range(nstart[r], nstart[r + 1]):
            kk = nent[q] // nper
            if ok[kk]:
                a = nent[q] - nper * kk
                f0 += fe[kk, a, 0]; f1 += fe[kk, a, 1]; f2 += fe[kk, a, 2]
        force[r, 0] = f0; force[r, 1] = f1; force[r, 2] = f2


@njit(cache=True, inline='always')
def scatter(force, nd, fe):
    """force[nd[a]] += fe[a] for the nodes of one element (the serial scatter), fe (n, 3)."""
    for a in range(nd.shape[0]):
        r = nd[a]
        force[r, 0] += fe[a, 0]
        force[r, 1] += fe[a, 1]
        force[r, 2] += fe[a, 2]
