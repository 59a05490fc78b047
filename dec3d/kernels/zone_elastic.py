"""Geometry and bookkeeping of the 4-node zone step (``kernels/zone_step.py``): the per-zone
face vectors, volume and strain increment in scalars (``_faces``, ``_strain``), the nodal force of
a face and its scatter (``_force``, ``_add``), and the plan that lets threads share the scatter
without changing a bit (``partition_entries``, ``scatter_plan``, ``node_table``, ``ElasticPlan``).

Formulas: 3DEC theory text (deformable blocks, Eqs. 53-59). Sums onto gridpoints are scattered in
ascending zone-entry order, as a serial loop does. Threads take parts of the zone entries
(``partition_entries``: by the zones' smallest gridpoint row, so a part is a compact region when
gridpoints are numbered in space), each part in ascending entry order. A target (gridpoint or
averaging node) gets the leading run of its entries that lie in one part straight from that
part's thread, in order; its other entries ("foreign" ones, near the borders between parts) are
written to slots and added after the sweep, in ascending entry order. Every target therefore gets
its terms in the serial order: the same bits for any part count and any thread count
(``scatter_plan`` makes this bookkeeping once per mesh; at 1e6 zones and two parts about 5 % of
the entries are foreign).

Why scalars (1e6 elastic zones, one thread, measured when the step had several copies; bench/README.md):
a step in passes that stores per-zone strain and face vectors between them took 221 ms, a fused
loop over per-zone scratch 339 ms, a threaded gather of 128 B of per-zone forces ~150 ms; with
every value a scalar local, the strain recomputed in a later sweep rather than stored and the
forces scattered straight to the gridpoints, ~70 ms.
"""
import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _fvec(pos, a, b, c, o):
    """Area vector of triangle (a b c), pointing away from point o (``zones._face_vector``)."""
    ux = pos[b, 0] - pos[a, 0]; uy = pos[b, 1] - pos[a, 1]; uz = pos[b, 2] - pos[a, 2]
    wx = pos[c, 0] - pos[a, 0]; wy = pos[c, 1] - pos[a, 1]; wz = pos[c, 2] - pos[a, 2]
    nx = 0.5 * (uy * wz - uz * wy)
    ny = 0.5 * (uz * wx - ux * wz)
    nz = 0.5 * (ux * wy - uy * wx)
    d = (pos[o, 0] - pos[a, 0]) * nx + (pos[o, 1] - pos[a, 1]) * ny + (pos[o, 2] - pos[a, 2]) * nz
    if d > 0.0:
        nx = -nx; ny = -ny; nz = -nz
    return nx, ny, nz


@njit(cache=True, inline="always")
def _faces(pos, i0, i1, i2, i3):
    """Outward area vectors of the faces opposite nodes 0-3 of the tetrahedron (i0 i1 i2 i3)
    and its volume, in scalars (``zones.tet_kinematics``'s formulas)."""
    a0x, a0y, a0z = _fvec(pos, i1, i2, i3, i0)
    a1x, a1y, a1z = _fvec(pos, i2, i3, i0, i1)
    a2x, a2y, a2z = _fvec(pos, i3, i0, i1, i2)
    a3x, a3y, a3z = _fvec(pos, i0, i1, i2, i3)
    p0x = pos[i0, 0]; p0y = pos[i0, 1]; p0z = pos[i0, 2]
    x1 = pos[i1, 0] - p0x; y1 = pos[i1, 1] - p0y; z1 = pos[i1, 2] - p0z
    x2 = pos[i2, 0] - p0x; y2 = pos[i2, 1] - p0y; z2 = pos[i2, 2] - p0z
    x3 = pos[i3, 0] - p0x; y3 = pos[i3, 1] - p0y; z3 = pos[i3, 2] - p0z
    vol = abs(x1 * (y2 * z3 - z2 * y3) - y1 * (x2 * z3 - z2 * x3) + z1 * (x2 * y3 - y2 * x3)) / 6.0
    return a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol


@njit(cache=True, inline="always")
def _strain(vel, i0, i1, i2, i3, a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol, dt):
    """Strain increment (xx yy zz xy xz yz) and spin increment (01 02 12) of a tetrahedron from
    its face vectors and volume (``_faces``), ``zones.tet_kinematics``'s formulas."""
    g00 = 0.0; g01 = 0.0; g02 = 0.0; g10 = 0.0; g11 = 0.0; g12 = 0.0; g20 = 0.0; g21 = 0.0; g22 = 0.0
    v0 = vel[i0, 0]; v1 = vel[i0, 1]; v2 = vel[i0, 2]
    g00 -= v0 * a0x; g01 -= v0 * a0y; g02 -= v0 * a0z
    g10 -= v1 * a0x; g11 -= v1 * a0y; g12 -= v1 * a0z
    g20 -= v2 * a0x; g21 -= v2 * a0y; g22 -= v2 * a0z
    v0 = vel[i1, 0]; v1 = vel[i1, 1]; v2 = vel[i1, 2]
    g00 -= v0 * a1x; g01 -= v0 * a1y; g02 -= v0 * a1z
    g10 -= v1 * a1x; g11 -= v1 * a1y; g12 -= v1 * a1z
    g20 -= v2 * a1x; g21 -= v2 * a1y; g22 -= v2 * a1z
    v0 = vel[i2, 0]; v1 = vel[i2, 1]; v2 = vel[i2, 2]
    g00 -= v0 * a2x; g01 -= v0 * a2y; g02 -= v0 * a2z
    g10 -= v1 * a2x; g11 -= v1 * a2y; g12 -= v1 * a2z
    g20 -= v2 * a2x; g21 -= v2 * a2y; g22 -= v2 * a2z
    v0 = vel[i3, 0]; v1 = vel[i3, 1]; v2 = vel[i3, 2]
    g00 -= v0 * a3x; g01 -= v0 * a3y; g02 -= v0 * a3z
    g10 -= v1 * a3x; g11 -= v1 * a3y; g12 -= v1 * a3z
    g20 -= v2 * a3x; g21 -= v2 * a3y; g22 -= v2 * a3z
    f = dt / (3.0 * vol)
    return (g00 * f, g11 * f, g22 * f, 0.5 * (g01 + g10) * f, 0.5 * (g02 + g20) * f, 0.5 * (g12 + g21) * f,
            0.5 * (g01 - g10) * f, 0.5 * (g02 - g20) * f, 0.5 * (g12 - g21) * f)


@njit(cache=True, inline="always")
def _force(s0, s1, s2, s3, s4, s5, ax, ay, az, w):
    """Nodal force w σ·a of a face area vector a, and its magnitude."""
    fx = (s0 * ax + s3 * ay + s4 * az) * w
    fy = (s3 * ax + s1 * ay + s5 * az) * w
    fz = (s4 * ax + s5 * ay + s2 * az) * w
    return fx, fy, fz, math.sqrt(fx * fx + fy * fy + fz * fz)


@njit(cache=True, inline="always")
def _add(force, fmag, r, fx, fy, fz, fm, foreign, sb, j):
    """Add one nodal force to gridpoint r, or to slot j when the entry is foreign; returns the
    next slot."""
    if foreign:
        sb[j, 0] = fx; sb[j, 1] = fy; sb[j, 2] = fz; sb[j, 3] = fm
        return j + 1
    force[r, 0] += fx; force[r, 1] += fy; force[r, 2] += fz
    fmag[r] += fm
    return j


@njit(cache=True)
def partition_entries(g4, nvert, npart):
    """Split the zone entries into ``npart`` parts of about equal size by the smallest
    gridpoint row of each entry's zone (ranges of gridpoint rows: compact regions when the
    gridpoints are numbered in space, as the mesher does), each part in ascending entry order.
    Returns (pstart (npart + 1,), pk (nr,) int32): the entries of part p are
    pk[pstart[p]:pstart[p + 1]]."""
    nr = g4.shape[0]
    npart = max(1, npart)
    lo = np.empty(nr, np.int64)
    cnt = np.zeros(nvert + 1, np.int64)
    for k in range(nr):
        m = min(min(g4[k, 0], g4[k, 1]), min(g4[k, 2], g4[k, 3]))
        lo[k] = m
        cnt[m + 1] += 1
    for t in range(nvert):
        cnt[t + 1] += cnt[t]              # cnt[t]: entries whose smallest row is below t
    part = np.empty(nr, np.int64)
    pstart = np.zeros(npart + 1, np.int64)
    for k in range(nr):
        p = cnt[lo[k]] * npart // max(nr, 1)   # by the rank of the entry's smallest row
        part[k] = p
        pstart[p + 1] += 1
    for p in range(npart):
        pstart[p + 1] += pstart[p]
    fill = pstart[:npart].copy()
    pk = np.empty(nr, np.int32)
    for k in range(nr):
        p = part[k]
        pk[fill[p]] = k
        fill[p] += 1
    return pstart, pk


