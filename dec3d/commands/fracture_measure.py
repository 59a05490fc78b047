"""`fracture compute`, `fracture intersections compute`, `fracture list`, `fracture delete`, and
`block cut dfn` with the contact range element `jointset-id` (measures: ``dec3d.geometry.dfn_measure``;
cutting: ``dec3d.geometry.dfn_cut``)."""
from __future__ import annotations

import math

import numpy as np

from ..errors import CommandError, ResourceError
from ..geometry import dfn_measure
from ..geometry.dfn_cut import TooManyBlocks, cut_dfn
from ..geometry.errors import GeometryError
from ..model.model import KIND_RIGID
from ..model import fractures as FR
from ..units import suffix as unit
from .budget import budget, check_blocks
from .fracture import _arrays, _box, _dfn_rows
from .registry import command, range_element
from .values import ANGLE, FLAG, POINT, Num, Nums, P, Text


def _grid_lines(box, k: int):
    """k × k scanlines across the box along each of x, y, z (cell centres): (starts, ends)."""
    b = np.asarray(box, float)
    f = (np.arange(k) + 0.5) / k
    starts, ends = [], []
    for ax in range(3):
        o1, o2 = [a for a in range(3) if a != ax]
        u = b[2 * o1] + f * (b[2 * o1 + 1] - b[2 * o1])
        v = b[2 * o2] + f * (b[2 * o2 + 1] - b[2 * o2])
        uu, vv = np.meshgrid(u, v, indexing="ij")
        p0 = np.zeros((k * k, 3))
        p0[:, o1], p0[:, o2], p0[:, ax] = uu.ravel(), vv.ravel(), b[2 * ax]
        p1 = p0.copy()
        p1[:, ax] = b[2 * ax + 1]
        starts.append(p0)
        ends.append(p1)
    return np.concatenate(starts), np.concatenate(ends)


def _put(session, key, value, suffix):
    session.results[key] = float(value)
    if suffix:
        session.results[f"{key}.{suffix}"] = float(value)


@command("fracture compute",
         keywords=[P("dfn", Text(), "only this DFN (results are also stored as `<name>.<dfn>`)"),
                   P("scanline", Nums(6, 6), "P10 along the segment x1 y1 z1 x2 y2 z2", units="m"),
                   P("scanlines", Num(integer=True, lo=1, hi=1000), "P10 on k × k scanlines across the box along "
                     "each of x, y and z (3k² lines)"),
                   P("box", Nums(6, 6), "P32 in the box x1 x2 y1 y2 z1 z2 (default: the blocks' box)", units="m"),
                   P("plane-origin", POINT, "P21 on the plane through this point (in the box)", units="m"),
                   P("dip", ANGLE, "dip of the P21 plane", default=0.0),
                   P("dip-direction", ANGLE, "dip direction of the P21 plane", default=0.0)],
         doc="Compute and print DFN measures: count by set, P32 in a box, P10 on scanlines, P21 on a plane, "
             "orientation and size statistics.",
         details="P32 = disk area inside the box / its volume, the disks clipped to the box exactly; P10 = disks "
                 "the scanline(s) cross / their length; P21 = trace length inside the box / area of the plane's "
                 "section of the box. With P10 and P32 both, `p10_ratio` = P10 / (P32 E|cos θ|), θ between a "
                 "fracture's normal and the line, E the area-weighted mean over the DFN's fractures (1 in theory "
                 "for uniformly placed disks). Orientation: mean dip, mean dip direction (degrees) and Fisher's "
                 "κ̂ = (N − 1)/(N − R); sizes: the maximum-likelihood power-law exponent of the diameters on the "
                 "template's size limits (a DFN generated from a template). The keywords are dec3d's (Itasca's "
                 "`fracture compute` page could not be read in full). Results: `fractures`, `p32`, `p10`, `p21`, "
                 "`p10_ratio`, `mean_dip`, `mean_dip_direction`, `kappa`, `size_exponent`; with `dfn`, also "
                 "each as `<name>.<dfn>`.",
         examples=["fracture compute", "fracture compute box 0 50 0 50 0 50 scanline 0 25 25 50 25 25",
                   "fracture compute box 5 45 5 45 5 45 scanlines 10 dfn 'iso'",
                   "fracture compute plane-origin 25 25 25 dip 90 dip-direction 90 dfn 'rock'"])
