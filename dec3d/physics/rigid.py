"""Rigid-block engine: contacts, sub-contacts and the calculation cycle (3DEC theory, Fig. 13).

One ``RigidEngine`` hangs on the model (``engine(model)``). Every ``update_interval`` steps:
neighbour pairs (axis-aligned envelopes enlarged by CTOL, sort-and-sweep on x: simple and
exact, not yet 3DEC's cell map), common plane per pair (kernel ``commonplane``, fast path
from the previous normal), contacts kept while gap ≤ CTOL, sub-contacts rebuilt
(``subcontacts.make_subcontacts``) carrying the force state of the sub-contact of the same
contact at the nearest old position (within CTOL), else the contact's mean stresses × area;
shear forces turned to the new normal by Eq. (23). Every step: joint law and force scatter
(kernel ``jointlaw``), then motion (kernel ``motion``) for the leader rows (joined blocks and
full-inertia Euler equations are not done yet: every block moves on its own, scalar inertia).
Sub-contact points move with the mean displacement of the two blocks (Eq. 11).
"""
from __future__ import annotations

import math

import numpy as np

from dec3d.errors import Dec3dError
from dec3d.kernels.commonplane import common_plane, contact_type
from dec3d.kernels.jointlaw import (MODEL_ELASTIC, MODEL_MOHR, NPROP, P_COH, P_COH_RES, P_KN, P_KS,
                                    P_TANDIL, P_TANF, P_TANF_RES, P_TEN, P_TEN_RES, P_ZDIL,
                                    rotate_shear, subcontact_forces)
from dec3d.kernels.motion import block_timestep, rigid_motion

from .subcontacts import make_subcontacts

#: joint models: name -> (kernel code, property names accepted)
JOINT_MODELS = {
    "elastic": (MODEL_ELASTIC, ("stiffness-normal", "stiffness-shear")),
    "mohr": (MODEL_MOHR, ("stiffness-normal", "stiffness-shear", "friction", "cohesion", "tension",
                          "dilation", "dilation-zero", "friction-residual", "cohesion-residual",
                          "tension-residual")),
}


class RunError(Dec3dError):
    """The run became unstable (NaN or runaway velocity)."""


def props_vector(props: dict) -> np.ndarray:
    """Property dict (degrees for angles) -> kernel row (P_* columns)."""
    v = np.zeros(NPROP)
    v[P_KN] = props.get("stiffness-normal", 0.0)
    v[P_KS] = props.get("stiffness-shear", 0.0)
    f = props.get("friction", 0.0)
    v[P_TANF] = math.tan(math.radians(f))
    v[P_COH] = props.get("cohesion", 0.0)
    v[P_TEN] = props.get("tension", 0.0)
    v[P_TANDIL] = math.tan(math.radians(props.get("dilation", 0.0)))
    v[P_ZDIL] = props.get("dilation-zero", 0.0)
    v[P_TANF_RES] = math.tan(math.radians(props.get("friction-residual", f)))
    v[P_COH_RES] = props.get("cohesion-residual", 0.0)
    v[P_TEN_RES] = props.get("tension-residual", 0.0)
    return v


