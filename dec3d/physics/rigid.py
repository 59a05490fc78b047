"""Rigid-block engine: neighbour search, contacts, sub-contacts and the cycle (3DEC theory, Fig. 13).

State lives in the model: contacts and sub-contacts are two stores (``contacts``,
``subcontacts``, saved and restored with the rest), the engine settings and detection
bookkeeping are ``model.settings.mechanical`` (plain JSON) and a few vertex/block fields.
The ``RigidEngine`` object on the model holds only what can be rebuilt: the candidate
pairs, the time step and timings. A restored run continues bit for bit.

Detection (every ``model update-interval`` steps, default 10, and as soon as a block has
moved CTOL/2 since the last one):
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
     previous pass by identity (kernel ``contactmap.carry_over``).
  Pairs whose blocks have both moved less than QUIET·CTOL since they were last looked at
  keep their contact and sub-contacts as they are.
Cycling (kernel ``cycle.run_steps``): many steps per call, up to the next detection,
history sample, VTK snapshot or solve check.

Contacts are oriented from the block with the lower id (A) to the higher (B) and sorted
by (id A, id B); that key finds a contact again after blocks are deleted or cut.
"""
from __future__ import annotations

import math
import sys
import time as _time

import numpy as np

from dec3d.errors import Dec3dError
from dec3d.kernels.cellmap import cell_grid, cell_pairs, outside_grid
from dec3d.kernels.contactmap import (blocks_moved, carry_over, cp_batch, envelopes, match_sorted,
                                      vertex_point_areas)
from dec3d.kernels.cycle import run_steps
from dec3d.kernels.jointlaw import NPROP, P_KN, P_KS
from dec3d.kernels.motion import DAMP_ADAPTIVE, DAMP_COMBINED, DAMP_LOCAL, DAMP_NONE, NSERVO, S_HIST, block_timestep
from dec3d.kernels.subgeom import subcontacts_batch
from dec3d.io.vtk import periodic_vtk
from dec3d.model.groups import group_field
from dec3d.model.store import Field, Store

from .bodies import group_properties, inertial_masses, new_servo
from .jmodels import JOINT_MODELS, MODEL_BY_CODE

_F = np.float64
_I = np.int64

CONTACT_FIELDS = {
    "ida": Field((), _I, -1),            # block ids, A < B
    "idb": Field((), _I, -1),
    "a": Field((), _I, -1),              # block rows (refreshed at every detection)
    "b": Field((), _I, -1),
    "pos": Field((3,), _F, 0.0),         # c-p reference point [m]
    "normal": Field((3,), _F, 0.0),      # unit normal A → B
    "gap": Field((), _F, 0.0),           # [m], negative = overlap
    "type": Field((), _I, 0),            # CT_* (kernels.commonplane)
    "jmodel": Field((), _I, 1),          # joint model code (physics.jmodels)
    "prop": Field((NPROP,), _F, 0.0),    # kernel property row
    "own_props": Field((), np.uint8, 0), # 1: set by `block contact property`; 0: follows the defaults
    "sub_start": Field((), _I, 0),       # CSR into subcontacts
    "sub_count": Field((), _I, 0),
    "group": group_field(),
}

SUBCONTACT_FIELDS = {
    "contact": Field((), _I, -1),
    "kind": Field((), _I, 0),            # 0 A-vertex/B-face, 1 B-vertex/A-face, 2 edge-edge, 3 point
    "key0": Field((), _I, -1),
    "key1": Field((), _I, -1),
    "pos": Field((3,), _F, 0.0),         # on the c-p [m]
    "area": Field((), _F, 0.0),          # [m²]
    "fn": Field((), _F, 0.0),            # normal force, compression positive [N]
    "fs": Field((3,), _F, 0.0),          # shear force on B [N]
    "un": Field((), _F, 0.0),            # normal displacement (starts at the gap) [m]
    "udil": Field((), _F, 0.0),          # dilation [m]
    "us": Field((3,), _F, 0.0),          # accumulated shear displacement [m]
    "state": Field((), _I, 0),           # ST_* bits (kernels.jointlaw)
}