def fracture_compute(session, call):
    a = call.args
    m = session.model
    rows, did = _dfn_rows(session, call)
    suffix = a["dfn"]
    c, n, r = _arrays(m, rows)
    fs = FR.fracture_store(m)
    sets, counts = np.unique(fs["set"][rows], return_counts=True)
    session.write(f"fractures: {len(rows)}  (by set: " + ", ".join(f"{int(s)}: {int(k)}" for s, k in zip(sets, counts))
                  + ")")
    _put(session, "fractures", len(rows), suffix)
    if len(rows) == 0:
        return
    box = _box(session, call, "box") if (a["box"] is not None or m.blocks.n) else None
    p32 = None
    if box is not None:
        p32 = dfn_measure.p32(c, n, r, box)
        _put(session, "p32", p32, suffix)
        session.write(f"P32 in the box: {p32:.6g} 1/m")
    lines = []
    if a["scanline"] is not None:
        lines.append((np.asarray(a["scanline"][:3], float)[None], np.asarray(a["scanline"][3:], float)[None]))
    if a["scanlines"] is not None:
        if box is None:
            raise CommandError("`scanlines` needs a box (`box x1 x2 y1 y2 z1 z2`)", call.location)
        lines.append(_grid_lines(box, int(a["scanlines"])))
    if lines:
        p0 = np.concatenate([x[0] for x in lines])
        p1 = np.concatenate([x[1] for x in lines])
        hits = sum(int(dfn_measure.scanline_hits(c, n, r, p0[i], p1[i]).sum()) for i in range(len(p0)))
        dirs = (p1 - p0) / np.linalg.norm(p1 - p0, axis=1)[:, None]
        length = float(np.linalg.norm(p1 - p0, axis=1).sum())
        p10 = hits / length
        _put(session, "p10", p10, suffix)
        L, pl = unit(m, "length"), unit(m, "per-length")
        session.write(f"P10 on {len(p0)} scanline(s) of {length:.6g}{L}: {p10:.6g}{pl} ({hits} crossings)")
        if p32 is not None and p32 > 0:
            wlen = np.linalg.norm(p1 - p0, axis=1) / length
            area = r * r
            ecos = float((np.abs(n @ dirs.T) @ wlen * area).sum() / area.sum())
            ratio = p10 / (p32 * ecos)
            _put(session, "p10_ratio", ratio, suffix)
            session.write(f"P10 / (P32 E|cos θ|) = {ratio:.5f} (E|cos θ| = {ecos:.5f})")
    if a["plane_origin"] is not None:
        if box is None:
            raise CommandError("P21 needs a box (`box x1 x2 y1 y2 z1 z2`)", call.location)
        d, dd = float(a["dip"]), float(a["dip_direction"])
        normal = [math.sin(d) * math.sin(dd), math.sin(d) * math.cos(dd), math.cos(d)]
        try:
            v, length, area = dfn_measure.p21(c, n, r, a["plane_origin"], normal, box)
        except ValueError as exc:
            raise CommandError(str(exc), call.locations.get("plane_origin", call.location)) from None
        _put(session, "p21", v, suffix)
        session.write(f"P21 on the plane: {v:.6g}{unit(m, 'per-length')} (traces {length:.6g}{unit(m, 'length')} "
                      f"on {area:.6g}{unit(m, 'area')})")
    if len(rows) > 1:
        md, mdd, kap = dfn_measure.fisher_stats(n)
        _put(session, "mean_dip", math.degrees(md), suffix)
        _put(session, "mean_dip_direction", math.degrees(mdd), suffix)
        _put(session, "kappa", kap, suffix)
        session.write(f"mean orientation {math.degrees(md):.2f}/{math.degrees(mdd):.2f}, kappa {kap:.4g}")
    t = FR.dfn_state(m).get("dfn_templates", {}).get(str(did)) if did is not None else None
    if t is not None and t["size"]["kind"] == "power-law" and len(rows) > 1:
        lo, hi = t["size_limits"]
        a_hat = dfn_measure.powerlaw_mle(2 * r, float(lo), None if hi is None else float(hi))
        _put(session, "size_exponent", a_hat, suffix)
        session.write(f"power-law exponent of the diameters (maximum likelihood): {a_hat:.4f}")


@command("fracture intersections compute", keywords=[P("dfn", Text(), "only this DFN")],
         doc="Find the intersections between disks and the connected clusters they form.",
         details="Two disks intersect when their chords on the line common to their planes overlap. Clusters are "
                 "the connected components of the intersection graph (numbered from 0 by their first fracture, kept "
                 "per fracture: `fracture vtk` writes it). Results: `intersections`, `clusters`, "
                 "`largest_cluster` (fractures in the largest), `isolated` (fractures meeting no other).",
         examples=["fracture intersections compute", "fracture intersections compute dfn 'rock'"])
