"""Contact bookkeeping across detection passes (3DEC theory, "Representation of Contacts",
"Interaction between Blocks": force history kept when contacts and sub-contacts are found again).

- ``match_sorted``: rows of an old sorted key list that hold each new key (merge join).
- ``cp_batch``: the common plane of every candidate pair, with the fast path for pairs that
  were contacts before (kernel ``commonplane.common_plane``).
- ``carry_over``: the state of each new sub-contact from the old sub-contacts of the same
  contact: the sub-contact with the same identity (kind and vertex, or the two edges)
  keeps its displacements and state and its shear force scaled by the area ratio (the
  stress is kept); a new one gets the mean shear stress and dilation of the old contact
  (smooth reallocation, as in UDEC) and, like every sub-contact of a new contact, its own
  gap as uⁿ (``subcontact_gaps``), flagged ``ST_NEW`` (its first force update adds no
  increment: the gap was measured after the step's motion). The old contact's mean opening
  would put a new corner sub-contact of a rocking block up to CTOL/2 inside its base.
- ``subcontact_gaps``: the gap of each sub-contact along the contact normal, from the two
  blocks' surfaces over its point.

Sub-contact kinds (``subgeom``): 0 vertex of A on a face of B, 1 vertex of B on a face of A,
2 edge-edge crossing, 3 point of a lower contact type. A vertex sub-contact keeps its
identity when its vertex moves onto another face of the opposing block (relocation).
"""
from __future__ import annotations

import math

import numpy as np
from numba import get_num_threads, njit, prange

from .commonplane import common_plane, contact_type
from .joints import ST_NEW

#: detection kernels with a parallel loop (``cp_batch``, ``subcontact_gaps``) are compiled serial
#: (their ``prange`` runs as ``range``), with a parallel twin (``*_parallel``) for at least this many
#: items on more than one thread (``threaded``): a small model's pass is over before the other
#: threads wake up, and a parallel kernel takes about three times as long to compile (a cold start);
#: measured: a detection of the 10-layer cube stack (10 600 contacts, 30 000 sub-contacts) took 15 ms
#: on one thread and 10 ms longer with the twins and the Python threads of ``physics.contacts``
PARALLEL_FROM = 40000


@njit(cache=True)
def match_sorted(old0, old1, new0, new1):
    """For each new key (new0[i], new1[i]) the row of the equal old key, or -1.

    Both key lists sorted lexicographically and free of repeats. Returns int64 (len(new0),).
    """
    out = np.full(new0.shape[0], -1, np.int64)
    j = 0
    no = old0.shape[0]
    for i in range(new0.shape[0]):
        while j < no and (old0[j] < new0[i] or (old0[j] == new0[i] and old1[j] < new1[i])):
            j += 1
        if j < no and old0[j] == new0[i] and old1[j] == new1[i]:
            out[i] = j
    return out


@njit(cache=True)
def cp_batch(ra, rb, prev, vpos, bvstart, bvcount, centroid, old_n, old_c, reach,
             out_n, out_c, out_gap, out_type):
    """Common plane of every candidate pair (rows ra[i], rb[i]; A → B).

    prev (k,) int64: row of the old contact of the pair or -1 (new pairs start from the
    line of centroids, Eq. 5; old ones from their normal and reference point, fast path).
    vpos (nv, 3) m; bvstart/bvcount (nb,) vertex ranges; centroid (nb, 3) m;
    old_n/old_c (nold, 3) previous normals and reference points; reach (k,) [m]: the pair is
    a contact when its gap is at most this (CTOL, plus the blocks' step motion when fast).
    Writes out_n/out_c (k, 3), out_gap (k,) m, out_type (k,) contact type (CT_*, 0 if apart).
    """
    for i in prange(ra.shape[0]):          # pairs (in parallel in the twin): each writes only its own row
        n0 = np.empty(3)
        nn = np.empty(3)
        cc = np.empty(3)
        a = ra[i]
        b = rb[i]
        va = vpos[bvstart[a]:bvstart[a] + bvcount[a]]
        vb = vpos[bvstart[b]:bvstart[b] + bvcount[b]]
        p = prev[i]
        if p >= 0:
            for d in range(3):
                n0[d] = old_n[p, d]
                cc[d] = old_c[p, d]
        else:
            for d in range(3):
                n0[d] = centroid[b, d] - centroid[a, d]
                cc[d] = 0.5 * (centroid[a, d] + centroid[b, d])
            if n0[0] == 0.0 and n0[1] == 0.0 and n0[2] == 0.0:
                n0[2] = 1.0
        gap, na, nb, _ = common_plane(va, vb, n0, reach[i], p >= 0, nn, cc)
        for d in range(3):
            out_n[i, d] = nn[d]
            out_c[i, d] = cc[d]
        out_gap[i] = gap
        out_type[i] = contact_type(na, nb) if gap <= reach[i] else 0