#: engine settings (``model.settings.mechanical``) and their defaults
MECH_DEFAULTS = {
    "ctol": None,              # CTOL [m]; None: 0.005 × mean block size (dec3d's choice)
    "damping": "local",        # local | combined | global | none
    "alpha": 0.8,              # local / combined damping coefficient
    "frac": 0.1,               # Eq. (87)
    "timestep": None,          # fixed Δt [s] or None
    "jmodel": "mohr",          # model of contacts created from now on
    "props": {},               # their properties (user units)
    "mass_scale": "auto",      # on | off | auto (on while damping is not none: static runs)
    "inertia": "auto",         # full | scalar | auto (full, with Euler's equations, when damping is none)
    "servo": [],               # adaptive global damping state (kernels.motion, first NSERVO entries)
    "servo_ratio": 0.5,        # its target ratio
    "scale_timestep": None,    # Δt wanted with density scaling [s] (None: Eq. 87, median body)
}


#: a block is looked at again at a detection when a vertex has moved more than QUIET × CTOL
#: since it was last looked at (dec3d's choice; areas and planes change by ~QUIET·CTOL/size)
QUIET = 0.1


class RunError(Dec3dError):
    """The run became unstable (NaN or runaway velocity)."""


def mech(model) -> dict:
    """The model's engine settings, with every default filled in."""
    m = model.settings.mechanical
    for k, v in MECH_DEFAULTS.items():
        if k not in m:
            m[k] = dict(v) if isinstance(v, dict) else v
    return m


def contact_stores(model) -> tuple[Store, Store]:
    """The ``contacts`` and ``subcontacts`` stores, made on first use."""
    stores = model.stores
    if "contacts" not in stores:
        model.add_store(Store("contacts", CONTACT_FIELDS, capacity=64))
    if "subcontacts" not in stores:
        model.add_store(Store("subcontacts", SUBCONTACT_FIELDS, capacity=256))
    return model.store("contacts"), model.store("subcontacts")


def _subcontacts(vpos, b, f, fv, ra, rb, cn, cc, ctol, parea):
    """Sub-contacts of every contact (kernel ``subgeom.subcontacts_batch``, grown until it fits)."""
    cap = max(16, 8 * len(ra))
    while True:
        out = (np.empty(cap, _I), np.empty(cap, _I), np.empty(cap, _I), np.empty(cap, _I),
               np.empty((cap, 3)), np.empty(cap))
        k = subcontacts_batch(vpos, b["vert_start"], b["vert_count"], b["face_start"], b["face_count"],
                              f["vstart"], f["nvert"], fv["vertex"], ra, rb, cn, cc, ctol, parea, *out)
        if k <= cap:
            return tuple(a[:k] for a in out)
        cap = int(k)


def default_row(s: dict, code: int) -> np.ndarray:
    """Property row of a contact of model ``code`` that follows the material-table defaults
    (the default properties this model has)."""
    jm = MODEL_BY_CODE[code]
    return jm.row({k: v for k, v in s["props"].items() if k in jm.props})


