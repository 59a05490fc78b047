"""Contacts and sub-contacts of rigid blocks: their stores and their detection (3DEC theory,
"A Scheme to Detect and Represent Contacts in 3D", "Interaction between Blocks").

Detection (``ContactDetection.detect``; the engine calls it every ``model update-interval``
steps, default 10, and as soon as a block has moved CTOL/2 since the last one):
  1. neighbour search by cell mapping (kernel ``cellmap``) of the block envelopes enlarged
     by CTOL on each side (a search volume 2·CTOL larger, as the text says) and by each
     block's step motion, redone only when a vertex has moved more than CTOL/2 since the
     last map (the text's u_acc > CTOL, halved so that two blocks moving towards each other
     cannot both slip past), or the blocks changed; the cell space is made anew, 10 %
     larger than the blocks, when a block leaves it;
  2. the common plane of every candidate pair (kernel ``contactmap.cp_batch``: fast path
     from the previous plane, face snap); a pair is a contact while its gap is at most
     CTOL plus the distance its two blocks can close in one step;
  3. sub-contacts of every contact (kernel ``subgeom``), their state carried over from the
     previous pass by identity (kernel ``contactmap.carry_over``); a sub-contact without
     a twin starts from its own gap (kernel ``contactmap.subcontact_gaps``).
  Pairs whose blocks have both moved less than QUIET·CTOL since they were last looked at
  keep their contact and sub-contacts as they are.
On more than one thread (``model configure threads``) the sub-contacts are found chunk by
chunk and gathered piece by piece on Python threads (``in_threads``, kernels compiled
``nogil``), joined in their order: the same rows, bit for bit, as one thread.

Contacts are oriented from the block with the lower id (A) to the higher (B) and sorted
by (id A, id B); that key finds a contact again after blocks are deleted or cut.
"""
from __future__ import annotations

import threading
import time as _time

import numpy as np
from numba import get_num_threads

from dec3d.kernels.cellmap import cell_grid, cell_pairs, outside_grid
from dec3d.kernels import contactmap as _cm
from dec3d.kernels.contactmap import (blocks_moved, carry_over, cp_batch, envelopes, gather_subcontacts, match_sorted,
                                      subcontact_gaps, threaded, vertex_point_areas)
from dec3d.kernels.kept import add_turns, as_they_are, pairs_to_look_at, take_defaults
from dec3d.kernels.joints import MODELS, NPROP, model_mask
from dec3d.kernels.subgeom import subcontacts_batch
from dec3d.model.model import KIND_DEFORMABLE, KIND_FE, KIND_RIGID
from dec3d.model.ranges import pairs_in_groups

from .contact_store import history_columns, property_columns
from .jmodels import JOINT_MODELS, MODEL_BY_CODE
from .water import refresh as refresh_pore_pressure

_I = np.int64

#: engine settings (``model.settings.mechanical``) and their defaults

#: a block is looked at again at a detection when a vertex has moved more than QUIET × CTOL
#: since it was last looked at (dec3d's choice; areas and planes change by ~QUIET·CTOL/size)
QUIET = 0.1

#: contacts between rigid blocks follow the relative rule (``detect``): kept while their blocks have
#: moved (and turned) less than QUIET·CTOL relative to each other (a stack settling or sliding as one)
RELATIVE = True

#: property columns each joint-model code reads
_NCOLS = {m.CODE: m.NCOLS for m in MODELS}
#: the sub-contact fields a detection writes (``contactmap.gather_subcontacts``), in its order
_GATHERED = ("contact", "kind", "key0", "key1", "pos", "area", "fn", "fs", "un", "udil", "us", "state", "hist")