@njit(cache=True)
def newell(vpos, fverts, start, m):
    """Newell's vector of the face whose m vertex indices start at ``fverts[start]``: 2 × area ×
    unit normal for a planar face (outward for counter-clockwise vertices seen from outside)."""
    nx = 0.0
    ny = 0.0
    nz = 0.0
    for j in range(m):
        p = fverts[start + j]
        q = fverts[start + (j + 1) % m]
        nx += (vpos[p, 1] - vpos[q, 1]) * (vpos[p, 2] + vpos[q, 2])
        ny += (vpos[p, 2] - vpos[q, 2]) * (vpos[p, 0] + vpos[q, 0])
        nz += (vpos[p, 0] - vpos[q, 0]) * (vpos[p, 1] + vpos[q, 1])
    return nx, ny, nz


@njit(cache=True)
def subcontact_gaps(sc_contact, pos, ca, cb, cn, cgap, centroid, vpos, bfstart, bfcount, fvstart,
                    fnvert, fverts, out):
    """Gap [m] of each sub-contact: along the contact normal n (A → B) through its point x,
    the distance from A's surface to B's surface (negative: overlap).

    A convex block is the intersection of its face half-spaces, so on the line x + t n its
    side facing B ends at t_A = min over A's faces with outward normal m, m·n > 0, of
    m·(f − x) / m·n (f a point of the face), and B begins at t_B = max over B's faces with
    m·n < 0 of the same; gap = t_B − t_A. Exact for a point over both blocks, a plane
    continuation just beside one. Face normals by Newell's formula from the current vertices,
    turned outward with the block centroid. The contact gap ``cgap`` (nc,) when a side has no
    such face (degenerate). sc_contact (ns,), pos (ns, 3) [m]; ca, cb (nc,) block rows;
    cn (nc, 3); centroid (nb, 3); faces as in ``subgeom.subcontacts_batch``; writes out (ns,).
    """
    # the face planes of a contact's two blocks are worked out once for its run of sub-contacts
    # (consecutive rows of one contact: the sub-contacts come ordered by contact)
    ns = sc_contact.shape[0]
    nrun = 0
    for s in range(ns):
        if s == 0 or sc_contact[s] != sc_contact[s - 1]:
            nrun += 1
    first = np.empty(nrun + 1, np.int64)
    r = 0
    for s in range(ns):
        if s == 0 or sc_contact[s] != sc_contact[s - 1]:
            first[r] = s
            r += 1
    first[nrun] = ns
    for r in prange(nrun):                  # (in parallel in the twin) each writes only its own rows
        c = sc_contact[first[r]]
        n0 = cn[c, 0]
        n1 = cn[c, 1]
        n2 = cn[c, 2]
        nfa = bfcount[ca[c]]
        plane = np.empty((nfa + bfcount[cb[c]], 7))   # m (outward unit normal), f (face centre), m·n
        npl = np.zeros(2, np.int64)
        for side in range(2):
            b = ca[c] if side == 0 else cb[c]
            for f in range(bfstart[b], bfstart[b] + bfcount[b]):
                m = fnvert[f]
                if m < 3:
                    continue
                mx, my, mz = newell(vpos, fverts, fvstart[f], m)
                fx = 0.0
                fy = 0.0
                fz = 0.0
                for j in range(m):
                    p = fverts[fvstart[f] + j]
                    fx += vpos[p, 0]
                    fy += vpos[p, 1]
                    fz += vpos[p, 2]
                ln = math.sqrt(mx * mx + my * my + mz * mz)
                if ln == 0.0:
                    continue
                fx /= m
                fy /= m
                fz /= m
                mx /= ln
                my /= ln
                mz /= ln
                if mx * (fx - centroid[b, 0]) + my * (fy - centroid[b, 1]) + mz * (fz - centroid[b, 2]) < 0.0:
                    mx = -mx
                    my = -my
                    mz = -mz
                mn = mx * n0 + my * n1 + mz * n2
                if abs(mn) <= 1e-9 or (side == 0 and mn <= 0.0) or (side == 1 and mn >= 0.0):
                    continue
                k = npl[side] + (0 if side == 0 else nfa)
                plane[k, 0] = mx
                plane[k, 1] = my
                plane[k, 2] = mz
                plane[k, 3] = fx
                plane[k, 4] = fy
                plane[k, 5] = fz
                plane[k, 6] = mn
                npl[side] += 1
        for s in range(first[r], first[r + 1]):
            ta = math.inf
            tb = -math.inf
            for side in range(2):
                k0 = 0 if side == 0 else nfa
                for k in range(k0, k0 + npl[side]):
                    t = (plane[k, 0] * (plane[k, 3] - pos[s, 0]) + plane[k, 1] * (plane[k, 4] - pos[s, 1]) +
                         plane[k, 2] * (plane[k, 5] - pos[s, 2])) / plane[k, 6]
                    if side == 0 and t < ta:
                        ta = t
                    if side == 1 and t > tb:
                        tb = t
            if ta == math.inf or tb == -math.inf:
                out[s] = cgap[c]
            else:
                out[s] = tb - ta