class RigidEngine:
    def __init__(self, model):
        self.model = model
        self.ctol: float | None = None
        self.default_model = "mohr"
        self.default_props: dict[str, float] = {}
        self.alpha_local = 0.8
        self.alpha_visc = 0.0
        self.frac = 0.1
        self.dt_user: float | None = None
        self.step = 0
        self.time = 0.0
        self.unbal = 0.0
        self.ratio = 1.0
        #: callables hook(engine) run after every step (histories register here)
        self.step_hooks: list = []
        # contacts (pair key -> row) and their arrays
        self.pairs: dict[tuple[int, int], int] = {}
        self.ca = np.zeros(0, np.int64)
        self.cb = np.zeros(0, np.int64)
        self.cn = np.zeros((0, 3))
        self.cc = np.zeros((0, 3))
        self.cgap = np.zeros(0)
        self.ctype = np.zeros(0, np.int64)
        self.cmodel = np.zeros(0, np.int64)
        self.cprop = np.zeros((0, NPROP))
        self.cname: list[str] = []
        self.cuser: list[dict] = []
        self._empty_sc()

    def _empty_sc(self):
        self.sc = {"contact": np.zeros(0, np.int64), "pos": np.zeros((0, 3)), "area": np.zeros(0),
                   "fn": np.zeros(0), "fs": np.zeros((0, 3)), "un": np.zeros(0), "udil": np.zeros(0),
                   "us": np.zeros((0, 3)), "state": np.zeros(0, np.int64)}

    # ------------------------------------------------------------ settings
    def tolerance(self) -> float:
        if self.ctol is not None:
            return self.ctol
        b = self.model.blocks
        size = np.cbrt(b["volume"][b["volume"] > 0]).mean() if b.n else 1.0
        return 0.005 * float(size)

    def point_area(self) -> float:
        b = self.model.blocks
        return 0.01 * float(np.cbrt(b["volume"]).mean() ** 2) if b.n else 1e-4

    def timestep(self) -> float:
        if self.dt_user:
            return self.dt_user
        b = self.model.blocks
        kn = max(self.default_props.get("stiffness-normal", 0.0), self.default_props.get("stiffness-shear", 0.0))
        if len(self.cprop):
            kn = max(kn, float(self.cprop[:, [P_KN, P_KS]].max()))
        area = float(self.model.faces["area"].max()) if self.model.faces.n else 1.0
        mmin = float(b["mass"][b["mass"] > 0].min()) if (b["mass"] > 0).any() else 1.0
        return block_timestep(mmin, kn * area, self.frac) or 1e-3

    # ------------------------------------------------------------ detection
    def _block_verts(self, r):
        b = self.model.blocks
        s, c = b["vert_start"][r], b["vert_count"][r]
        return self.model.vertices["pos"][s:s + c]

    def candidate_pairs(self, ctol):
        m = self.model
        b, pos = m.blocks, m.vertices["pos"]
        n = b.n
        lo = np.empty((n, 3))
        hi = np.empty((n, 3))
        for r in range(n):
            v = pos[b["vert_start"][r]:b["vert_start"][r] + b["vert_count"][r]]
            lo[r], hi[r] = v.min(0) - ctol, v.max(0) + ctol
        order = np.argsort(lo[:, 0], kind="stable")
        out = []
        for k, i in enumerate(order):
            for j in order[k + 1:]:
                if lo[j, 0] > hi[i, 0]:
                    break
                if (lo[i] <= hi[j]).all() and (lo[j] <= hi[i]).all():
                    out.append((min(i, j), max(i, j)))
        return sorted(out)

    def detect(self):
        ctol = self.tolerance()
        b = self.model.blocks
        cen = b["centroid"]
        old_pairs, old = self.pairs, self._snapshot()
        new_pairs: dict[tuple[int, int], int] = {}
        rows = []
        for (i, j) in self.candidate_pairs(ctol):
            if b["hidden"][i] or b["hidden"][j]:
                continue
            va, vb = self._block_verts(i), self._block_verts(j)
            prev = old_pairs.get((i, j))
            n = np.empty(3)
            c = old["cc"][prev].copy() if prev is not None else 0.5 * (cen[i] + cen[j])
            n0 = old["cn"][prev] if prev is not None else cen[j] - cen[i]
            gap, na, nb, _ = common_plane(va, vb, n0, ctol, prev is not None, n, c)
            if gap > ctol:
                continue
            new_pairs[(i, j)] = len(rows)
            rows.append((i, j, n, c, gap, contact_type(na, nb), prev))
        self._install(rows, new_pairs, old, ctol)

    def _snapshot(self):
        return {"cn": self.cn.copy(), "cc": self.cc.copy(), "cmodel": self.cmodel.copy(),
                "cprop": self.cprop.copy(), "cname": list(self.cname), "cuser": list(self.cuser),
                "sc": {k: v.copy() for k, v in self.sc.items()}}

    def _install(self, rows, new_pairs, old, ctol):
        nc = len(rows)
        self.pairs = new_pairs
        self.ca = np.array([r[0] for r in rows], np.int64)
        self.cb = np.array([r[1] for r in rows], np.int64)
        self.cn = np.array([r[2] for r in rows]).reshape(nc, 3)
        self.cc = np.array([r[3] for r in rows]).reshape(nc, 3)
        self.cgap = np.array([r[4] for r in rows])
        self.ctype = np.array([r[5] for r in rows], np.int64)
        self.cmodel = np.zeros(nc, np.int64)
        self.cprop = np.zeros((nc, NPROP))
        self.cname, self.cuser = [], []
        osc = old["sc"]
        parts = {k: [] for k in self.sc}
        pa = self.point_area()
        for c, (i, j, n, cp, gap, ct, prev) in enumerate(rows):
            if prev is not None:
                self.cmodel[c], self.cprop[c] = old["cmodel"][prev], old["cprop"][prev]
                self.cname.append(old["cname"][prev])
                self.cuser.append(old["cuser"][prev])
            else:
                self.cname.append(self.default_model)
                self.cuser.append(dict(self.default_props))
                self.cmodel[c] = JOINT_MODELS[self.default_model][0]
                self.cprop[c] = props_vector(self.default_props)
            pts, areas = make_subcontacts(self._block_verts(i), self._block_verts(j), n, cp, ctol, pa)
            k = len(pts)
            st = {"contact": np.full(k, c, np.int64), "pos": pts, "area": areas, "fn": np.zeros(k),
                  "fs": np.zeros((k, 3)), "un": np.full(k, gap), "udil": np.zeros(k),
                  "us": np.zeros((k, 3)), "state": np.zeros(k, np.int64)}
            if prev is not None:
                sel = np.flatnonzero(osc["contact"] == prev)
                if sel.size:
                    fs_old = osc["fs"][sel].copy()
                    rotate_shear(np.zeros(len(sel), np.int64), old["cn"][prev][None], n[None], fs_old)
                    atot = osc["area"][sel].sum() or 1.0
                    for t in range(k):
                        d = np.linalg.norm(osc["pos"][sel] - pts[t], axis=1)
                        o = int(np.argmin(d))
                        if d[o] <= max(ctol, 1e-9):
                            s = sel[o]
                            scale = areas[t] / osc["area"][s] if osc["area"][s] > 0 else 1.0
                            st["fs"][t] = fs_old[o] * scale
                            for key in ("un", "udil", "us", "state"):
                                st[key][t] = osc[key][s]
                        else:      # smooth carry-over: mean stresses of the old contact
                            st["fs"][t] = fs_old.sum(0) / atot * areas[t]
                            st["un"][t] = float((osc["un"][sel] * osc["area"][sel]).sum() / atot)
                            st["udil"][t] = float((osc["udil"][sel] * osc["area"][sel]).sum() / atot)
                            st["state"][t] = int(np.bitwise_or.reduce(osc["state"][sel]) & 1)
            for key in parts:
                parts[key].append(st[key])
        if nc:
            self.sc = {k: np.concatenate(v) for k, v in parts.items()}
        else:
            self._empty_sc()

    # ------------------------------------------------------------ cycling
    def cycle(self, nsteps: int, stop=None) -> int:
        """Run up to ``nsteps`` steps; ``stop(engine)`` checked after each step. Returns steps done."""
        m = self.model
        b = m.blocks
        if b.n == 0:
            return 0
        if (b["mass"] <= 0).any():
            raise RunError("a block has no mass: set `block property density` before cycling")
        g = np.asarray(m.settings.gravity, dtype=np.float64)
        dt = self.timestep()
        self.dt = dt
        rows = np.flatnonzero((b["leader"] == np.arange(b.n)) & ~b["hidden"]).astype(np.int64)
        interval = max(1, int(m.settings.update_interval))
        vmax = 1e6
        done = 0
        for _ in range(nsteps):
            if self.step % interval == 0 or not self.pairs:
                self.detect()
            sc = self.sc
            vel_before = b["velocity"].copy()
            spin_before = b["spin"].copy()
            subcontact_forces(dt, b["centroid"], b["velocity"], b["spin"], b["force"], b["moment"],
                              self.ca, self.cb, self.cn, self.cmodel, self.cprop, sc["contact"], sc["pos"],
                              sc["area"], sc["fn"], sc["fs"], sc["un"], sc["udil"], sc["us"], sc["state"])
            cen_before = b["centroid"].copy()
            bad, fmax, fsum = rigid_motion(dt, g, self.alpha_local, self.alpha_visc, rows, b["mass"], b["mass"],
                                           b["inertia_approx"], b["fixity"], b["force"], b["moment"], b["fapp"],
                                           b["mapp"], b["velocity"], b["spin"], b["centroid"], b["disp"],
                                           b["vert_start"], b["vert_count"], m.vertices["pos"], vmax)
            self.step += 1
            done += 1
            if bad >= 0 or not math.isfinite(fmax):
                r = bad if bad >= 0 else 0
                raise RunError(f"the run became unstable at step {self.step}: block {int(b['id'][r])} "
                               f"reached velocity {np.abs(b['velocity'][r]).max():.3g} m/s "
                               f"(time step {dt:.3g} s too large or stiffness too high)")
            # sub-contact points follow the mean displacement of their two blocks (Eq. 11)
            if len(sc["contact"]):
                dA = self._point_disp(cen_before, sc["contact"], sc["pos"], self.ca, dt, spin_before=None)
                dB = self._point_disp(cen_before, sc["contact"], sc["pos"], self.cb, dt, spin_before=None)
                sc["pos"] += 0.5 * (dA + dB)
            self.time += dt
            self.unbal = fmax
            nfree = max(len(rows), 1)
            self.ratio = fmax / (fsum / nfree) if fsum > 0 else 0.0
            for hook in self.step_hooks:
                hook(self)
            if stop is not None and stop(self):
                break
        return done

    def _point_disp(self, cen_before, scc, pos, side, dt, spin_before=None):
        b = self.model.blocks
        r = side[scc]
        arm = pos - cen_before[r]
        return b["velocity"][r] * dt + np.cross(b["spin"][r] * dt, arm)


def engine(model) -> RigidEngine:
    """The model's rigid engine, made on first use."""
    e = getattr(model, "rigid_engine", None)
    if e is None:
        e = RigidEngine(model)
        model.rigid_engine = e
    return e
