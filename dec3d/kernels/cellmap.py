"""Cell mapping and searching: candidate neighbour pairs of blocks in O(n).

3DEC theory, "Identification of Neighbors / Cell Mapping and Searching": space is divided
into rectangular cells of the order of one block; every block is mapped into all cells
its envelope (axis-aligned box, already enlarged by the search tolerance by the caller)
overlaps, and its neighbours are the other blocks found in those cells.

Layout: the grid is ``origin`` (3,) m, a cubic cell edge ``size`` m and ``ncell`` (3,)
int64 cells per axis; cell (ix, iy, iz) is ``[origin + (ix, iy, iz)·size, ... + size]``
and has the linear index ``(ix·ny + iy)·nz + iz``. Envelopes partly outside the grid are
clamped to it (every point outside maps to the nearest boundary cell), so the pairs stay
complete; the engine regrows the grid (``cell_grid`` with a 10 % margin) when
``outside_grid`` says an active envelope has left it, to keep the cells balanced.

Blocks are mapped in CSR form (count pass, prefix sum, fill pass). A pair is reported
only from the one cell that contains the componentwise maximum of the two lower corners
(clamped to the grid): that point lies in both boxes when they overlap, so the cell is
shared by both and every pair comes out exactly once without a hash set.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _cell_coord(x, o, size, n):
    """Cell index along one axis of coordinate x [m], clamped to 0 .. n-1 (NaN -> 0)."""
    t = (x - o) / size
    if not (t >= 0.0):
        return 0
    if t >= n:
        return n - 1
    k = int(t)
    if k > n - 1:
        k = n - 1
    return k


@njit(cache=True)
def cell_grid(lo, hi, active, margin):
    """Cell grid for the active envelopes.

    lo, hi (n, 3) float64 envelope corners [m]; active (n,) bool; margin: fraction of the
    extent of all active envelopes (per axis) added on each side, e.g. 0.1 = 10 %.

    Returns origin (3,) float64 [m], size float [m] (> 0, cubic cells), ncell (3,) int64.
    The cell size is the cube root of the mean envelope volume of the active blocks (for
    flat or degenerate envelopes: the mean longest edge, else the model extent, else 1 m),
    enlarged if needed so that the grid has at most 8·(active blocks) + 64 cells.
    Without active blocks: origin 0, size 1, one cell.
    """
    n = lo.shape[0]
    gmin = np.full(3, np.inf)
    gmax = np.full(3, -np.inf)
    nact = 0
    vsum = 0.0
    esum = 0.0
    for b in range(n):
        if not active[b]:
            continue
        nact += 1
        v = 1.0
        emax = 0.0
        for d in range(3):
            e = hi[b, d] - lo[b, d]
            if e < 0.0:
                e = 0.0
            v *= e
            if e > emax:
                emax = e
            if lo[b, d] < gmin[d]:
                gmin[d] = lo[b, d]
            if hi[b, d] > gmax[d]:
                gmax[d] = hi[b, d]
        vsum += v
        esum += emax
    origin = np.zeros(3)
    ncell = np.ones(3, dtype=np.int64)
    if nact == 0:
        return origin, 1.0, ncell
    ext = np.empty(3)
    for d in range(3):
        ext[d] = max(gmax[d] - gmin[d], 0.0)
    size = (vsum / nact) ** (1.0 / 3.0)
    if not (size > 0.0) or not math.isfinite(size):
        size = esum / nact
    if not (size > 0.0) or not math.isfinite(size):
        size = max(ext[0], max(ext[1], ext[2]))
    if not (size > 0.0) or not math.isfinite(size):
        size = 1.0
    length = np.empty(3)
    for d in range(3):
        pad = margin * max(ext[d], size)
        if pad < 0.0:
            pad = 0.0
        origin[d] = gmin[d] - pad
        length[d] = ext[d] + 2.0 * pad
    cap = 8.0 * nact + 64.0
    while True:
        total = 1.0
        for d in range(3):
            total *= max(1.0, math.ceil(length[d] / size))
        if total <= cap:
            break
        f = (total / cap) ** (1.0 / 3.0)
        size *= max(f, 1.02)
    for d in range(3):
        ncell[d] = max(1, int(math.ceil(length[d] / size)))
    return origin, size, ncell


@njit(cache=True)
def outside_grid(lo, hi, active, origin, size, ncell):
    """True if an active envelope is not entirely inside the grid.

    lo, hi (n, 3) float64 [m]; active (n,) bool; origin (3,) [m]; size [m]; ncell (3,) int64.
    """
    for b in range(lo.shape[0]):
        if not active[b]:
            continue
        for d in range(3):
            if not (lo[b, d] >= origin[d]) or not (hi[b, d] <= origin[d] + ncell[d] * size):
                return True
    return False


@njit(cache=True)
def cell_pairs(lo, hi, active, origin, size, ncell):
    """Candidate neighbour pairs: every pair of active blocks whose closed envelopes overlap.

    lo, hi (n, 3) float64 envelope corners [m] (enlarged by the search tolerance by the
    caller); active (n,) bool; origin (3,) float64 [m], size float [m], ncell (3,) int64:
    the grid from ``cell_grid``.

    Returns pairs (k, 2) int64 with pairs[:, 0] < pairs[:, 1], each overlapping pair
    (lo_i <= hi_j and lo_j <= hi_i on x, y and z) exactly once, sorted lexicographically.
    """
    n = lo.shape[0]
    nx, ny, nz = ncell[0], ncell[1], ncell[2]
    ntot = nx * ny * nz
    # cell ranges of every active block
    rng = np.zeros((n, 6), dtype=np.int64)
    count = np.zeros(ntot + 1, dtype=np.int64)
    for b in range(n):
        if not active[b]:
            continue
        for d in range(3):
            rng[b, d] = _cell_coord(lo[b, d], origin[d], size, ncell[d])
            rng[b, 3 + d] = _cell_coord(hi[b, d], origin[d], size, ncell[d])
            if rng[b, 3 + d] < rng[b, d]:      # inverted box (hi < lo): map its lower corner
                rng[b, 3 + d] = rng[b, d]
        for ix in range(rng[b, 0], rng[b, 3] + 1):
            for iy in range(rng[b, 1], rng[b, 4] + 1):
                base = (ix * ny + iy) * nz
                for iz in range(rng[b, 2], rng[b, 5] + 1):
                    count[base + iz + 1] += 1
    # CSR: blocks of cell c are ent[start[c] : start[c + 1]], ascending block order
    for c in range(ntot):
        count[c + 1] += count[c]
    ent = np.empty(count[ntot], dtype=np.int64)
    fill = np.empty(ntot, dtype=np.int64)
    for c in range(ntot):
        fill[c] = count[c]
    for b in range(n):
        if not active[b]:
            continue
        for ix in range(rng[b, 0], rng[b, 3] + 1):
            for iy in range(rng[b, 1], rng[b, 4] + 1):
                base = (ix * ny + iy) * nz
                for iz in range(rng[b, 2], rng[b, 5] + 1):
                    c = base + iz
                    ent[fill[c]] = b
                    fill[c] += 1
    cap = 8 * n + 16
    out = np.empty((cap, 2), dtype=np.int64)
    k = 0
    buf = np.empty(64, dtype=np.int64)
    for i in range(n):
        if not active[i]:
            continue
        m = 0
        for ix in range(rng[i, 0], rng[i, 3] + 1):
            for iy in range(rng[i, 1], rng[i, 4] + 1):
                base = (ix * ny + iy) * nz
                for iz in range(rng[i, 2], rng[i, 5] + 1):
                    c = base + iz
                    s1 = count[c + 1]
                    s = s1
                    # entries are ascending: binary search the first j > i
                    a = count[c]
                    while a < s:
                        h = (a + s) >> 1
                        if ent[h] <= i:
                            a = h + 1
                        else:
                            s = h
                    for e in range(a, s1):
                        j = ent[e]
                        ok = True
                        for d in range(3):
                            if lo[i, d] > hi[j, d] or lo[j, d] > hi[i, d]:
                                ok = False
                                break
                        if not ok:
                            continue
                        # report only from the cell of max(lo_i, lo_j)
                        px = _cell_coord(max(lo[i, 0], lo[j, 0]), origin[0], size, nx)
                        if px != ix:
                            continue
                        py = _cell_coord(max(lo[i, 1], lo[j, 1]), origin[1], size, ny)
                        if py != iy:
                            continue
                        pz = _cell_coord(max(lo[i, 2], lo[j, 2]), origin[2], size, nz)
                        if pz != iz:
                            continue
                        if m == buf.shape[0]:
                            nb = np.empty(2 * m, dtype=np.int64)
                            for e2 in range(m):
                                nb[e2] = buf[e2]
                            buf = nb
                        buf[m] = j
                        m += 1
        # sort this block's partners (Shell sort, gaps 1, 4, 13, ...: usually a few dozen;
        # np.sort would add seconds of compilation for this), then append
        gap = 1
        while gap < m // 3:
            gap = 3 * gap + 1
        while gap > 0:
            for p in range(gap, m):
                v = buf[p]
                q = p
                while q >= gap and buf[q - gap] > v:
                    buf[q] = buf[q - gap]
                    q -= gap
                buf[q] = v
            gap //= 3
        if k + m > cap:
            ncap = max(2 * cap, k + m)
            no = np.empty((ncap, 2), dtype=np.int64)
            for r in range(k):
                no[r, 0] = out[r, 0]
                no[r, 1] = out[r, 1]
            out = no
            cap = ncap
        for p in range(m):
            out[k, 0] = i
            out[k, 1] = buf[p]
            k += 1
    res = np.empty((k, 2), dtype=np.int64)     # element loops, not slice copies: those
    for r in range(k):                         # compile seconds of shape checks
        res[r, 0] = out[r, 0]
        res[r, 1] = out[r, 1]
    return res