def parallel_twin(kernel, name):
    """``kernel`` compiled with ``parallel`` under its own name (numba caches it in its own file;
    also ``bodyscale``'s)."""
    f = getattr(kernel, "py_func", kernel)         # (a plain function when the JIT is disabled)
    g = type(f)(f.__code__, f.__globals__, name, f.__defaults__, f.__closure__)
    g.__qualname__ = name
    g.__module__ = f.__module__
    g.__doc__ = f"``{f.__name__}`` with its ``prange`` loops in parallel."
    return njit(cache=True, parallel=True)(g)


cp_batch_parallel = parallel_twin(cp_batch, "cp_batch_parallel")
subcontact_gaps_parallel = parallel_twin(subcontact_gaps, "subcontact_gaps_parallel")


def threaded(kernel, n):
    """The kernel to run on ``n`` items: its parallel twin for ``PARALLEL_FROM`` items or more on
    more than one thread, else ``kernel`` (the same numbers: each item writes only its own row)."""
    if n >= PARALLEL_FROM and get_num_threads() > 1:
        return cp_batch_parallel if kernel is cp_batch else subcontact_gaps_parallel
    return kernel


@njit(cache=True, nogil=True)
def carry_over(cprev, new_sc_contact, new_kind, new_key0, new_key1, new_area, sgap,
               old_start, old_count, old_kind, old_key0, old_key1, old_area,
               old_fs, old_un, old_udil, old_us, old_state, old_hist, old_n, new_n,
               fs, un, udil, us, state, hist):
    """State of the new sub-contacts from the old ones (see the module docstring).

    cprev (nc,) old contact row of each new contact or -1; new_sc_* (ns,) the new
    sub-contacts, ordered by contact; sgap (ns,) their own gaps [m] (``subcontact_gaps``),
    the uⁿ of every sub-contact without an old twin (state ``ST_NEW``); old_start/old_count
    (nold,) CSR of the old sub-contacts per old contact; old_* the old sub-contact arrays;
    old_n (nold, 3) / new_n (nc, 3) contact normals: old shear forces are first turned to
    the new plane by Eq. (23). Writes fs (ns, 3) N, un, udil (ns,) m, us (ns, 3) m, state (ns,),
    hist (ns, NJHIST) the joint models' history: the twin's, or the area-weighted mean of the old
    contact's sub-contacts (zero on a new contact).
    """
    rot = np.empty(3)
    mean_fs = np.zeros(3)
    for s in range(new_sc_contact.shape[0]):
        c = new_sc_contact[s]
        p = cprev[c]
        for d in range(3):
            fs[s, d] = 0.0
            us[s, d] = 0.0
        udil[s] = 0.0
        state[s] = ST_NEW
        un[s] = sgap[s]
        for j in range(hist.shape[1]):
            hist[s, j] = 0.0
        if p < 0:
            continue
        k0 = old_n[p, 1] * new_n[c, 2] - old_n[p, 2] * new_n[c, 1]
        k1 = old_n[p, 2] * new_n[c, 0] - old_n[p, 0] * new_n[c, 2]
        k2 = old_n[p, 0] * new_n[c, 1] - old_n[p, 1] * new_n[c, 0]
        lo = old_start[p]
        hi = lo + old_count[p]
        hit = -1
        for o in range(lo, hi):
            if old_kind[o] != new_kind[s] or old_key0[o] != new_key0[s]:
                continue
            if new_kind[s] >= 2 and old_key1[o] != new_key1[s]:
                continue
            hit = o
            break
        if hit >= 0:
            r = new_area[s] / old_area[hit] if old_area[hit] > 0.0 else 1.0
            f0 = old_fs[hit, 0]
            f1 = old_fs[hit, 1]
            f2 = old_fs[hit, 2]
            rot[0] = f0 - (f1 * k2 - f2 * k1)
            rot[1] = f1 - (f2 * k0 - f0 * k2)
            rot[2] = f2 - (f0 * k1 - f1 * k0)
            for d in range(3):
                fs[s, d] = rot[d] * r
                us[s, d] = old_us[hit, d]
            un[s] = old_un[hit]
            udil[s] = old_udil[hit]
            state[s] = old_state[hit]
            for j in range(hist.shape[1]):
                hist[s, j] = old_hist[hit, j]
            continue
        # no old twin: the mean shear stress and dilation of the old contact, its failure
        # state; its own gap
        atot = 0.0
        mdil = 0.0
        st = 0
        for d in range(3):
            mean_fs[d] = 0.0
        for o in range(lo, hi):
            atot += old_area[o]
            mdil += old_udil[o] * old_area[o]
            for d in range(3):
                mean_fs[d] += old_fs[o, d]
            st |= old_state[o] & 1
            for j in range(hist.shape[1]):
                hist[s, j] += old_hist[o, j] * old_area[o]
        if atot <= 0.0:
            for j in range(hist.shape[1]):
                hist[s, j] = 0.0
            continue
        for j in range(hist.shape[1]):
            hist[s, j] /= atot
        f0 = mean_fs[0]
        f1 = mean_fs[1]
        f2 = mean_fs[2]
        rot[0] = f0 - (f1 * k2 - f2 * k1)
        rot[1] = f1 - (f2 * k0 - f0 * k2)
        rot[2] = f2 - (f0 * k1 - f1 * k0)
        for d in range(3):
            fs[s, d] = rot[d] / atot * new_area[s]
        udil[s] = mdil / atot
        state[s] = st | ST_NEW