def intersections_compute(session, call):
    m = session.model
    rows, _ = _dfn_rows(session, call)
    c, n, r = _arrays(m, rows)
    lab, pairs = dfn_measure.clusters(c, n, r)
    FR.fracture_store(m)["cluster"][rows] = lab
    sizes = np.bincount(lab) if len(lab) else np.zeros(0, np.int64)
    res = {"intersections": len(pairs), "clusters": len(sizes), "largest_cluster": int(sizes.max()) if len(sizes) else 0,
           "isolated": int((sizes == 1).sum())}
    for k, v in res.items():
        session.results[k] = float(v)
    session.write(f"{res['intersections']} intersections, {res['clusters']} clusters (largest {res['largest_cluster']}"
                  f" fractures, {res['isolated']} isolated)")


@command("fracture list", keywords=[P("dfn", Text(), "only this DFN")],
         doc="List the DFNs and templates: fractures per set, sizes and orientations.",
         examples=["fracture list", "fracture list dfn 'rock'"])
def fracture_list(session, call):
    m = session.model
    st = FR.dfn_state(m)
    fs = FR.fracture_store(m)
    for name, t in st["templates"].items():
        session.write(f"template '{name}': set {t.get('set')}, orientation {t['orientation']['kind']}, "
                      f"size {t['size']['kind']}, size-limits {t['size_limits']}")
    rows, _ = _dfn_rows(session, call)
    for did in np.unique(fs["dfn"][rows]):
        sel = rows[fs["dfn"][rows] == did]
        session.write(f"DFN '{FR.dfn_name(m, did)}' (id {int(did)}): {len(sel)} fractures")
        for s in np.unique(fs["set"][sel]):
            q = sel[fs["set"][sel] == s]
            d, dd = FR.dips_from_normals(fs["normal"][q])
            session.write(f"  set {int(s)}: {len(q)} fractures, diameter {2 * fs['radius'][q].min():.4g}.."
                          f"{2 * fs['radius'][q].max():.4g}{unit(m, 'length')}, mean dip {math.degrees(d.mean()):.1f}")


@command("fracture delete", keywords=[P("dfn", Text(), "only this DFN")], range="fractures",
         doc="Delete the fractures in range (of one DFN, or all).",
         examples=["fracture delete", "fracture delete dfn 'rock'", "fracture delete range id-list 1 2 3"])
def fracture_delete(session, call):
    m = session.model
    FR.fracture_store(m)                      # (made empty when there is none: the range needs it)
    mask = session.range_mask(call, "fractures")
    rows, _ = _dfn_rows(session, call)
    rows = rows[mask[rows]]
    FR.delete(m, rows)
    session.write(f"{len(rows)} fractures deleted")


def _check_cut(call):
    from ..errors import BindError

    if (call.args["name"] is None) == (call.args["id"] is None):
        raise BindError("`block cut dfn` needs `name s` or `id i`", call.location)


@command("block cut dfn",
         keywords=[P("name", Text(), "cut with the DFN of this name"),
                   P("id", Num(integer=True, lo=1), "cut with the DFN of this id"),
                   P("jointset-id", Num(integer=True, lo=0), "joint-set id recorded on the new faces (default: "
                     "the DFN id); select their contacts with `range jointset-id i`"),
                   P("join", FLAG, "join the pieces of each block", bare=True)],
         range="block", check=_check_cut,
         doc="Cut the visible blocks in range by the disk fractures of a DFN.",
         details="3DEC's rule: blocks are split completely, no partial cracks; every block a disk touches is cut "
                 "through by the disk's whole plane (the joints made are larger than the disks), blocks the disk "
                 "does not reach are not cut. A disk touches a block when the block has corners on both sides "
                 "of its plane (beyond the tolerance) and the block's section by the plane comes within the "
                 "radius of the disk's centre. Disks are taken in order of generation; each cut is exact and a "
                 "plane within the tolerance (`block tolerance`) of a corner passes through it, so no piece is "
                 "thinner than the tolerance or of zero volume. The new faces record the joint-set id and the "
                 "fracture id (face fields `jointset`, `fracture`); pieces of them cut later keep them. Only "
                 "blocks whose box overlaps a disk's box are tested. Results: `blocks_made`, `fractures_used`, "
                 "`slivers_skipped`, `smallest_volume`, `volume_change` (relative change of the total volume of "
                 "the blocks cut, a check: round-off only).",
         examples=["block cut dfn name 'rock'", "block cut dfn id 1 jointset-id 3 range position-z 0 20"])
