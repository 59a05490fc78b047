"""What a detection keeps: the tests that decide, pair by pair, whether a contact stays as it is
(``physics.contacts.ContactDetection.detect``).

On a large quiet model nearly every detection keeps every contact, and then these tests are all
a detection costs: as numpy expressions (gathers, a norm, copies and comparisons of the property
rows) they took about 17 ms a detection on the 20-layer cube stack (94 000 contacts), 1 ms a
step, as much as an eighth of the step; here each is one pass over its rows, without scratch.
"""
from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def add_turns(turn, tpos, tcen, vpos, cen, bvstart, bvcount) -> None:
    """Accumulated turn of each block [m], in place: ``turn[b]`` grows by the largest displacement
    of a vertex of block b besides its centroid since the references (vertex positions ``tpos``,
    centroids ``tcen``): |(R − I) r| of the rotation R since then, plus any deformation. Summed
    over detections it bounds how far the rotation since any earlier one has moved the vertices
    (R₂R₁ − I = (R₂ − I)R₁ + (R₁ − I)). Then the references become the present positions.
    bvstart, bvcount (nb,): each block's vertex rows (contiguous)."""
    for b in range(bvstart.shape[0]):
        c0 = cen[b, 0] - tcen[b, 0]
        c1 = cen[b, 1] - tcen[b, 1]
        c2 = cen[b, 2] - tcen[b, 2]
        most = 0.0
        for v in range(bvstart[b], bvstart[b] + bvcount[b]):
            d0 = (vpos[v, 0] - tpos[v, 0]) - c0
            d1 = (vpos[v, 1] - tpos[v, 1]) - c1
            d2 = (vpos[v, 2] - tpos[v, 2]) - c2
            d = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if d > most:
                most = d
            for k in range(3):
                tpos[v, k] = vpos[v, k]
        turn[b] += most
        for k in range(3):
            tcen[b, k] = cen[b, k]


@njit(cache=True)
def pairs_to_look_at(ra, rb, prev, moved, relative, cen, ref_ca, ref_cb, turn, ref_ta, ref_tb, lim, look):
    """Which candidate pairs (block rows ra, rb; old contact row prev, −1 none) a detection looks
    at again, in look (bool, in place); returns how many. A pair is looked at when one of its
    blocks moved (``moved``, per block) — except a pair with an old contact between two blocks
    that follow the relative rule (``relative``, per block; ``contacts.RELATIVE``): it is looked
    at only when |Δc_B − Δc_A| + Δturn_A + Δturn_B ≥ lim [m], the displacements of its
    centroids and the growth of its turns since the contact was computed (``ref_*``)."""
    k = 0
    for i in range(ra.shape[0]):
        a = ra[i]
        b = rb[i]
        p = prev[i]
        if p >= 0 and relative[a] and relative[b]:
            x0 = (cen[b, 0] - ref_cb[p, 0]) - (cen[a, 0] - ref_ca[p, 0])
            x1 = (cen[b, 1] - ref_cb[p, 1]) - (cen[a, 1] - ref_ca[p, 1])
            x2 = (cen[b, 2] - ref_cb[p, 2]) - (cen[a, 2] - ref_ca[p, 2])
            drift = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2) + (turn[a] - ref_ta[p]) + (turn[b] - ref_tb[p])
            hit = not (drift < lim)
        else:
            hit = moved[a] or moved[b]
        look[i] = hit
        if hit:
            k += 1
    return k


@njit(cache=True)
def as_they_are(prev, ra, rb, ca, cb, sub_start, sub_count, nsub) -> bool:
    """Whether the candidate pairs (ra, rb) with old contact rows prev (−1: none) hold every old
    contact (rows ca, cb of its blocks), in its own row and order, with the sub-contacts
    (nsub rows) laid out in contact order (sub_start the running sum of sub_count)."""
    nc = ca.shape[0]
    want = 0
    for i in range(prev.shape[0]):
        p = prev[i]
        if p < 0:
            continue
        if p != want or ra[i] != ca[p] or rb[i] != cb[p]:
            return False
        want += 1
    if want != nc:
        return False
    total = 0
    for c in range(nc):
        if sub_start[c] != total:
            return False
        total += sub_count[c]
    return total == nsub


@njit(cache=True)
def take_defaults(own, jmodel, prop, table):
    """Contacts that follow the defaults (``own`` 0) take the default row of their joint model,
    ``table[jmodel]``, in place; returns how many rows changed (NaN equals NaN)."""
    changed = 0
    for c in range(own.shape[0]):
        if own[c] != 0:
            continue
        row = table[jmodel[c]]
        same = True
        for j in range(row.shape[0]):
            x = prop[c, j]
            y = row[j]
            if x != y and not (x != x and y != y):
                same = False
                prop[c, j] = y
        if not same:
            changed += 1
    return changed