@njit(cache=True, nogil=True)
def gather_subcontacts(lo, hi, base, starts, counts, nold, old, new, out):
    """The sub-contacts of contacts lo .. hi-1 of a detection, each taken from the old rows or the
    new ones: contact c has counts[c] sub-contacts, written from row starts[c] of ``out`` and
    read from row base[c] of the old rows followed by the new ones (base[c] ≥ nold: row
    base[c] − nold of the new). Its rows in order, one contact after the other.

    old: (kind, key0, key1, pos, area, fn, fs, un, udil, us, state, hist), the old sub-contact
    arrays (nold rows); new: the same without fn (a new sub-contact starts with fn 0); out: (contact,
    kind, key0, key1, pos, area, fn, fs, un, udil, us, state, hist), ``out[0][i]`` the contact of row i."""
    o_kind, o_key0, o_key1, o_pos, o_area, o_fn, o_fs, o_un, o_udil, o_us, o_state, o_hist = old
    n_kind, n_key0, n_key1, n_pos, n_area, n_fs, n_un, n_udil, n_us, n_state, n_hist = new
    w_c, w_kind, w_key0, w_key1, w_pos, w_area, w_fn, w_fs, w_un, w_udil, w_us, w_state, w_hist = out
    for c in range(lo, hi):
        for j in range(counts[c]):
            i = starts[c] + j
            r = base[c] + j
            w_c[i] = c
            if r < nold:
                w_kind[i] = o_kind[r]
                w_key0[i] = o_key0[r]
                w_key1[i] = o_key1[r]
                w_area[i] = o_area[r]
                w_fn[i] = o_fn[r]
                w_un[i] = o_un[r]
                w_udil[i] = o_udil[r]
                w_state[i] = o_state[r]
                for d in range(3):
                    w_pos[i, d] = o_pos[r, d]
                    w_fs[i, d] = o_fs[r, d]
                    w_us[i, d] = o_us[r, d]
                for d in range(w_hist.shape[1]):
                    w_hist[i, d] = o_hist[r, d]
            else:
                r -= nold
                w_kind[i] = n_kind[r]
                w_key0[i] = n_key0[r]
                w_key1[i] = n_key1[r]
                w_area[i] = n_area[r]
                w_fn[i] = 0.0
                w_un[i] = n_un[r]
                w_udil[i] = n_udil[r]
                w_state[i] = n_state[r]
                for d in range(3):
                    w_pos[i, d] = n_pos[r, d]
                    w_fs[i, d] = n_fs[r, d]
                    w_us[i, d] = n_us[r, d]
                for d in range(w_hist.shape[1]):
                    w_hist[i, d] = n_hist[r, d]


