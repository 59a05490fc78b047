"""Slow, obviously-correct twins of the contact bookkeeping and cycle kernels
(``kernels.contactmap``, ``kernels.cycle``)."""
import numpy as np


def match_sorted(old0, old1, new0, new1):
    where = {(int(a), int(b)): i for i, (a, b) in enumerate(zip(old0, old1))}
    return np.array([where.get((int(a), int(b)), -1) for a, b in zip(new0, new1)], np.int64)


def envelopes(vpos, bvstart, bvcount, active, pad):
    n = len(bvstart)
    lo = np.zeros((n, 3))
    hi = np.zeros((n, 3))
    for b in range(n):
        if active[b]:
            v = vpos[bvstart[b]:bvstart[b] + bvcount[b]]
            lo[b], hi[b] = v.min(0) - pad, v.max(0) + pad
    return lo, hi


def _turn(f, n_old, n_new):
    """Eq. (23): F − F × (n_old × n_new)."""
    return f - np.cross(f, np.cross(n_old, n_new))


NEW = 8   # the state bit of a sub-contact whose uⁿ is a freshly measured gap


def carry_over(cprev, sc_contact, kind, key0, key1, area, sgap, old_start, old_count, old_kind, old_key0,
               old_key1, old_area, old_fs, old_un, old_udil, old_us, old_state, old_hist, old_n, new_n):
    ns = len(sc_contact)
    hist = np.zeros((ns, old_hist.shape[1]))
    fs, us = np.zeros((ns, 3)), np.zeros((ns, 3))
    un, udil, state = np.zeros(ns), np.zeros(ns), np.zeros(ns, np.int64)
    for s in range(ns):
        c = sc_contact[s]
        p = cprev[c]
        un[s] = sgap[s]          # no twin: its own gap, first increment already in it
        state[s] = NEW
        if p < 0:
            continue
        olds = list(range(old_start[p], old_start[p] + old_count[p]))
        twins = [o for o in olds if old_kind[o] == kind[s] and old_key0[o] == key0[s]
                 and (kind[s] < 2 or old_key1[o] == key1[s])]
        if twins:
            o = twins[0]
            ratio = area[s] / old_area[o] if old_area[o] > 0 else 1.0
            fs[s] = _turn(old_fs[o], old_n[p], new_n[c]) * ratio
            us[s], un[s], udil[s], state[s] = old_us[o], old_un[o], old_udil[o], old_state[o]
            hist[s] = old_hist[o]      # the joint model's history goes with its sub-contact
            continue
        atot = sum(old_area[o] for o in olds)
        if atot <= 0:
            continue
        fs[s] = _turn(sum(old_fs[o] for o in olds), old_n[p], new_n[c]) / atot * area[s]
        udil[s] = sum(old_udil[o] * old_area[o] for o in olds) / atot
        state[s] = int(np.bitwise_or.reduce([old_state[o] & 1 for o in olds])) | NEW
        # a sub-contact new on an old contact: the area-weighted mean history of the contact's old ones
        hist[s] = sum(old_hist[o] * old_area[o] for o in olds) / atot
    return fs, un, udil, us, state, hist


def move_points(dt, ca, cb, owner, pts, centroid, vel, spin):
    """Eq. (11): each point moves by the mean displacement of its two blocks at that point."""
    out = pts.copy()
    for i, c in enumerate(owner):
        d = np.zeros(3)
        for blk in (ca[c], cb[c]):
            arm = pts[i] - (centroid[blk] - vel[blk] * dt)
            d += vel[blk] * dt + np.cross(spin[blk] * dt, arm)
        out[i] = pts[i] + 0.5 * d
    return out
