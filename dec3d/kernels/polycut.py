"""Exact cutting of convex polyhedral blocks by a family of parallel planes.

A piece is held in local arrays: vertex positions ``vp`` (nv, 3), the global vertex row
each vertex inherits its state from ``vsrc`` (nv,), face vertex counts ``fn`` (nf,), the
global face row each face came from ``fsrc`` (nf,; -1 for a face made by a cut) and the
face loops ``fvl`` (sum fn,) as local vertex indices, counter-clockwise seen from outside.

Splitting by n·x = d: each vertex is classified by its signed distance s = n·x − d as
below (s < −tol), on the plane (|s| ≤ tol, "snapped": it stays where it is and belongs to
both pieces) or above (s > tol). Only edges whose ends are strictly on opposite sides get
a new vertex, computed from the below end, so the same geometric edge in two blocks gives
bit-identical points. Hence no piece is thinner than tol across the plane, no edge is
shorter than tol, the two pieces share one cut polygon vertex for vertex, and their
volumes add up to the parent's to round-off (the pieces partition the parent).
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _grow1(a, need):
    if need <= a.shape[0]:
        return a
    new = np.empty(max(need, 2 * a.shape[0]), a.dtype)
    new[: a.shape[0]] = a
    return new


@njit(cache=True)
def _grow2(a, need):
    if need <= a.shape[0]:
        return a
    new = np.empty((max(need, 2 * a.shape[0]), a.shape[1]), a.dtype)
    new[: a.shape[0]] = a
    return new


@njit(cache=True)
def split_convex(vp, vsrc, fn, fsrc, fvl, normal, d, tol, u, w):
    """Split one convex piece by the plane n·x = d.

    vp (nv, 3) m, vsrc (nv,), fn (nf,), fsrc (nf,), fvl (m,) as in the module docstring;
    normal (3,) unit; d [m]; tol [m]; u, w (3,) unit vectors with u × w = normal.
    Returns (status, below piece (5 arrays), above piece (5 arrays)). status 0: split;
    -1: nothing above the plane; 1: nothing below; 2: degenerate section (not split).
    The below piece's cut face has outward normal +n, the above piece's −n.
    """
    nv = vp.shape[0]
    nf = fn.shape[0]
    m = fvl.shape[0]
    s = np.empty(nv)
    side = np.empty(nv, np.int8)
    nneg = 0
    npos = 0
    for v in range(nv):
        s[v] = normal[0] * vp[v, 0] + normal[1] * vp[v, 1] + normal[2] * vp[v, 2] - d
        if s[v] < -tol:
            side[v] = -1
            nneg += 1
        elif s[v] > tol:
            side[v] = 1
            npos += 1
        else:
            side[v] = 0
    e2 = np.empty((0, 3))
    e1 = np.empty(0, np.int64)
    if npos == 0 or nneg == 0:
        st = -1 if npos == 0 else 1
        return st, e2, e1, e1, e1, e1, e2, e1, e1, e1, e1

    cap_v = nv + m // 2 + 2
    bp = np.empty((cap_v, 3))
    ap = np.empty((cap_v, 3))
    bsrc = np.empty(cap_v, np.int64)
    asrc = np.empty(cap_v, np.int64)
    bmap = np.full(nv, -1, np.int64)
    amap = np.full(nv, -1, np.int64)
    pp_b = np.empty(cap_v, np.int64)     # plane points: index in the below piece
    pp_a = np.empty(cap_v, np.int64)     # ... and in the above piece
    nb = 0
    na = 0
    npp = 0
    for v in range(nv):
        if side[v] <= 0:
            bmap[v] = nb
            bp[nb] = vp[v]
            bsrc[nb] = vsrc[v]
            nb += 1
        if side[v] >= 0:
            amap[v] = na
            ap[na] = vp[v]
            asrc[na] = vsrc[v]
            na += 1
        if side[v] == 0:
            pp_b[npp] = bmap[v]
            pp_a[npp] = amap[v]
            npp += 1

    ce_lo = np.empty(cap_v, np.int64)
    ce_hi = np.empty(cap_v, np.int64)
    ce_b = np.empty(cap_v, np.int64)
    ce_a = np.empty(cap_v, np.int64)
    nce = 0
    cap_f = m + nf + cap_v
    b_fn = np.empty(nf + 1, np.int64)
    a_fn = np.empty(nf + 1, np.int64)
    b_fsrc = np.empty(nf + 1, np.int64)
    a_fsrc = np.empty(nf + 1, np.int64)
    b_fv = np.empty(cap_f, np.int64)
    a_fv = np.empty(cap_f, np.int64)
    nbf = 0
    naf = 0
    nbfv = 0
    nafv = 0
    off = 0
    for f in range(nf):
        k = fn[f]
        start_b = nbfv
        start_a = nafv
        off_plane_b = False
        off_plane_a = False
        for q in range(k):
            va = fvl[off + q]
            vb = fvl[off + (q + 1) % k]
            sa = side[va]
            sb = side[vb]
            if sa <= 0:
                b_fv[nbfv] = bmap[va]
                nbfv += 1
                if sa < 0:
                    off_plane_b = True
            if sa >= 0:
                a_fv[nafv] = amap[va]
                nafv += 1
                if sa > 0:
                    off_plane_a = True
            if sa * sb < 0:
                lo = va if sa < 0 else vb
                hi = vb if sa < 0 else va
                idx = -1
                for e in range(nce):
                    if ce_lo[e] == lo and ce_hi[e] == hi:
                        idx = e
                        break
                if idx < 0:
                    # from the below end: identical in every block sharing this edge
                    t = s[lo] / (s[lo] - s[hi])
                    for x in range(3):
                        bp[nb, x] = vp[lo, x] + t * (vp[hi, x] - vp[lo, x])
                    ap[na] = bp[nb]
                    bsrc[nb] = vsrc[lo]
                    asrc[na] = vsrc[lo]
                    ce_lo[nce] = lo
                    ce_hi[nce] = hi
                    ce_b[nce] = nb
                    ce_a[nce] = na
                    pp_b[npp] = nb
                    pp_a[npp] = na
                    nb += 1
                    na += 1
                    npp += 1
                    idx = nce
                    nce += 1
                b_fv[nbfv] = ce_b[idx]
                nbfv += 1
                a_fv[nafv] = ce_a[idx]
                nafv += 1
        # a clipped loop made only of plane points lies in the cut face: drop it
        if nbfv - start_b >= 3 and off_plane_b:
            b_fn[nbf] = nbfv - start_b
            b_fsrc[nbf] = fsrc[f]
            nbf += 1
        else:
            nbfv = start_b
        if nafv - start_a >= 3 and off_plane_a:
            a_fn[naf] = nafv - start_a
            a_fsrc[naf] = fsrc[f]
            naf += 1
        else:
            nafv = start_a
        off += k

    if npp < 3:
        return 2, e2, e1, e1, e1, e1, e2, e1, e1, e1, e1

    # order the section polygon by angle about its mean (it is convex)
    cu = 0.0
    cw = 0.0
    for i in range(npp):
        p = pp_b[i]
        cu += bp[p, 0] * u[0] + bp[p, 1] * u[1] + bp[p, 2] * u[2]
        cw += bp[p, 0] * w[0] + bp[p, 1] * w[1] + bp[p, 2] * w[2]
    cu /= npp
    cw /= npp
    ang = np.empty(npp)
    for i in range(npp):
        p = pp_b[i]
        pu = bp[p, 0] * u[0] + bp[p, 1] * u[1] + bp[p, 2] * u[2] - cu
        pw = bp[p, 0] * w[0] + bp[p, 1] * w[1] + bp[p, 2] * w[2] - cw
        ang[i] = np.arctan2(pw, pu)
    order = np.argsort(ang, kind="mergesort")
    # below piece: counter-clockwise about +n; above piece: reversed
    for i in range(npp):
        b_fv[nbfv + i] = pp_b[order[i]]
        a_fv[nafv + i] = pp_a[order[npp - 1 - i]]
    nbfv += npp
    nafv += npp
    b_fn[nbf] = npp
    a_fn[naf] = npp
    b_fsrc[nbf] = -1
    a_fsrc[naf] = -1
    nbf += 1
    naf += 1
    return (0, bp[:nb].copy(), bsrc[:nb].copy(), b_fn[:nbf].copy(), b_fsrc[:nbf].copy(),
            b_fv[:nbfv].copy(), ap[:na].copy(), asrc[:na].copy(), a_fn[:naf].copy(),
            a_fsrc[:naf].copy(), a_fv[:nafv].copy())


@njit(cache=True)
def _emit(bufs, cnt, parent, pvp, pvsrc, pfn, pfsrc, pfv):
    """Append one piece to the output buffers (growing them); cnt = [pieces, v, f, fv]."""
    o_parent, o_pnv, o_pnf, o_pos, o_vsrc, o_fn, o_fsrc, o_fv = bufs
    npc, nvo, nfo, nfvo = cnt[0], cnt[1], cnt[2], cnt[3]
    nv = pvp.shape[0]
    nf = pfn.shape[0]
    nfv = pfv.shape[0]
    o_parent = _grow1(o_parent, npc + 1)
    o_pnv = _grow1(o_pnv, npc + 1)
    o_pnf = _grow1(o_pnf, npc + 1)
    o_pos = _grow2(o_pos, nvo + nv)
    o_vsrc = _grow1(o_vsrc, nvo + nv)
    o_fn = _grow1(o_fn, nfo + nf)
    o_fsrc = _grow1(o_fsrc, nfo + nf)
    o_fv = _grow1(o_fv, nfvo + nfv)
    o_parent[npc] = parent
    o_pnv[npc] = nv
    o_pnf[npc] = nf
    o_pos[nvo:nvo + nv] = pvp
    o_vsrc[nvo:nvo + nv] = pvsrc
    o_fn[nfo:nfo + nf] = pfn
    o_fsrc[nfo:nfo + nf] = pfsrc
    o_fv[nfvo:nfvo + nfv] = pfv
    cnt[0] += 1
    cnt[1] += nv
    cnt[2] += nf
    cnt[3] += nfv
    return (o_parent, o_pnv, o_pnf, o_pos, o_vsrc, o_fn, o_fsrc, o_fv)


@njit(cache=True)
def cut_blocks(pos, fv, f_vstart, f_nvert, b_vstart, b_vcount, b_fstart, b_fcount,
               rows, normal, offsets, tol, u, w):
    """Cut blocks ``rows`` by the planes n·x = offsets[k] (offsets sorted ascending).

    pos (nv, 3) m; fv (m,) global vertex rows; f_vstart, f_nvert (nf,); b_vstart, b_vcount,
    b_fstart, b_fcount (nb,) CSR ranges of each block; rows (k,) block rows to cut;
    normal, u, w (3,) with u × w = normal; offsets (p,) m; tol m.
    Only blocks actually split produce output; their pieces come in increasing n·x order.
    Returns (parent (np,) block row, piece_nv (np,), piece_nf (np,), out_pos (Σnv, 3),
    out_vsrc (Σnv,) global vertex row each vertex inherits from, out_fn (Σnf,),
    out_fsrc (Σnf,) global source face row or -1 for cut faces, out_fv (Σ fn,) vertex
    indices local to the piece).
    """
    bufs = (np.empty(16, np.int64), np.empty(16, np.int64), np.empty(16, np.int64),
            np.empty((128, 3)), np.empty(128, np.int64), np.empty(128, np.int64),
            np.empty(128, np.int64), np.empty(512, np.int64))
    cnt = np.zeros(4, np.int64)
    for i in range(rows.shape[0]):
        b = rows[i]
        vs = b_vstart[b]
        vc = b_vcount[b]
        smin = np.inf
        smax = -np.inf
        for v in range(vs, vs + vc):
            sv = normal[0] * pos[v, 0] + normal[1] * pos[v, 1] + normal[2] * pos[v, 2]
            smin = min(smin, sv)
            smax = max(smax, sv)
        lo = np.searchsorted(offsets, smin + tol, side="right")
        hi = np.searchsorted(offsets, smax - tol, side="left")
        if lo >= hi:
            continue
        # the block as a working piece in local numbering
        vp = pos[vs:vs + vc].copy()
        vsrc = np.arange(vs, vs + vc)
        fs = b_fstart[b]
        fc = b_fcount[b]
        fn = f_nvert[fs:fs + fc].copy()
        fsrc = np.arange(fs, fs + fc)
        fvl = np.empty(fn.sum(), np.int64)
        q = 0
        for f in range(fs, fs + fc):
            for j in range(f_vstart[f], f_vstart[f] + f_nvert[f]):
                fvl[q] = fv[j] - vs
                q += 1
        nsplit = 0
        for k in range(lo, hi):
            res = split_convex(vp, vsrc, fn, fsrc, fvl, normal, offsets[k], tol, u, w)
            st = res[0]
            if st == 1 or st == 2:
                continue
            if st == -1:
                break
            bufs = _emit(bufs, cnt, b, res[1], res[2], res[3], res[4], res[5])
            nsplit += 1
            vp, vsrc, fn, fsrc, fvl = res[6], res[7], res[8], res[9], res[10]
        if nsplit > 0:
            bufs = _emit(bufs, cnt, b, vp, vsrc, fn, fsrc, fvl)
    npc, nvo, nfo, nfvo = cnt[0], cnt[1], cnt[2], cnt[3]
    return (bufs[0][:npc], bufs[1][:npc], bufs[2][:npc], bufs[3][:nvo], bufs[4][:nvo],
            bufs[5][:nfo], bufs[6][:nfo], bufs[7][:nfvo])