def block_cut_dfn(session, call):
    a = call.args
    m = session.model
    if a["name"] is not None:
        did = FR.dfn_id(m, a["name"], create=False)
        if did is None:
            raise CommandError(f"there is no DFN '{a['name']}'", call.locations.get("name", call.location))
    else:
        did = int(a["id"])
        if str(did) not in FR.dfn_state(m)["dfns"]:
            raise CommandError(f"there is no DFN {did}", call.locations.get("id", call.location))
    rows = FR.select(m, did)
    check_blocks(session, len(rows), "this DFN", call.location)
    mask = session.range_mask(call, "block")
    c, n, r = _arrays(m, rows)
    js = int(a["jointset_id"]) if a["jointset_id"] is not None else did
    FR.ensure_face_fields(m)
    vsel = mask & ~m.blocks["hidden"]
    v0 = float(m.blocks["volume"][vsel].sum())
    keep = {k: {f: a.copy() for f, a in m.stores[k].to_arrays().items()}     # (to_arrays may hand views)
            for k in ("blocks", "vertices", "faces", "face_vertices")}
    next_id = m.next_block_id
    cap = budget(session).max_blocks()
    try:
        made, used, skipped = cut_dfn(m, c.copy(), n.copy(), r.copy(), FR.fracture_store(m)["id"][rows].copy(), js,
                                      mask=mask, join=bool(a["join"]), max_blocks=cap,
                                      keep_whole=m.blocks["kind"] != KIND_RIGID)
    except GeometryError as exc:                   # a disk would split a zoned or FE block
        for k, arrs in keep.items():
            m.stores[k].load_arrays(arrs)
        m.next_block_id = next_id
        raise CommandError(f"{exc}; nothing was cut", call.location) from None
    except TooManyBlocks as exc:
        for k, arrs in keep.items():               # the model as it was before the command
            m.stores[k].load_arrays(arrs)
        m.next_block_id = next_id
        raise ResourceError(f"this DFN made {exc.blocks:,} blocks after {exc.done} of its {len(rows)} disks, over "
                            f"the budget of {cap:,} blocks; nothing was cut", call.location,
                            hint="raise it with `model budget blocks <n> memory <GiB>` if the machine has the "
                                 "memory") from None
    vol = m.blocks["volume"]
    # the pieces of the blocks cut: the blocks in range then, and the new rows
    after = np.concatenate([vsel, np.ones(m.blocks.n - len(vsel), bool)])
    session.results["volume_change"] = abs(float(vol[after].sum()) - v0) / v0 if v0 > 0 else 0.0
    session.results["blocks_made"] = float(made)
    session.results["fractures_used"] = float(used)
    session.results["slivers_skipped"] = float(skipped)
    session.results["smallest_volume"] = float(vol.min()) if len(vol) else 0.0
    session.write(f"{made} new blocks from {used} of {len(rows)} fractures (smallest block {vol.min():.4g}{unit(m, 'volume')}; "
                  f"{skipped} cuts not made: they would have left a sliver)")


@range_element("jointset-id", positional=[P("id", Num(integer=True), "joint-set id", required=True)],
               stores=("contact", "face"),
               doc="faces made by `block cut dfn` with this joint-set id, and the contacts lying on them")
def jointset_id(session, store, args):
    m = session.model
    f = m.faces
    want = int(args["id"])
    onset = (f["jointset"] == want) if "jointset" in f else np.zeros(f.n, bool)
    if store in ("face", "faces"):
        return onset
    cs = m.store("contacts")
    out = np.zeros(cs.n, bool)
    if not onset.any() or cs.n == 0:
        return out
    tol = max(float(m.tolerance), 1e-9)
    # a contact is on the joint set when a face of the set of either of its blocks holds its point,
    # parallel to its normal: every (contact, set face of one of its blocks) pair, vectorised
    rows = np.flatnonzero(onset)
    order = np.argsort(f["block"][rows], kind="stable")
    rows = rows[order]
    fb = f["block"][rows]
    for side in ("a", "b"):
        blk = cs[side]
        lo = np.searchsorted(fb, blk, side="left")
        hi = np.searchsorted(fb, blk, side="right")
        cnt = hi - lo
        if cnt.sum() == 0:
            continue
        k = np.repeat(np.arange(cs.n), cnt)
        start = np.repeat(lo - np.concatenate(([0], np.cumsum(cnt)[:-1])), cnt)
        fr = rows[start + np.arange(cnt.sum())]
        nf = f["normal"][fr]
        d = np.abs(np.einsum("ij,ij->i", nf, cs["pos"][k] - f["centroid"][fr]))
        par = np.abs(np.abs(np.einsum("ij,ij->i", nf, cs["normal"][k])) - 1) < 1e-6
        ok = (d <= 10 * tol + 1e-6 * np.sqrt(f["area"][fr])) & par
        out[k[ok]] = True
    return out