def in_threads(work, nitems: int, nthreads: int) -> None:
    """Call ``work(j)`` for j = 0 .. nitems-1 on ``nthreads`` threads (this one and nthreads-1
    started here), each taking the next j when it is free. ``work`` calls kernels compiled with
    ``nogil`` (they run side by side, outside numba's threading layer, and need no parallel
    twin: nothing compiles again) and writes only its own results; the first error is raised."""
    items = iter(range(nitems))     # (next() on a range iterator is atomic under the GIL)
    errors = []

    def loop():
        try:
            for j in items:
                work(j)
        except BaseException as exc:  # noqa: BLE001 - re-raised in the calling thread below
            errors.append(exc)

    extra = [threading.Thread(target=loop, daemon=True) for _ in range(min(nthreads, nitems) - 1)]
    for t in extra:
        t.start()
    loop()
    for t in extra:
        t.join()
    if errors:
        raise errors[0]


def _subcontacts_chunk(vpos, b, f, fv, ra, rb, cn, cc, ctol, parea):
    """Sub-contacts of the contacts (ra, rb, cn, cc) (kernel ``subgeom.subcontacts_batch``, its
    output grown until it fits); contact indices local to these contacts."""
    cap = max(16, 8 * len(ra))
    while True:
        out = (np.empty(cap, _I), np.empty(cap, _I), np.empty(cap, _I), np.empty(cap, _I),
               np.empty((cap, 3)), np.empty(cap))
        k = subcontacts_batch(vpos, b["vert_start"], b["vert_count"], b["face_start"], b["face_count"],
                              f["vstart"], f["nvert"], fv["vertex"], ra, rb, cn, cc, ctol, parea, *out)
        if k <= cap:
            return tuple(a[:k] for a in out)
        cap = int(k)


#: contacts per chunk are at least this many; a pass has about CHUNKS_PER_THREAD chunks per thread
#: (threads that finish early take the next chunk: a busy core holds up less)
CHUNK_MIN = 128
CHUNKS_PER_THREAD = 4