@njit(cache=True)
def scatter_plan(tgt, ntarget, pstart, pk, sel):
    """Bookkeeping of a scatter of the selected zone entries (sel[k]) onto targets tgt (nr, 4)
    (gridpoint rows, or averaging nodes) by the parts of ``partition_entries``: the entries of a
    target are added in ascending entry order (the serial order); the run of them, from its
    first, that all lie in one part is added straight into the target by that part's thread;
    the others ("foreign" entries) are written to slots and added after the sweep.
    Returns (bits (nr,) uint8: bit a set when entry (k, a) is foreign; sbase (npart + 1,): the
    slots of part p are sbase[p]..sbase[p + 1] - 1, one per foreign entry in the order the
    part visits them, (k, a) ascending; pstart, ptgt, pslot: for each target with foreign
    entries (ptgt[i]), its slots pslot[pstart[i]:pstart[i + 1]] in ascending entry order)."""
    nr = tgt.shape[0]
    npart = pstart.shape[0] - 1
    part = np.empty(nr, np.int64)
    for p in range(npart):
        for q in range(pstart[p], pstart[p + 1]):
            part[pk[q]] = p
    owner = np.full(ntarget, -1, np.int64)      # part adding straight into t; -2: run broken
    bits = np.zeros(nr, np.uint8)
    sbase = np.zeros(npart + 1, np.int64)
    nfor = np.zeros(ntarget, np.int64)
    for k in range(nr):
        if not sel[k]:
            continue
        p = part[k]
        for a in range(4):
            t = tgt[k, a]
            if owner[t] == -1:
                owner[t] = p
            elif owner[t] != p:
                owner[t] = -2
                bits[k] |= np.uint8(1 << a)
                sbase[p + 1] += 1
                nfor[t] += 1
    for p in range(npart):
        sbase[p + 1] += sbase[p]
    nt = 0
    for t in range(ntarget):
        if nfor[t] > 0:
            nt += 1
    ptgt = np.empty(nt, np.int64)
    tstart = np.zeros(nt + 1, np.int64)
    where = np.full(ntarget, -1, np.int64)
    i = 0
    for t in range(ntarget):
        if nfor[t] > 0:
            ptgt[i] = t
            where[t] = i
            tstart[i + 1] = tstart[i] + nfor[t]
            i += 1
    pslot = np.empty(sbase[npart], np.int64)
    fill = tstart[:nt].copy()
    nxt = sbase[:npart].copy()
    for k in range(nr):                          # ascending entries: each part's slots in its order
        b = bits[k]
        if b == 0:
            continue
        p = part[k]
        for a in range(4):
            if b & (1 << a):
                i = where[tgt[k, a]]
                pslot[fill[i]] = nxt[p]
                fill[i] += 1
                nxt[p] += 1
    return bits, sbase, tstart, ptgt, pslot


@njit(cache=True)
def node_table(gp, rows, node):
    """(g4, n4, same): int32 gridpoint rows gp[rows, :4] and their averaging nodes node[g4]
    (nr, 4); ``same`` when every node is its own (then n4 is g4)."""
    nr = rows.shape[0]
    g4 = np.empty((nr, 4), np.int32)
    same = True
    for k in range(nr):
        for a in range(4):
            r = gp[rows[k], a]
            g4[k, a] = r
            if node[r] != r:
                same = False
    if same:
        return g4, g4, True
    n4 = np.empty((nr, 4), np.int32)
    for k in range(nr):
        for a in range(4):
            n4[k, a] = node[g4[k, a]]
    return g4, n4, False


class ElasticPlan:
    """What ``zone_step.zone_step`` needs besides the model's arrays, made once per mesh (the
    zone stepper keeps it): compact int32 node lists, chunks, scatter plans and the scratch.
    ``nchunk``: chunks of zone entries (any count gives the same bits; one per thread keeps
    the foreign entries few)."""

    def __init__(self, gp, rows, node, zset, weight, nvert, nchunk):
        nr = len(rows)
        #: rows, zset and weight as ``zone_step`` takes them (empty when they say nothing)
        self.rows = np.zeros(0, np.int64) if np.array_equal(rows, np.arange(nr)) else rows
        self.zset = zset if (zset >= 0).any() else np.zeros(0, np.int64)
        self.weight = weight if (weight != 1.0).any() else np.zeros(0)
        self.g4, n4, ident = node_table(gp, rows, node)
        self.n4 = self.g4 if ident else n4          # (one array: the kernel's result boxes it twice)
        self.pstart, self.pk = partition_entries(self.g4, nvert, nchunk)
        fp = scatter_plan(self.g4, nvert, self.pstart, self.pk, np.ones(nr, np.bool_))
        free = zset < 0
        np_ = fp if (ident and free.all()) else scatter_plan(self.n4, nvert, self.pstart, self.pk, free)
        self.fplan, self.nplan = fp, np_
        self.nodesum = np.empty(nvert)
        self.nodevol = np.empty(nvert)
        self.sa = np.empty((int(np_[1][-1]), 2))
        self.sb = np.empty((int(fp[1][-1]), 4))
        nsr = nr if (zset >= 0).any() else 0
        self.evs = np.empty(nsr)
        self.vols = np.empty(nsr)