class RigidEngine:
    def __init__(self, model):
        self.model = model
        self.dt = 0.0
        self.unbal = 0.0
        self.ratio = 1.0
        #: kinetic energy of the moving bodies at the last step (real masses) [J]
        self.kinetic = 0.0
        #: callables hook(engine) run after every batch of steps (histories register here);
        #: a hook with an ``interval`` attribute gets a batch boundary at every multiple of it
        self.step_hooks: list = []
        #: seconds per phase; "hooks" covers histories and periodic VTK snapshots
        self.timings = {"detect": 0.0, "search": 0.0, "subcontacts": 0.0, "cycle": 0.0, "hooks": 0.0}
        self._cand = None             # candidate pairs (rows A, rows B) of the last cell map
        contact_stores(model)
        v = model.vertices
        for key in ("map_pos", "look_pos"):
            if key not in v:
                v.add_field(key, Field((3,), _F, 0.0))
        if "map_reach" not in model.blocks:
            model.blocks.add_field("map_reach", Field((), _F, 0.0))

    # ------------------------------------------------------------ model-backed state
    @property
    def step(self) -> int:
        return self.model.step

    @property
    def time(self) -> float:
        return self.model.time

    @property
    def contacts(self) -> Store:
        return self.model.store("contacts")

    @property
    def subcontacts(self) -> Store:
        return self.model.store("subcontacts")

    def settings(self) -> dict:
        return mech(self.model)

    # ------------------------------------------------------------ settings
    def tolerance(self) -> float:
        ctol = self.settings()["ctol"]
        if ctol:
            return float(ctol)
        b = self.model.blocks
        vol = b["volume"][b["volume"] > 0]
        size = float(np.cbrt(vol).mean()) if vol.size else 1.0
        return 0.005 * size

    def point_area(self) -> float:
        """Area given to each point sub-contact of a lower contact type (dec3d's choice:
        1 % of the mean block face, m²)."""
        b = self.model.blocks
        return 0.01 * float(np.cbrt(b["volume"]).mean() ** 2) if b.n else 1e-4

    def timestep(self) -> float:
        s = self.settings()
        if s["timestep"]:
            return float(s["timestep"])
        b = self.model.blocks
        jm = JOINT_MODELS[s["jmodel"]]
        drow = jm.row(s["props"])
        kn = max(drow[P_KN], drow[P_KS])
        c = self.contacts
        if c.n:
            kn = max(kn, float(c["prop"][:, [P_KN, P_KS]].max()))
        area = float(self.model.faces["area"].max()) if self.model.faces.n else 1.0
        live = (b["mass"] > 0) & ~b["hidden"]
        mmin = float(b["mass"][live].min()) if live.any() else 1.0
        return block_timestep(mmin, kn * area, float(s["frac"])) or 1e-3

    def damping(self) -> tuple[int, float]:
        """(damping mode code, α) for the motion kernel."""
        s = self.settings()
        code = {"none": DAMP_NONE, "local": DAMP_LOCAL, "combined": DAMP_COMBINED, "global": DAMP_ADAPTIVE}
        return code[s["damping"]], float(s["alpha"])

    def mass_scaling(self) -> bool:
        s = self.settings()
        return s["mass_scale"] == "on" or (s["mass_scale"] == "auto" and s["damping"] != "none")

    def full_inertia(self) -> bool:
        s = self.settings()
        return s["inertia"] == "full" or (s["inertia"] == "auto" and s["damping"] == "none")

    # ------------------------------------------------------------ detection
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
        if have and not force and float(np.abs(vpos - mpos).max()) <= 0.5 * ctol:
            if self._cand is None:       # after a restore: the same pairs from the saved map
                g = s["grid"]
                self._cand, _ = self._pairs(mpos, ctol, (np.array(g[0]), float(g[1]), np.array(g[2], _I)))
            return self._cand, False
        t0 = _time.perf_counter()
        g = s.get("grid")
        grid = None if (g is None or force) else (np.array(g[0]), float(g[1]), np.array(g[2], _I))
        m.blocks["map_reach"][...] = self._step_motion()
        self._cand, grid = self._pairs(vpos, ctol, grid)
        s["grid"] = [[float(x) for x in grid[0]], float(grid[1]), [int(x) for x in grid[2]]]
        mpos[...] = vpos
        self.timings["search"] += _time.perf_counter() - t0
        return self._cand, True

    def detect(self, force_search: bool = False) -> None:
        """Find the contacts and their sub-contacts again, keeping the force history.

        Incremental: a candidate pair whose two blocks have each moved less than
        ``QUIET`` × CTOL (largest vertex displacement) since they were last looked at keeps
        its contact and sub-contacts as they are (their points still follow Eq. 11 every
        step); every other pair gets a new common plane and new sub-contacts. After a
        remap of the cell space, a change of the blocks, or with ``force_search``, every
        pair is looked at.
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
        (ra, rb), remapped = self._search(ctol, force_search or changed)
        full = force_search or changed or remapped
        if full:
            moved = np.ones(b.n, bool)
        else:
            moved = np.zeros(b.n, bool)
            blocks_moved(vpos, look, b["vert_start"], b["vert_count"], QUIET * ctol, moved)
        ids = b["id"]
        prev = match_sorted(cs["ida"], cs["idb"], ids[ra], ids[rb])
        need = np.flatnonzero(moved[ra] | moved[rb])
        k = len(need)
        nn = np.empty((k, 3))
        cc = np.empty((k, 3))
        gap = np.empty(k)
        ctype = np.empty(k, _I)
        # a pair is a contact when its gap is at most CTOL plus what its blocks can close in
        # one step: fast blocks get their contact (still open) before they meet
        step = self._step_motion()
        reach = ctol + step[ra[need]] + step[rb[need]]
        cp_batch(ra[need], rb[need], prev[need], vpos, b["vert_start"], b["vert_count"], b["centroid"],
                 cs["normal"], cs["pos"], reach, nn, cc, gap, ctype)
        # the contacts: quiet old contacts as they were, looked-at pairs with gap ≤ CTOL
        is_new = np.zeros(len(ra), bool)
        is_new[need[ctype > 0]] = True
        kept = (prev >= 0) & ~(moved[ra] | moved[rb])
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
        lf = lc[~kept_c]
        normal[~kept_c], cpos[~kept_c], cgap[~kept_c], ctyp[~kept_c] = nn[lf], cc[lf], gap[lf], ctype[lf]
        # contact data carried by the pair key, or the defaults for a new contact
        s = self.settings()
        old = prev_c >= 0
        jm = JOINT_MODELS[s["jmodel"]]
        jcode = np.full(nc, jm.code, _I)
        prop = np.tile(default_row(s, jm.code), (nc, 1)) if nc else np.zeros((0, NPROP))
        group = np.full((nc, cs["group"].shape[1]), -1, np.int32)
        own = np.zeros(nc, np.uint8)
        jcode[old] = cs["jmodel"][prev_c[old]]
        own[old] = cs["own_props"][prev_c[old]]
        keep_row = old & (own == 1)
        prop[keep_row] = cs["prop"][prev_c[keep_row]]
        for code in np.unique(jcode[old & (own == 0)]):      # contacts that follow the defaults
            sel = old & (own == 0) & (jcode == code)
            prop[sel] = default_row(s, int(code))
        group[old] = cs["group"][prev_c[old]]
        # sub-contacts of the recomputed contacts (zero-area ones carry nothing and are dropped)
        t1 = _time.perf_counter()
        f_ra, f_rb, f_prev = ra[fresh], rb[fresh], prev[fresh]
        f_n, f_c, f_gap = nn[local[fresh]], cc[local[fresh]], gap[local[fresh]]
        sc_c, kind, key0, key1, pos, area = _subcontacts(vpos, b, f, fv, f_ra, f_rb, f_n, f_c, ctol,
                                                         self.point_area())
        vertex_point_areas(sc_c, kind, key0, ctype[local[fresh]], f_n, vpos, m.vertices["block"],
                           b["face_start"], b["face_count"], f["vstart"], f["nvert"], fv["vertex"],
                           self.point_area(), area)
        live = area > 0.0
        if not live.all():
            sc_c, kind, key0, key1, pos, area = (x[live] for x in (sc_c, kind, key0, key1, pos, area))
        ns = len(sc_c)
        fs = np.empty((ns, 3))
        un = np.empty(ns)
        udil = np.empty(ns)
        us = np.empty((ns, 3))
        state = np.empty(ns, _I)
        carry_over(f_prev, sc_c, kind, key0, key1, area, f_gap, cs["sub_start"], cs["sub_count"], ss["kind"],
                   ss["key0"], ss["key1"], ss["area"], ss["fs"], ss["un"], ss["udil"], ss["us"], ss["state"],
                   cs["normal"], f_n, fs, un, udil, us, state)
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
        src = np.repeat(base - starts, counts) + np.arange(total, dtype=_I)
        owner = np.repeat(np.arange(nc, dtype=_I), counts)
        pool = {"kind": (ss["kind"], kind), "key0": (ss["key0"], key0), "key1": (ss["key1"], key1),
                "pos": (ss["pos"], pos), "area": (ss["area"], area), "fn": (ss["fn"], np.zeros(ns)),
                "fs": (ss["fs"], fs), "un": (ss["un"], un), "udil": (ss["udil"], udil), "us": (ss["us"], us),
                "state": (ss["state"], state)}
        sub = {key: np.concatenate(pair)[src] for key, pair in pool.items()}
        self.timings["subcontacts"] += _time.perf_counter() - t1
        # install
        cs.clear()
        cs.append(nc)
        for key, val in (("ida", ids[ra_c]), ("idb", ids[rb_c]), ("a", ra_c), ("b", rb_c), ("pos", cpos),
                         ("normal", normal), ("gap", cgap), ("type", ctyp), ("jmodel", jcode), ("prop", prop),
                         ("own_props", own), ("sub_start", starts), ("sub_count", counts), ("group", group)):
            cs[key][...] = val
        ss.clear()
        ss.append(total)
        ss["contact"][...] = owner
        for key, val in sub.items():
            ss[key][...] = val
        # the blocks looked at are the new reference for "moved"
        if full:
            look[...] = vpos
        else:
            sel = moved[m.vertices["block"]]
            look[sel] = vpos[sel]
        self.timings["detect"] += _time.perf_counter() - t0

    def ensure_contacts(self) -> None:
        """Detect now if the blocks changed since the last detection (3DEC keeps contacts
        current whenever blocks exist, so contact commands see them before any cycle)."""
        if self._geometry_signature() != self._signature:
            self.detect()

    # ------------------------------------------------------------ cycling
    def _groups(self):
        """CSR of the moving bodies: joined blocks by leader (leader first), lone blocks alone."""
        b = self.model.blocks
        rows = np.flatnonzero(~b["hidden"]).astype(_I)
        lead = b["leader"][rows]
        lead = np.where(lead < 0, rows, lead)
        order = np.lexsort((rows != lead, rows, lead))
        gmember = rows[order]
        glead = lead[order]
        first = np.concatenate(([True], glead[1:] != glead[:-1])) if len(rows) else np.zeros(0, bool)
        gstart = np.concatenate((np.flatnonzero(first), [len(rows)])).astype(_I)
        return gstart, np.ascontiguousarray(gmember)

    def _stiffness_sums(self, gstart, gmember) -> np.ndarray:
        """Per group, Σ over its sub-contacts of max(kn, ks)·area [N/m] (Eq. 87's K)."""
        b = self.model.blocks
        cs, ss = self.contacts, self.subcontacts
        kb = np.zeros(b.n)
        if ss.n:
            c = ss["contact"]
            k = np.maximum(cs["prop"][c, P_KN], cs["prop"][c, P_KS]) * ss["area"]
            kb += np.bincount(cs["a"][c], k, minlength=b.n) + np.bincount(cs["b"][c], k, minlength=b.n)
        return np.add.reduceat(kb[gmember], gstart[:-1]) if len(gmember) else np.zeros(0)

    def _masses(self, gstart, gmember, gmass, giscalar, dt_fixed):
        """(Δt, inertial masses, scaled scalar inertias) of the groups; density scaling when on."""
        s = self.settings()
        frac = float(s["frac"])
        if not self.mass_scaling() or not len(gmass):
            dt = dt_fixed if dt_fixed is not None else self.timestep()
            return dt, gmass.copy(), giscalar.copy()
        kg = self._stiffness_sums(gstart, gmember)
        if dt_fixed is None and s["scale_timestep"]:
            dt_fixed = float(s["scale_timestep"])
        if dt_fixed is not None:
            dt = dt_fixed
        else:
            on = kg > 0
            # Δt of Eq. (87) for a typical body (median mass and stiffness); lighter or stiffer
            # bodies get a larger inertial mass, heavier ones keep theirs
            dt = (block_timestep(float(np.median(gmass[on])), float(np.median(kg[on])), frac)
                  if on.any() else self.timestep())
        im, isc = inertial_masses(gmass, giscalar, kg, dt, frac)
        return dt, im, isc

    def cycle(self, nsteps: int, stop=None, max_time: float | None = None) -> int:
        """Run up to ``nsteps`` steps; ``stop(engine)`` is checked after every batch (at most
        ``update-interval`` steps apart); ``max_time``: stop when the model time reaches it.
        Returns the steps done."""
        m = self.model
        b = m.blocks
        if b.n == 0 or nsteps <= 0:
            return 0
        live = ~b["hidden"]
        if (b["mass"][live] <= 0).any():
            raise RunError("a block has no mass: set `block property density` before cycling")
        s = self.settings()
        g = np.asarray(m.settings.gravity, dtype=_F)
        mode, alpha = self.damping()
        full = self.full_inertia()
        gstart, gmember = self._groups()
        ng = len(gstart) - 1
        # orientation of each block: its principal axes are kept current (below)
        inertia = np.einsum("bij,bj,bkj->bik", b["principal_axes"], b["principal_moment"], b["principal_axes"])
        gmass, gcen, _, gprin, gaxes, giscalar = group_properties(gstart, gmember, b["mass"], b["centroid"],
                                                                  inertia, b["inertia_approx"],
                                                                  b["principal_moment"], b["principal_axes"])
        axes0 = gaxes.copy()
        servo = new_servo(ng, ratio=float(s["servo_ratio"]))
        if mode == DAMP_ADAPTIVE and len(s["servo"]) == NSERVO:
            servo[:NSERVO] = s["servo"]
        servo[S_HIST] = 0.0
        fixity = (b["fixity"] | b["apply_fix"]).astype(np.uint8)
        dt_fixed = float(s["timestep"]) if s["timestep"] else None
        out = np.zeros(4)
        vmax = 1e6
        interval = max(1, int(m.settings.update_interval))
        done = 0
        progress = _Progress(nsteps)
        if self._signature != self._geometry_signature():
            self.detect()
        dt, gimass, gisc = self._masses(gstart, gmember, gmass, giscalar, dt_fixed)
        self.dt = dt
        # detection also runs as soon as a block has moved CTOL/2 since the last one, so
        # that two blocks approaching each other cannot close more than CTOL unseen
        radius = self._radii()
        acc = np.zeros(b.n)
        motion = np.zeros(2)
        trigger = 0.5 * self.tolerance()
        due = False
        try:
            while done < nsteps:
                if m.step % interval == 0 or due:
                    self.detect()
                    acc[:] = 0.0
                    due = False
                    if self.mass_scaling():
                        _, gimass, gisc = self._masses(gstart, gmember, gmass, giscalar, dt)
                k = min(nsteps - done, interval - m.step % interval)
                for h in self.step_hooks:
                    hi = int(getattr(h, "interval", 0) or 0)
                    if hi > 0:
                        k = min(k, hi - m.step % hi)
                vtk = m.outputs.get("vtk")
                if vtk and vtk["interval"] > 0:
                    k = max(1, min(k, vtk["last_step"] + vtk["interval"] - m.step))
                if max_time is not None:
                    left = int(math.ceil((max_time - m.time) / dt - 1e-9))
                    if left <= 0:
                        break
                    k = min(k, left)
                cs, ss = self.contacts, self.subcontacts
                t0 = _time.perf_counter()
                n_ok, bad = run_steps(k, dt, g, mode, alpha, servo, full, gstart, gmember, gmass, gimass, gisc,
                                      gprin, gaxes, gcen, b["mass"], fixity, b["force"], b["moment"], b["fapp"],
                                      b["mapp"], b["velocity"], b["spin"], b["centroid"], b["disp"],
                                      b["vert_start"], b["vert_count"], m.vertices["pos"], cs["a"], cs["b"],
                                      cs["normal"], cs["pos"], np.arange(cs.n, dtype=_I), cs["jmodel"], cs["prop"],
                                      ss["contact"], ss["pos"], ss["area"], ss["fn"], ss["fs"], ss["un"], ss["udil"],
                                      ss["us"], ss["state"], vmax, out, radius, acc, trigger, motion)
                self.timings["cycle"] += _time.perf_counter() - t0
                due = motion[1] > 0.0
                m.step += n_ok
                m.time += n_ok * dt
                done += n_ok
                if bad >= 0 and motion[1] == 2.0:
                    raise RunError(f"the run became unstable at step {m.step}: block {int(b['id'][bad])} moved "
                                   f"farther than its own size in one step (speed "
                                   f"{np.linalg.norm(b['velocity'][bad]):.3g} m/s, time step {dt:.3g} s): "
                                   "it can pass through other blocks unseen")
                if bad >= 0:
                    raise RunError(f"the run became unstable at step {m.step}: block {int(b['id'][bad])} "
                                   f"reached velocity {np.abs(b['velocity'][bad]).max():.3g} m/s "
                                   f"(time step {dt:.3g} s too large or stiffness too high)")
                self.unbal = float(out[0])
                self.ratio = float(out[0] / (out[1] / max(ng, 1))) if out[1] > 0 else 0.0
                self.kinetic = float(out[2])
                t0 = _time.perf_counter()
                for hook in self.step_hooks:
                    hook(self)
                periodic_vtk(m)
                self.timings["hooks"] += _time.perf_counter() - t0
                progress.update(done)
                if stop is not None and stop(self):
                    break
        finally:
            progress.close()
            # keep each block's principal axes turning with its body; save the servo state
            turn = np.einsum("gij,gkj->gik", gaxes, axes0)
            gid = np.repeat(np.arange(ng), np.diff(gstart))
            pa = b["principal_axes"]
            pa[gmember] = np.einsum("bij,bjk->bik", turn[gid], pa[gmember])
            b["inertia"][gmember] = np.einsum("bij,bj,bkj->bik", pa[gmember], b["principal_moment"][gmember],
                                              pa[gmember])
            if mode == DAMP_ADAPTIVE:
                s["servo"] = [float(x) for x in servo[:NSERVO]]
        return done

    def timing_report(self) -> str:
        """The time spent per phase since the counters were last zeroed (seconds, share)."""
        t = self.timings
        tot = (t["detect"] + t["cycle"] + t["hooks"]) or 1e-30
        rows = [("detection", t["detect"]), ("  neighbour search", t["search"]),
                ("  sub-contacts", t["subcontacts"]), ("cycle kernel", t["cycle"]), ("histories, VTK", t["hooks"])]
        return "\n".join([f"{'phase':<20}{'seconds':>9}{'share':>8}"] +
                         [f"{k:<20}{v:9.3f}{100 * v / tot:7.1f}%" for k, v in rows])


class _Progress:
    """A rich progress bar for runs longer than about a second, on a terminal only."""

    def __init__(self, total: int):
        self.total = total
        self.t0 = _time.perf_counter()
        self.bar = None
        self.task = None
        self.enabled = sys.stdout.isatty()

    def update(self, done: int) -> None:
        if not self.enabled:
            return
        if self.bar is None:
            if _time.perf_counter() - self.t0 < 1.0:
                return
            from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

            self.bar = Progress(TextColumn("cycling"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                                TimeRemainingColumn(), transient=True)
            self.bar.start()
            self.task = self.bar.add_task("cycle", total=self.total)
        self.bar.update(self.task, completed=done)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()


def engine(model) -> RigidEngine:
    """The model's rigid engine, made on first use."""
    e = getattr(model, "rigid_engine", None)
    if e is None:
        e = RigidEngine(model)
        model.rigid_engine = e
    return e


def model_name(code: int) -> str:
    return MODEL_BY_CODE[int(code)].name
