"""Transitional stand-ins while the cellmap and subgeom kernels land (to be deleted)."""
import numpy as np

from .subcontacts import make_subcontacts


def cell_grid(lo, hi, active, margin):
    return (np.zeros(3), 1.0, np.ones(3, np.int64))


def outside_grid(lo, hi, active, origin, size, ncell):
    return False


def cell_pairs(lo, hi, active, origin, size, ncell):
    n = len(lo)
    out = []
    idx = np.flatnonzero(active)
    order = idx[np.argsort(lo[idx, 0], kind="stable")]
    for k, i in enumerate(order):
        for j in order[k + 1:]:
            if lo[j, 0] > hi[i, 0]:
                break
            if (lo[i] <= hi[j]).all() and (lo[j] <= hi[i]).all():
                out.append((min(i, j), max(i, j)))
    return np.array(sorted(out), np.int64).reshape(-1, 2)


def subcontacts_batch(vpos, bvs, bvc, bfs, bfc, fvs, fnv, fv, ca, cb, cn, cc, ctol, parea,
                      oc, ok, ok0, ok1, op, oa):
    rows = []
    for c in range(len(ca)):
        va = vpos[bvs[ca[c]]:bvs[ca[c]] + bvc[ca[c]]]
        vb = vpos[bvs[cb[c]]:bvs[cb[c]] + bvc[cb[c]]]
        pts, areas = make_subcontacts(va, vb, cn[c], cc[c], ctol, parea)
        for t in range(len(pts)):
            rows.append((c, 3, t, -1, pts[t], areas[t]))
    if len(rows) <= len(oc):
        for i, r in enumerate(rows):
            oc[i], ok[i], ok0[i], ok1[i], op[i], oa[i] = r
    return len(rows)