def _subcontacts(vpos, b, f, fv, ra, rb, cn, cc, ctol, parea, nthreads=None):
    """Sub-contacts of every contact, ordered by contact: from ``contactmap.PARALLEL_FROM`` contacts on
    more than one thread the contacts are cut into chunks, each chunk's sub-contacts found on
    its own (``_subcontacts_chunk``: the kernel keeps no state from one contact to the next) on
    the threads side by side, and the chunks joined in their order: the same rows as one pass."""
    n = len(ra)
    nt = get_num_threads() if nthreads is None else nthreads
    if n < _cm.PARALLEL_FROM or nt < 2:
        return _subcontacts_chunk(vpos, b, f, fv, ra, rb, cn, cc, ctol, parea)
    nchunk = int(min(nt * CHUNKS_PER_THREAD, max(nt, n // CHUNK_MIN)))
    bounds = np.linspace(0, n, nchunk + 1).astype(_I)
    parts = [None] * nchunk

    def work(j):
        lo, hi = bounds[j], bounds[j + 1]
        parts[j] = _subcontacts_chunk(vpos, b, f, fv, ra[lo:hi], rb[lo:hi], cn[lo:hi], cc[lo:hi], ctol, parea)

    in_threads(work, nchunk, nt)
    for j in range(1, nchunk):
        parts[j][0][...] += bounds[j]
    return tuple(np.concatenate([p[i] for p in parts]) for i in range(6))


def zoned_side_carries(sc_contact, kind, area, za, zb) -> None:
    """Face-face sub-contacts of a contact between a zoned block and a rigid one: the zoned
    side's gridpoints (and the edge crossings) carry the whole area, the rigid face's vertices
    none (their ``area`` set to 0, dropped by the caller), in place.

    The face-face rule (``kernels.subgeom``) gives both sides' vertices half the overlap each,
    a vertex's share being a third of each fan triangle of its face. A zoned face is the zone
    surface triangles, so its gridpoint shares are the consistent load of a uniform pressure on
    linear triangles (area/3 per corner). A rigid face's shares follow the fan of its loop (a
    square's corners 1/3, 1/6, 1/3, 1/6 of its area) and its corner forces reach the zoned
    face's gridpoints by the interpolation weights as point loads at the rigid corners: a rigid
    block on a laterally confined zoned column then settled 3.3 % more than under the uniform
    load its rigid face imposes. The rigid side is dropped only where the zoned side holds at
    least a quarter of the overlap, half of its own half (a rigid face inside one zone triangle
    keeps its corners, else it would have no spring at all); the kept areas are scaled back to
    the overlap's total.

    sc_contact (ns,) contact index of each sub-contact; kind (ns,) 0 A-vertex, 1 B-vertex,
    2 edge-edge, 3 point; area (ns,) [m²] changed; za, zb (nc,) whether A, B are zoned."""
    one = np.asarray(za, bool) != np.asarray(zb, bool)
    if not one.any() or len(sc_contact) == 0:
        return
    c = sc_contact
    face = one[c] & (kind <= 2)
    rigid_kind = np.where(za, 1, 0)[c]          # A zoned: B's vertices (kind 1) are the rigid face's
    drop = face & (kind == rigid_kind)
    keep = face & ~drop
    nc = len(one)
    tot = np.bincount(c[face], weights=area[face], minlength=nc)
    kept = np.bincount(c[keep], weights=area[keep], minlength=nc)
    ok = one & (tot > 0.0) & (kept >= 0.25 * tot)
    scale = np.where(ok, tot / np.where(kept > 0.0, kept, 1.0), 1.0)
    area[drop & ok[c]] = 0.0
    sel = keep & ok[c]
    area[sel] *= scale[c[sel]]


def joined_zoned_inert(sc_c, area, zoned, leader, ra, rb) -> None:
    """Contacts between two zoned (or two FE) blocks of one joined set (``block join``) carry no force: the
    blocks share their gridpoints there (linked rows), so their sub-contacts get area 0 (dropped
    by the caller), in place. sc_c (ns,) contact index of each sub-contact; area (ns,) [m²];
    zoned (nb,) bool; leader (nb,) row of the leader (-1 or itself: not joined); ra, rb (nc,) rows."""
    if not len(sc_c):
        return
    lead = np.where(leader < 0, np.arange(len(leader)), leader)
    inert = zoned[ra] & zoned[rb] & (lead[ra] == lead[rb])
    area[inert[sc_c]] = 0.0


def default_row(s: dict, code: int, width: int = NPROP) -> np.ndarray:
    """Property row of a contact of model ``code`` that follows the material-table defaults
    (the default properties this model has), ``width`` columns (``JointModel.row``)."""
    jm = MODEL_BY_CODE[code]
    return jm.row({k: v for k, v in s["props"].items() if k in jm.props}, width)


def apply_material_tables(model, tables, new, ra, rb, jcode, prop, own) -> None:
    """Give new contacts (mask ``new``; block rows ``ra``, ``rb``) the model and properties of the
    last `material-table add` entry whose group pair they join (an entry without groups: any pair)."""
    for t in tables:
        jm = JOINT_MODELS[t["jmodel"]]
        hit = new.copy()
        if t.get("groups"):
            hit &= pairs_in_groups(model, ra, rb, t["groups"][0], t["groups"][1], t.get("slot"))
        if hit.any():
            jcode[hit] = jm.code
            prop[hit] = jm.row(t["props"], prop.shape[1])
            own[hit] = 1


class ContactDetection:
    """The detection half of the rigid engine (mixed into ``rigid.RigidEngine``, which
    provides ``model``, ``dt``, ``timings``, ``settings()``, ``tolerance()``,
    ``point_area()``, ``contacts`` and ``subcontacts``).
    """

    # Detection state that must survive save/restore (so a restored run continues exactly):
    # vertex fields ``map_pos`` (positions at the last cell map) and ``look_pos`` (when the
    # block was last looked at), settings ``grid`` (the cell space) and ``signature`` (the
    # blocks at the last detection). The candidate pairs are rebuilt from ``map_pos``.
    def _geometry_signature(self):
        m = self.model
        b = m.blocks
        return [b.n, m.vertices.n, m.faces.n, int(b["id"].sum()), int(b["hidden"].sum())]

    @property
    def _signature(self):
        return self.settings().get("signature")

    @_signature.setter
    def _signature(self, sig):
        self.settings()["signature"] = sig

    def _radii(self) -> np.ndarray:
        """Per block, the largest centroid-to-vertex distance [m]."""
        b, v = self.model.blocks, self.model.vertices
        r = np.zeros(b.n)
        if v.n:
            np.maximum.at(r, v["block"], np.linalg.norm(v["pos"] - b["centroid"][v["block"]], axis=1))
        return r

    def _step_motion(self) -> np.ndarray:
        """Per block, how far its vertices can move in one step at the current velocities
        (|v| Δt + |ω| Δt r) [m]; 0 before a run."""
        b = self.model.blocks
        if not self.dt or b.n == 0:
            return np.zeros(b.n)
        return self.dt * (np.linalg.norm(b["velocity"], axis=1) + self._radii() * np.linalg.norm(b["spin"], axis=1))

    def _pairs(self, pos, ctol, grid):
        """Candidate pairs of blocks whose envelopes (vertex positions ``pos``) enlarged by
        CTOL and by their step motion at the map (block field ``map_reach``) overlap, by cell
        mapping; rows with A the lower block id, sorted by ids."""
        b = self.model.blocks
        active = ~b["hidden"] & (b["vert_count"] > 0)
        lo = np.empty((b.n, 3))
        hi = np.empty((b.n, 3))
        envelopes(pos, b["vert_start"], b["vert_count"], active, ctol, lo, hi)
        lo -= b["map_reach"][:, None]
        hi += b["map_reach"][:, None]
        if grid is None or outside_grid(lo, hi, active, *grid):
            grid = cell_grid(lo, hi, active, 0.1)
        pairs = cell_pairs(lo, hi, active, *grid)
        ida, idb = b["id"][pairs[:, 0]], b["id"][pairs[:, 1]]
        swap = ida > idb
        ra = np.where(swap, pairs[:, 1], pairs[:, 0]).astype(_I)
        rb = np.where(swap, pairs[:, 0], pairs[:, 1]).astype(_I)
        order = np.lexsort((b["id"][rb], b["id"][ra]))
        return (np.ascontiguousarray(ra[order]), np.ascontiguousarray(rb[order])), grid

    def _search(self, ctol: float, force: bool) -> tuple[tuple[np.ndarray, np.ndarray], bool]:
        """(candidate pairs, whether the cell space was mapped anew), remapped only when
        a vertex has moved more than CTOL/2 since the last map, or when forced."""
        m = self.model
        s = self.settings()
        v = m.vertices
        vpos, mpos = v["pos"], v["map_pos"]
        have = s.get("grid") is not None and len(vpos) > 0
        if have and not force and self._cand is None:    # after a restore: the same pairs from the saved map
            g = s["grid"]
            self._cand, _ = self._pairs(mpos, ctol, (np.array(g[0]), float(g[1]), np.array(g[2], _I)))
        if have and not force and float(np.abs(vpos - mpos).max()) <= 0.5 * ctol:
            return self._cand, False
        t0 = _time.perf_counter()
        self._cand_before = self._cand           # (detect looks at the pairs that are new candidates)
        g = s.get("grid")
        grid = None if (g is None or force) else (np.array(g[0]), float(g[1]), np.array(g[2], _I))
        m.blocks["map_reach"][...] = self._step_motion()
        self._cand, grid = self._pairs(vpos, ctol, grid)
        s["grid"] = [[float(x) for x in grid[0]], float(grid[1]), [int(x) for x in grid[2]]]
        mpos[...] = vpos
        self.timings["search"] += _time.perf_counter() - t0
        return self._cand, True

    def _turned(self, changed: bool) -> np.ndarray:
        """Block field ``turn`` [m] brought up to now (``kept.add_turns``; blocks changed: only
        the references are set)."""
        b, v = self.model.blocks, self.model.vertices
        if changed:
            v["turn_pos"][...] = v["pos"]
            b["turn_cen"][...] = b["centroid"]
        else:
            add_turns(b["turn"], v["turn_pos"], b["turn_cen"], v["pos"], b["centroid"], b["vert_start"],
                      b["vert_count"])
        return b["turn"]

    def detect(self, force_search: bool = False) -> None:
        """Find the contacts and their sub-contacts again, keeping the force history.

        Incremental: a candidate pair whose two blocks have each moved less than
        ``QUIET`` × CTOL (largest vertex displacement) since they were last looked at keeps
        its contact and sub-contacts as they are (their points still follow Eq. 11 every
        step); every other pair gets a new common plane and new sub-contacts. With ``RELATIVE``
        a contact between two rigid blocks follows the relative rule instead: it is kept while
        |Δc_B − Δc_A| + Δturn_A + Δturn_B < QUIET × CTOL since it was computed (centroid
        displacements and turns, ``_turned``: the normal is not turned between detections,
        so blocks turning together have theirs recomputed). After a
        remap of the cell space the pairs that were not candidates before are looked at
        too; after a change of the blocks, or with ``force_search``, every pair is.
        """
        t0 = _time.perf_counter()
        m = self.model
        b, f, fv = m.blocks, m.faces, m.face_vertices
        cs, ss = self.contacts, self.subcontacts
        sig = self._geometry_signature()
        changed = sig != self._signature
        self._signature = sig
        ctol = self.tolerance()
        vpos = m.vertices["pos"]
        look = m.vertices["look_pos"]
        geometry, self._cand_before = force_search or changed, None
        (ra, rb), remapped = self._search(ctol, geometry)
        turn = self._turned(changed)
        cen = b["centroid"]
        ids = b["id"]
        # after a remap alone, the pairs that were candidates before follow the rules below as well
        before = self._cand_before
        full = geometry or (remapped and before is None)
        if full:
            moved = np.ones(b.n, bool)
        else:
            moved = np.zeros(b.n, bool)
            blocks_moved(vpos, look, b["vert_start"], b["vert_count"], QUIET * ctol, moved)
        prev = match_sorted(cs["ida"], cs["idb"], ids[ra], ids[rb])
        look_at = np.empty(len(ra), bool)
        # contacts between rigid blocks (``RELATIVE``): kept while their blocks moved little relative to each other
        relative = (b["kind"] == KIND_RIGID) if RELATIVE and not full else np.zeros(b.n, bool)
        pairs_to_look_at(ra, rb, prev, moved, relative, cen, cs["ref_ca"], cs["ref_cb"], turn, cs["ref_ta"],
                         cs["ref_tb"], QUIET * ctol, look_at)
        if remapped and not full:
            look_at |= match_sorted(ids[before[0]], ids[before[1]], ids[ra], ids[rb]) < 0
        need = np.flatnonzero(look_at)
        k = len(need)
        #: candidate pairs the last detection looked at again (common plane and sub-contacts anew)
        self.looked_at = k
        if not full and k == 0 and self._as_they_are(ra, rb, prev):
            # nothing to look at again and every contact kept in place: all the install below would
            # change is the properties of contacts that follow the defaults (a quiet model's
            # first detection of a run; on a large model the gathers cost ~2 % of a short run)
            # (as the full install below says it: every contact kept, with the same properties)
            self.detect_kept_all = not self.follow_defaults()
            self.timings["detect"] += _time.perf_counter() - t0
            return
        nn = np.empty((k, 3))
        cc = np.empty((k, 3))
        gap = np.empty(k)
        ctype = np.empty(k, _I)
        # a pair is a contact when its gap is at most CTOL plus what its blocks can close in
        # one step: fast blocks get their contact (still open) before they meet
        step = self._step_motion()
        reach = ctol + step[ra[need]] + step[rb[need]]
        threaded(cp_batch, k)(ra[need], rb[need], prev[need], vpos, b["vert_start"], b["vert_count"],
                              b["centroid"], cs["normal"], cs["pos"], reach, nn, cc, gap, ctype)
        # the contacts: quiet old contacts as they were, looked-at pairs with gap ≤ CTOL
        is_new = np.zeros(len(ra), bool)
        is_new[need[ctype > 0]] = True
        kept = (prev >= 0) & ~look_at
        rows = np.flatnonzero(kept | is_new)
        local = np.full(len(ra), -1, _I)
        local[need] = np.arange(k)
        fresh = need[ctype > 0]                 # candidate indices of recomputed contacts, in order
        nc = len(rows)
        ra_c, rb_c, prev_c = ra[rows], rb[rows], prev[rows]
        kept_c = kept[rows]
        lc = local[rows]
        p_k = prev_c[kept_c]
        normal = np.empty((nc, 3))
        cpos = np.empty((nc, 3))
        cgap = np.empty(nc)
        ctyp = np.empty(nc, _I)
        normal[kept_c], cpos[kept_c], cgap[kept_c], ctyp[kept_c] = (cs["normal"][p_k], cs["pos"][p_k],
                                                                   cs["gap"][p_k], cs["type"][p_k])
        ref_ca, ref_cb, ref_ta, ref_tb = cen[ra_c], cen[rb_c], turn[ra_c], turn[rb_c]
        ref_ca[kept_c], ref_cb[kept_c], ref_ta[kept_c], ref_tb[kept_c] = (cs["ref_ca"][p_k], cs["ref_cb"][p_k],
                                                                          cs["ref_ta"][p_k], cs["ref_tb"][p_k])
        lf = lc[~kept_c]
        normal[~kept_c], cpos[~kept_c], cgap[~kept_c], ctyp[~kept_c] = nn[lf], cc[lf], gap[lf], ctype[lf]
        # contact data carried by the pair key, or the defaults for a new contact
        s = self.settings()
        old = prev_c >= 0
        jm = JOINT_MODELS[s["jmodel"]]
        jcode = np.full(nc, jm.code, _I)
        group = np.full((nc, cs["group"].shape[1]), -1, np.int32)
        own = np.zeros(nc, np.uint8)
        jcode[old] = cs["jmodel"][prev_c[old]]
        own[old] = cs["own_props"][prev_c[old]]
        keep_row = old & (own == 1)
        follow = ~keep_row                 # new contacts and old ones that follow the defaults
        codes = np.unique(jcode[follow])
        tables = s.get("mtables") if not old.all() else None      # `block contact material-table add` entries
        # the property rows hold the columns the models in use read, no more (``property_columns``):
        # every contact's row is copied here at each detection
        mask = model_mask(jcode)
        for t in tables or ():
            mask |= 1 << JOINT_MODELS[t["jmodel"]].code
        width = property_columns(cs, mask)
        # (each row written once: a model of one joint model following its defaults is one broadcast)
        prop = np.empty((nc, width))
        if len(codes) == 1 and follow.all():
            prop[:] = default_row(s, int(codes[0]), width)
        else:
            prop[keep_row] = cs["prop"][prev_c[keep_row]]
            for code in codes:
                prop[follow & (jcode == code)] = default_row(s, int(code), width)
        group[old] = cs["group"][prev_c[old]]
        pp_apply = np.zeros(nc)
        pp_apply[old] = cs["pp_apply"][prev_c[old]]
        extra = {}
        if "aperture" in cs:                       # a flow plane's own apertures (physics.flownet)
            extra["aperture"] = np.full((nc, 3), -1.0)
            extra["aperture"][old] = cs["aperture"][prev_c[old]]
        if tables:
            apply_material_tables(m, tables, ~old, ra_c, rb_c, jcode, prop, own)
        # sub-contacts of the recomputed contacts (zero-area ones carry nothing and are dropped)
        t1 = _time.perf_counter()
        f_ra, f_rb, f_prev = ra[fresh], rb[fresh], prev[fresh]
        f_n, f_c, f_gap = nn[local[fresh]], cc[local[fresh]], gap[local[fresh]]
        sc_c, kind, key0, key1, pos, area = _subcontacts(vpos, b, f, fv, f_ra, f_rb, f_n, f_c, ctol,
                                                         self.point_area())
        vertex_point_areas(sc_c, kind, key0, ctype[local[fresh]], f_n, vpos, m.vertices["block"],
                           b["face_start"], b["face_count"], f["vstart"], f["nvert"], fv["vertex"],
                           self.point_area(), area)
        zoned = b["kind"] == KIND_DEFORMABLE
        # FE blocks are deformable sides too: against a zoned or an FE block both sides' surface
        # nodes carry half (the two spring sets of the zoned pair); against a rigid block the FE side all
        deform = zoned | (b["kind"] == KIND_FE)
        if deform.any():
            zoned_side_carries(sc_c, kind, area, deform[f_ra], deform[f_rb])
            joined_zoned_inert(sc_c, area, zoned, b["leader"], f_ra, f_rb)
            # two FE blocks of one joined set share their nodes as well (``zone_mesh.relink``)
            joined_zoned_inert(sc_c, area, b["kind"] == KIND_FE, b["leader"], f_ra, f_rb)
        live = area > 0.0
        if not live.all():
            sc_c, kind, key0, key1, pos, area = (x[live] for x in (sc_c, kind, key0, key1, pos, area))
        ns = len(sc_c)
        sgap = np.empty(ns)
        threaded(subcontact_gaps, ns)(sc_c, pos, f_ra, f_rb, f_n, f_gap, b["centroid"], vpos, b["face_start"],
                                      b["face_count"], f["vstart"], f["nvert"], fv["vertex"], sgap)
        fs = np.empty((ns, 3))
        un = np.empty(ns)
        udil = np.empty(ns)
        us = np.empty((ns, 3))
        state = np.empty(ns, _I)
        # the joint models' history goes along only while a model in use keeps one (no columns otherwise)
        history_columns(ss, np.concatenate((jcode, cs["jmodel"])))
        hist = np.empty((ns, ss.fields["hist"].shape[0]))
        olds = (cs["sub_start"], cs["sub_count"], ss["kind"], ss["key0"], ss["key1"], ss["area"], ss["fs"], ss["un"],
                ss["udil"], ss["us"], ss["state"], ss["hist"], cs["normal"], f_n)
        nt = get_num_threads() if ns >= _cm.PARALLEL_FROM else 1
        cut = np.linspace(0, ns, nt + 1).astype(_I)       # (each sub-contact's state is its own: rows apart)
        in_threads(lambda j: carry_over(f_prev, *(x[cut[j]:cut[j + 1]] for x in (sc_c, kind, key0, key1, area, sgap)),
                                        *olds, *(x[cut[j]:cut[j + 1]] for x in (fs, un, udil, us, state, hist))), nt, nt)
        nf = len(fresh)
        f_count = np.bincount(sc_c, minlength=nf).astype(_I) if nf else np.zeros(0, _I)
        f_start = (np.cumsum(f_count) - f_count).astype(_I)
        # gather: kept contacts take their old rows, recomputed ones the new rows
        fidx = np.full(len(ra), -1, _I)
        fidx[fresh] = np.arange(nf)
        fi = fidx[rows]
        counts = np.empty(nc, _I)
        base = np.empty(nc, _I)
        counts[kept_c], base[kept_c] = cs["sub_count"][p_k], cs["sub_start"][p_k]
        counts[~kept_c], base[~kept_c] = f_count[fi[~kept_c]], ss.n + f_start[fi[~kept_c]]
        starts = (np.cumsum(counts) - counts).astype(_I)
        total = int(counts.sum())
        # nothing recomputed and every old sub-contact kept in place (a quiet model): the rows
        # stay as they are (the gather below would copy each of them onto itself)
        same = nf == 0 and total == ss.n and np.array_equal(base, starts)
        if not same:
            # straight into new arrays (the old rows are read from the store's own), installed below
            gathered = ss.blank(total, _GATHERED)
            old_rows = tuple(ss[key] for key in _GATHERED[1:])
            new_rows = (kind, key0, key1, pos, area, fs, un, udil, us, state, hist)
            out = tuple(gathered[key] for key in _GATHERED)
            nt = get_num_threads() if total >= _cm.PARALLEL_FROM else 1
            cut = np.linspace(0, nc, nt + 1).astype(_I)
            in_threads(lambda j: gather_subcontacts(cut[j], cut[j + 1], base, starts, counts, ss.n, old_rows, new_rows,
                                                    out), nt, nt)
        self.timings["subcontacts"] += _time.perf_counter() - t1
        #: whether this detection kept every contact and sub-contact as it was, with the same
        #: properties (density scaling by body then keeps its masses: ``steps._Run.detected``)
        self.detect_kept_all = (not full and k == 0 and same and nc == cs.n and np.array_equal(prev_c, np.arange(nc))
                                and np.array_equal(prop, cs["prop"], equal_nan=True) and np.array_equal(jcode, cs["jmodel"]))
        # install
        self.detections += 1
        values = {"ida": ids[ra_c], "idb": ids[rb_c], "a": ra_c, "b": rb_c, "pos": cpos, "normal": normal,
                  "gap": cgap, "type": ctyp, "jmodel": jcode, "prop": prop, "own_props": own, "sub_start": starts,
                  "sub_count": counts, "group": group, "ref_ca": ref_ca, "ref_cb": ref_cb, "ref_ta": ref_ta,
                  "ref_tb": ref_tb, "pp_apply": pp_apply, **extra}
        rows_new = cs.blank(nc, values)         # (the other fields get their fill value)
        for key, val in values.items():
            rows_new[key][:nc] = val
        cs.install(nc, rows_new)
        if same:
            ss["contact"][...] = np.repeat(np.arange(nc, dtype=_I), counts)
        else:
            ss.install(total, gathered)
        refresh_pore_pressure(self)         # (the sub-contacts' pore pressure from its sources)
        # the blocks looked at are the new reference for "moved"
        if full:
            look[...] = vpos
        else:
            sel = moved[m.vertices["block"]]
            look[sel] = vpos[sel]
        self.timings["detect"] += _time.perf_counter() - t0

    def _as_they_are(self, ra, rb, prev) -> bool:
        """Whether the candidate pairs (ra, rb) with old contact rows prev (−1: none) hold every
        contact, in its row, on its blocks' rows, with the sub-contacts in contact order."""
        cs = self.contacts
        return bool(as_they_are(prev, ra, rb, cs["a"], cs["b"], cs["sub_start"], cs["sub_count"], self.subcontacts.n))

    def follow_defaults(self) -> bool:
        """Contacts that follow the material-table defaults (``own_props`` 0) take them now, as a
        detection would (for runs in which no detection is due: zoned blocks alone in small strain).
        Returns whether a property changed."""
        cs = self.contacts
        if not cs.n:
            return False
        s = self.settings()
        width = cs["prop"].shape[1]
        table = np.zeros((max(MODEL_BY_CODE) + 1, width))
        for code in MODEL_BY_CODE:                 # (a model wider than the rows is not in use)
            if _NCOLS[code] <= width:
                table[code] = default_row(s, code, width)
        return take_defaults(cs["own_props"], cs["jmodel"], cs["prop"], table) > 0

    def ensure_contacts(self) -> None:
        """Detect now if the blocks changed since the last detection (3DEC keeps contacts
        current whenever blocks exist, so contact commands see them before any cycle)."""
        if self._geometry_signature() != self._signature:
            self.detect()
            # the blocks changed between runs: the next run works its Δt out afresh instead of
            # going on with the last run's (``_Run``: a run continuing where one ended)
            self.settings()["dt_run"] = []