@njit(cache=True)
def envelopes(vpos, bvstart, bvcount, active, pad, lo, hi):
    """Axis-aligned envelope of each active block enlarged by ``pad`` [m] on every side."""
    for b in range(bvstart.shape[0]):
        if not active[b]:
            for d in range(3):
                lo[b, d] = 0.0
                hi[b, d] = 0.0
            continue
        for d in range(3):
            lo[b, d] = math.inf
            hi[b, d] = -math.inf
        for v in range(bvstart[b], bvstart[b] + bvcount[b]):
            for d in range(3):
                x = vpos[v, d]
                if x < lo[b, d]:
                    lo[b, d] = x
                if x > hi[b, d]:
                    hi[b, d] = x
        for d in range(3):
            lo[b, d] -= pad
            hi[b, d] += pad


@njit(cache=True)
def blocks_moved(vpos, snap, bvstart, bvcount, tol, out):
    """out[b] = True where a vertex of block b is more than ``tol`` [m] (in any coordinate)
    from its position in ``snap`` (nv, 3)."""
    for b in range(bvstart.shape[0]):
        hit = False
        for v in range(bvstart[b], bvstart[b] + bvcount[b]):
            for d in range(3):
                if abs(vpos[v, d] - snap[v, d]) > tol:
                    hit = True
        out[b] = hit


@njit(cache=True)
def vertex_point_areas(sc_contact, kind, key0, ctype, cn, vpos, vblock, bfstart, bfcount, fvstart,
                       fnvert, fverts, point_area, area):
    """Areas of the point sub-contacts of vertex-face and edge-face contacts (kind 3, key0 a
    vertex row), in place: the text's rule (a third of the surrounding triangles on the c-p)
    extended to a vertex whose faces are not on the plane: each face of the vertex's block
    that contains the vertex gives its area / its vertex count, times |n_face · n| (its
    projection onto the c-p). Never less than ``point_area``. A block standing on a corner
    or an edge so gets springs of the size of its faces, growing smoothly to the face-face
    areas as a face comes down onto the plane; a nominal 1 % point area let a heavy block
    on an edge sink by a large fraction of its size.

    ctype (nc,) contact types; cn (nc, 3) normals; vblock (nv,) owning block row of each
    vertex; faces as in ``subgeom.subcontacts_batch``; area (ns,) [m²] updated.
    """
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        if kind[s] != 3 or not (ctype[c] == 3 or ctype[c] == 5):
            continue
        v = key0[s]
        if v < 0 or v >= vblock.shape[0]:
            continue
        b = vblock[v]
        tot = 0.0
        for f in range(bfstart[b], bfstart[b] + bfcount[b]):
            m = fnvert[f]
            has = False
            for j in range(fvstart[f], fvstart[f] + m):
                if fverts[j] == v:
                    has = True
                    break
            if not has:
                continue
            # Newell's vector: 2 × area × unit normal of the (planar) face
            nx, ny, nz = newell(vpos, fverts, fvstart[f], m)
            tot += 0.5 * abs(nx * cn[c, 0] + ny * cn[c, 1] + nz * cn[c, 2]) / m
        area[s] = max(point_area, tot)
