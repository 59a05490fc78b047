"""Rigid-block engine: settings and the calculation cycle (3DEC theory, Fig. 13).

State lives in the model: contacts and sub-contacts are two stores (``contacts``,
``subcontacts``, saved and restored with the rest; ``contacts.py``), the engine settings and
detection bookkeeping are ``model.settings.mechanical`` (plain JSON) and a few vertex/block
fields. The ``RigidEngine`` object on the model holds only what can be rebuilt: the
candidate pairs, the time step and timings. A restored run continues bit for bit.

Detection is ``contacts.ContactDetection`` (mixed in). Cycling (kernel ``cycle.run_steps``):
many steps per call, up to the next detection, history sample, VTK snapshot or solve check.
"""
from __future__ import annotations

import copy
import math
import time as _time

import numpy as np

from dec3d.errors import Dec3dError
from dec3d.io.vtk import periodic_vtk
from dec3d.kernels.balance import body_balance
from dec3d.kernels.cycle import run_steps
from dec3d.kernels.gpcontact import mixed_move_points, mixed_subcontact_forces, surface_weights
from dec3d.kernels.jointlaw import P_KN, P_KS
from dec3d.kernels.motion import (DAMP_ADAPTIVE, DAMP_COMBINED, DAMP_LOCAL, DAMP_NONE, NSERVO, S_HIST, block_timestep,
                                  rigid_motion_groups)
from dec3d.model.model import KIND_DEFORMABLE, KIND_FE
from dec3d.model.store import Store
from dec3d.model.feblocks import has_feblocks
from dec3d.model.zones import has_zones

from .bodies import group_properties, inertial_masses, new_servo
from .contacts import ContactDetection, contact_stores, default_row
from .jmodels import JOINT_MODELS
from .runcontrol import CycleInterrupted, _Progress, _sigint_stops_cycling, _StopFlag, request_stop  # noqa: F401  (request_stop: part of this module's API)

_F = np.float64
_I = np.int64

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
    "dt_run": [],              # [Δt, step]: the step the last rigid run ended on and the Δt it was using
}


class RunError(Dec3dError):
    """The run became unstable (NaN or runaway velocity). The engine has put the model back
    to its state before the ``cycle`` call that failed."""


#: vertex fields the deformable step changes (saved before a run, put back if it fails)
_GP_STATE = ("velocity", "disp", "force", "mass", "imass")


def _deformable(kind):
    """Zoned and FE blocks: they move by their gridpoints (nodes), not as rigid bodies."""
    return (kind == KIND_DEFORMABLE) | (kind == KIND_FE)


def _has_gridpoints(m) -> bool:
    return has_zones(m) or has_feblocks(m)

#: target wall time of one kernel call [s]: Ctrl-C and progress are seen at least this often
CHUNK_SECONDS = 0.2
#: local/maximum ratios are scaled by this so that they mean about the same as the average
#: (Itasca, ``zone ratio`` / ``structure ratio`` command pages, see ``RigidEngine.criteria``)
RATIO_SCALE = 0.1


def mech(model) -> dict:
    """The model's engine settings, with every default filled in."""
    m = model.settings.mechanical
    for k, v in MECH_DEFAULTS.items():
        if k not in m:
            m[k] = dict(v) if isinstance(v, dict) else v
    return m


class RigidEngine(ContactDetection):
    def __init__(self, model):
        self.model = model
        self.dt = 0.0
        #: the equilibrium measures of ``criteria()`` at the last step (None: not worked out yet)
        self._criteria: dict | None = None
        self._group_cache = None      # (gstart, gmember) while cycling
        #: kinetic energy of the moving bodies at the last step (real masses) [J]
        self.kinetic = 0.0
        #: callables hook(engine) run after every batch of steps (histories register here);
        #: a hook with an ``interval`` attribute gets a batch boundary at every multiple of it
        self.step_hooks: list = []
        #: seconds per phase; "hooks" covers histories and periodic VTK snapshots
        self.timings = {"detect": 0.0, "search": 0.0, "subcontacts": 0.0, "cycle": 0.0, "hooks": 0.0}
        self._cand = None             # candidate pairs (rows A, rows B) of the last cell map
        #: the deformable step of the last run on a model with zones (``physics.zones``), or None
        self._zstep = None
        contact_stores(model)

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

    # ------------------------------------------------------------ cycling
    def _groups(self):
        """CSR of the moving bodies: joined blocks by leader (leader first), lone blocks alone.
        Zoned (deformable) blocks are not rigid bodies: they move by their gridpoints."""
        b = self.model.blocks
        rows = np.flatnonzero(~b["hidden"] & ~_deformable(b["kind"])).astype(_I)
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

    # ------------------------------------------------------------ equilibrium measures
    @property
    def unbal(self) -> float:
        """Largest unbalanced force of a moving body at the last step [N]."""
        return self.criteria()["unbalanced-maximum"]

    @property
    def ratio(self) -> float:
        """The mechanical ratio at the last step (the average ratio, Itasca's default)."""
        return self.criteria()["ratio"]

    def criteria(self) -> dict[str, float]:
        """The equilibrium measures of the moving bodies at the last step, as Itasca defines them
        for gridpoints (FLAC3D/3DEC manual, "Reaching Equilibrium" and its "Out-of-Balance Force
        and Ratio Calculation" section; ``zone ratio`` and ``structure ratio`` command pages,
        docs.itascacg.com), applied to dec3d's bodies (a lone block or a group of joined blocks):

        - unbalanced force of a body: |Σ F| of everything acting on it (contact forces, weight,
          applied force), the components its fixity holds left out — what moves it;
        - applied force magnitude of a body: Σ |F| over the same forces one by one (the weight,
          the applied force and the force of each sub-contact): "a measure of the total forces
          being applied";
        - ``unbalanced-maximum``: the largest unbalanced force [N];
        - ``ratio-average``: mean unbalanced force / mean applied force magnitude;
        - ``ratio-local``: the largest ratio of a body's unbalanced force to its own applied
          force magnitude, scaled by 0.1 "to make it mean approximately the same as average";
        - ``ratio-maximum``: the largest unbalanced force / mean applied force magnitude,
          scaled by 0.1 likewise;
        - ``ratio``: the average ratio (the default ratio of ``model solve``).
        Bodies whose three translations are fixed take no part (dec3d's choice); a body on
        which no force acts has no local ratio. Moments are not counted (as for gridpoints).
        Worked out (kernel ``balance.body_balance``) from the sub-contact forces of the last
        step (``fn``, ``fs``), which the cycle leaves in place, so the cycle kernels need not
        return them.
        """
        if self._criteria is None:
            self._criteria = self._work_out_criteria()
        return self._criteria

    def _work_out_criteria(self) -> dict[str, float]:
        m = self.model
        b = m.blocks
        out = {"ratio": 0.0, "ratio-average": 0.0, "ratio-local": 0.0, "ratio-maximum": 0.0,
               "unbalanced-maximum": 0.0}
        gstart, gmember = self._group_cache if self._group_cache is not None else self._groups()
        zst = self._zstep if _has_gridpoints(m) else None
        if b.n == 0 or (len(gmember) == 0 and zst is None):
            return out
        ng = len(gstart) - 1
        cs, ss = self.contacts, self.subcontacts
        held = (b["fixity"] | b["apply_fix"])[gmember[gstart[:-1]]].astype(np.uint8)
        un = np.empty(ng)
        A = np.empty(ng)
        if ng:
            body_balance(np.asarray(m.settings.gravity, dtype=_F), gstart, gmember, b["mass"], b["fapp"], held,
                         cs["a"], cs["b"], cs["normal"], ss["contact"], ss["fn"], ss["fs"], np.empty((b.n, 3)),
                         np.empty(b.n), un, A)
        free = (held & 7) != 7
        un = un[free]
        A = A[free]
        if zst is not None:
            # gridpoints of zoned blocks count as bodies (Itasca's own definitions are for gridpoints)
            gu, ga = zst.balance()
            un = np.concatenate((un, gu))
            A = np.concatenate((A, ga))
        if not len(un):
            return out
        umax = float(un.max())
        out["unbalanced-maximum"] = umax
        if A.sum() > 0.0:
            out["ratio-average"] = float(un.sum() / A.sum())
            out["ratio-maximum"] = RATIO_SCALE * umax / float(A.mean())
        on = A > 0.0
        if on.any():
            out["ratio-local"] = RATIO_SCALE * float((un[on] / A[on]).max())
        out["ratio"] = out["ratio-average"]
        return out

    def stiffness_warning(self) -> str | None:
        """A warning when contacts in use (with sub-contacts) have zero normal or shear
        stiffness: blocks would sink into each other or slide freely and a solve would
        run to its cycle limit. Looks at the contacts as they are (``cycle(warn=…)`` calls it
        after its first detection)."""
        if self.model.blocks.n == 0:
            return None
        cs = self.contacts
        if cs.n == 0:
            return None
        used = cs["sub_count"] > 0
        prop = cs["prop"].copy()
        follow = cs["own_props"] == 0             # these take the defaults at the next detection
        for code in np.unique(cs["jmodel"][follow]):
            prop[follow & (cs["jmodel"] == code)] = default_row(self.settings(), int(code))
        bad = used & ((prop[:, P_KN] <= 0.0) | (prop[:, P_KS] <= 0.0))
        if not bad.any():
            return None
        k = int(np.flatnonzero(bad)[0])
        return (f"{int(bad.sum())} of {int(used.sum())} contacts have zero normal or shear stiffness "
                f"(the first between blocks {int(cs['ida'][k])} and {int(cs['idb'][k])}): blocks will sink "
                "into each other or slide freely; set stiffness-normal and stiffness-shear with "
                "`block contact property` or `block contact material-table default property`")

    # ------------------------------------------------------------ cycling
    def cycle(self, nsteps: int, stop=None, max_time: float | None = None, warn=None) -> int:
        """Run up to ``nsteps`` steps; ``stop(engine)`` is checked after every batch (at most
        ``update-interval`` steps apart); ``max_time``: stop when the model time reaches it;
        ``warn(text)`` gets the ``stiffness_warning()`` once contacts are detected, before the
        first step. Returns the steps done.

        A failed call leaves the model as it was before it: what the cycle changes (block
        motion fields, vertex positions, the contact and sub-contact stores, the engine
        settings, time, step, history samples) is copied first and put back when anything
        raises — a blow-up (``RunError``), a second Ctrl-C, an error in a hook. The copy costs
        about the memory of those stores once per call. The first Ctrl-C (or
        ``request_stop()``) stops at the end of the current batch instead (kernel calls last
        about ``CHUNK_SECONDS``): the model is consistent there and ``CycleInterrupted``
        (a KeyboardInterrupt) is raised after the state is stored."""
        m = self.model
        if m.blocks.n == 0 or nsteps <= 0:
            return 0
        snap = self._snapshot()
        self._spin0 = snap["blocks"]["spin"]
        _StopFlag.requested = False
        try:
            # a run that blows up is reported by the engine itself (RunError), not by numpy warnings
            with _sigint_stops_cycling(), np.errstate(over="ignore", invalid="ignore"):
                done = self._cycle(nsteps, stop, max_time, warn)
        except BaseException:
            self._restore(snap)
            _StopFlag.requested = False
            raise
        if _StopFlag.requested:
            _StopFlag.requested = False
            raise CycleInterrupted(m.step)
        return done

    def _snapshot(self) -> dict:
        m = self.model
        b, v = m.blocks, m.vertices
        hs = getattr(m, "history_set", None)
        return {"blocks": {k: b[k].copy() for k in b.fields},
                "vertices": {k: v[k].copy() for k in ("pos", "map_pos", "look_pos")
                             + (_GP_STATE if _has_gridpoints(m) else ()) if k in v},
                "zones": ({k: m.store("zones")[k].copy() for k in ("stress", "gstress", "volume", "state")}
                          if has_zones(m) else {}),
                "feblocks": ({k: m.store("feblocks")[k].copy() for k in ("stress", "gstress")}
                             if has_feblocks(m) else {}),
                # (to_arrays gives views where it can: copy them)
                "contacts": {k: a.copy() for k, a in self.contacts.to_arrays().items()},
                "subcontacts": {k: a.copy() for k, a in self.subcontacts.to_arrays().items()},
                "mech": copy.deepcopy(m.settings.mechanical), "time": m.time, "step": m.step,
                "engine": (self.dt, self.kinetic, self._cand, self._criteria),
                "histories": [(h, len(h.steps), len(h.times), len(h.values)) for h in (hs.items if hs else [])]}

    def _restore(self, snap: dict) -> None:
        m = self.model
        b, v = m.blocks, m.vertices
        for k, a in snap["blocks"].items():
            b.full(k)[: len(a)] = a
        for k, a in snap["vertices"].items():
            v.full(k)[: len(a)] = a
        for k, a in snap["zones"].items():
            m.store("zones").full(k)[: len(a)] = a
        for k, a in snap.get("feblocks", {}).items():
            m.store("feblocks").full(k)[: len(a)] = a
        self.contacts.load_arrays(snap["contacts"])
        self.subcontacts.load_arrays(snap["subcontacts"])
        mechanical = m.settings.mechanical
        mechanical.clear()
        mechanical.update(snap["mech"])
        m.time, m.step = snap["time"], snap["step"]
        self.dt, self.kinetic, self._cand, self._criteria = snap["engine"]
        for h, ns, nt, nv in snap["histories"]:
            del h.steps[ns:], h.times[nt:], h.values[nv:]

    def _blowup(self, bad: int, dt: float, far: bool) -> RunError:
        """The message of a run that became unstable at block row ``bad``: a spin blow-up
        names the angular speed [rad/s], a translation blow-up the speed [m/s]."""
        m = self.model
        b = m.blocks
        bid = int(b["id"][bad])
        w = math.hypot(*b["spin"][bad])                  # (hypot: no overflow on the way)
        v = math.hypot(*b["velocity"][bad])
        spin = not math.isfinite(w) or w * dt > 1.0
        if spin:
            w0 = math.hypot(*self._spin0[bad]) if getattr(self, "_spin0", None) is not None else math.nan
            if not math.isfinite(w):
                w = w0
            what = (f"spins at {w:.3g} rad/s ({w * dt:.3g} rad in one step of {dt:.3g} s)" if math.isfinite(w)
                    else "has a spin that is not a finite number")
        elif far:
            what = f"moved farther than its own size in one step (speed {v:.3g} m/s, time step {dt:.3g} s)"
        else:
            what = f"reached velocity {v:.3g} m/s (time step {dt:.3g} s too large or stiffness too high)"
        tail = ": it can pass through other blocks unseen" if far and not spin else ""
        return RunError(f"the run became unstable at step {m.step}: block {bid} {what}{tail}; "
                        "the model is back at its state before this command")

    def _cycle(self, nsteps: int, stop, max_time, warn=None) -> int:
        m = self.model
        b = m.blocks
        live = ~b["hidden"]
        if _has_gridpoints(m):
            return self._cycle_zoned(nsteps, stop, max_time, warn)
        if (b["mass"][live] <= 0).any():
            raise RunError("a block has no mass: set `block property density` before cycling")
        s = self.settings()
        g = np.asarray(m.settings.gravity, dtype=_F)
        mode, alpha = self.damping()
        full = self.full_inertia()
        gstart, gmember = self._groups()
        self._group_cache = (gstart, gmember)
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
        progress = _Progress(nsteps, self)
        fresh = self._signature != self._geometry_signature()
        if fresh:
            self.detect()
        if warn is not None:
            msg = self.stiffness_warning()
            if msg:
                warn(msg)
        # Δt follows the contact stiffnesses: worked out again at every detection (below). A run
        # that starts between two detections, on the step where the last run ended and with the
        # geometry as it left it, goes on with that run's Δt, so that a run split into several
        # commands (or saved and restored in between) takes exactly the steps of one run
        last = s["dt_run"]
        if (dt_fixed is None and not fresh and len(last) == 2 and int(last[1]) == m.step
                and m.step % interval != 0):
            dt, gimass, gisc = self._masses(gstart, gmember, gmass, giscalar, float(last[0]))
        else:
            dt, gimass, gisc = self._masses(gstart, gmember, gmass, giscalar, dt_fixed)
        self.dt = dt
        # detection also runs as soon as a block has moved CTOL/2 since the last one, so
        # that two blocks approaching each other cannot close more than CTOL unseen
        radius = self._radii()
        acc = np.zeros(b.n)
        motion = np.zeros(2)
        trigger = 0.5 * self.tolerance()
        due = False
        chunk = 10                       # steps per kernel call, adapted to CHUNK_SECONDS
        try:
            while done < nsteps and not _StopFlag.requested:
                if m.step % interval == 0 or due:
                    self.detect()
                    acc[:] = 0.0
                    due = False
                    if dt_fixed is None:
                        # the contacts made or lost change the stiffness each body feels
                        dt, gimass, gisc = self._masses(gstart, gmember, gmass, giscalar, None)
                        self.dt = dt
                    elif self.mass_scaling():
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
                # the batch of k steps runs as kernel calls of about CHUNK_SECONDS each, so that
                # Ctrl-C and progress are seen in time; the split changes no number (the kernel
                # carries its state in the arrays; time advances once per batch as before)
                n_ok = 0
                bad = -1
                while n_ok < k:
                    kk = min(k - n_ok, chunk)
                    t0 = _time.perf_counter()
                    c_ok, bad = run_steps(kk, dt, g, mode, alpha, servo, full, gstart, gmember, gmass, gimass, gisc,
                                          gprin, gaxes, gcen, b["mass"], fixity, b["force"], b["moment"], b["fapp"],
                                          b["mapp"], b["velocity"], b["spin"], b["centroid"], b["disp"],
                                          b["vert_start"], b["vert_count"], m.vertices["pos"], cs["a"], cs["b"],
                                          cs["normal"], cs["pos"], np.arange(cs.n, dtype=_I), cs["jmodel"],
                                          cs["prop"], ss["contact"], ss["pos"], ss["area"], ss["fn"], ss["fs"],
                                          ss["un"], ss["udil"], ss["us"], ss["state"], vmax, out, radius, acc,
                                          trigger, motion)
                    spent = _time.perf_counter() - t0
                    self.timings["cycle"] += spent
                    n_ok += c_ok
                    if bad >= 0 or motion[1] > 0.0 or c_ok < kk:
                        break
                    if c_ok > 0:
                        chunk = max(1, min(100000, int(c_ok * CHUNK_SECONDS / max(spent, 1e-9))))
                    progress.update(done + n_ok)
                    if _StopFlag.requested:
                        break
                due = motion[1] > 0.0
                m.step += n_ok
                m.time += n_ok * dt
                done += n_ok
                self._criteria = None
                if bad >= 0:
                    raise self._blowup(bad, dt, motion[1] == 2.0)
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
            self._group_cache = None
            progress.close()
            # keep each block's principal axes turning with its body; save the servo state
            turn = np.einsum("gij,gkj->gik", gaxes, axes0)
            gid = np.repeat(np.arange(ng), np.diff(gstart))
            pa = b["principal_axes"]
            # re-orthonormalised (polar factor): a slightly skew frame would grow threefold per
            # call (Q A Aᵀ A), and after ~30 `model cycle` commands Euler's equations blow up
            pa[gmember] = _orthonormal(np.einsum("bij,bjk->bik", turn[gid], pa[gmember]))
            # a lone block takes back the kernel's own frame unchanged: the next run starts from
            # exactly the axes this one ended with, so splitting a run into several `model cycle`
            # commands (or save/restore between them) changes no bit
            lone = np.diff(gstart) == 1
            pa[gmember[gstart[:-1][lone]]] = gaxes[lone]
            b["inertia"][gmember] = np.einsum("bij,bj,bkj->bik", pa[gmember], b["principal_moment"][gmember],
                                              pa[gmember])
            s["dt_run"] = [float(self.dt), int(m.step)]
            if mode == DAMP_ADAPTIVE:
                s["servo"] = [float(x) for x in servo[:NSERVO]]
        return done

    # ------------------------------------------------------------ models with zoned blocks
    def _zone_contacts_check(self) -> bool:
        """Contacts between two zoned blocks are not wired yet (issue "deformable blocks II"):
        refuse them, except between blocks of one joined set (linked gridpoints make those
        inert). Returns whether some contact joins a zoned block and a rigid one."""
        b, cs = self.model.blocks, self.contacts
        if not cs.n:
            return False
        za = _deformable(b["kind"][cs["a"]])
        zb = _deformable(b["kind"][cs["b"]])
        lead = np.where(b["leader"] < 0, np.arange(b.n), b["leader"])
        bad = za & zb & (lead[cs["a"]] != lead[cs["b"]])
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise RunError(f"{int(bad.sum())} contacts join two zoned (deformable) blocks that are not joined (the "
                           f"first between blocks {int(cs['ida'][k])} and {int(cs['idb'][k])}): contacts between "
                           "deformable blocks do not cycle yet (issue 10, next part); nothing was cycled")
        return bool((za ^ zb).any())

    def _mixed_weights(self, zst, recompute: bool = True) -> tuple:
        """Gridpoint rows and interpolation weights of every sub-contact and contact point on a
        zoned side (``gpcontact.surface_weights``), and the contact stiffness they give the
        gridpoints (the joint term of Eq. 85: max(kn, ks) · area, shared by the weights).

        They are kept in the contact stores (``gp_a gw_a gp_b gw_b``): made at a detection and
        used until the next one, so a run that starts between two detections (a split run, a
        restored model) takes them as the last run left them (``recompute=False``) instead of
        working them out from points that have moved since."""
        m = self.model
        b, f, v = m.blocks, m.faces, m.vertices
        cs, ss = self.contacts, self.subcontacts
        zoned = _deformable(b["kind"])
        stores = ((ss, ss["contact"]), (cs, np.arange(cs.n, dtype=_I)))
        if not recompute:
            # kept weights are usable only if every point on a zoned side has its triangle
            for st, owner in stores:
                for side, key in (("a", "gp_a"), ("b", "gp_b")):
                    if (st[key][zoned[cs[side][owner]], 0] < 0).any():
                        recompute = True
        if recompute:
            geo = (zoned, v["pos"], b["face_start"], b["face_count"], f["vstart"], f["nvert"],
                   m.face_vertices["vertex"])
            for st, owner in stores:
                k = len(owner)
                na, wa, nb, wb = np.empty((k, 3), _I), np.empty((k, 3)), np.empty((k, 3), _I), np.empty((k, 3))
                surface_weights(np.ascontiguousarray(owner), st["pos"], cs["a"], cs["b"], *geo, na, wa, nb, wb)
                st["gp_a"][:] = na
                st["gw_a"][:] = wa
                st["gp_b"][:] = nb
                st["gw_b"][:] = wb
        out = [tuple(st[key] for key in ("gp_a", "gw_a", "gp_b", "gw_b")) for st, _ in stores]
        na, wa, nb, wb = out[0]
        c = ss["contact"]
        kk = np.maximum(cs["prop"][c, P_KN], cs["prop"][c, P_KS]) * ss["area"]
        rows = np.concatenate((na.ravel(), nb.ravel()))
        kw = np.concatenate(((wa * kk[:, None]).ravel(), (wb * kk[:, None]).ravel()))
        on = rows >= 0
        zst.set_contact_stiffness(rows[on], kw[on])
        return out[0], out[1]

    def _cycle_zoned(self, nsteps: int, stop, max_time, warn=None) -> int:
        """``_cycle`` for a model with zoned blocks: per batch, the rigid bodies (if any) by
        ``run_steps`` and the zoned blocks step by step (``physics.zones.ZoneStepper``) with the
        same Δt. The two parts share no contact (``_zone_contacts_check``), so running the rigid
        steps of a batch before the zone steps of that batch is the same as interleaving them."""
        from .zones import ZoneStepper

        m = self.model
        b = m.blocks
        rigid = ~b["hidden"] & ~_deformable(b["kind"])
        if (b["mass"][rigid] <= 0).any():
            raise RunError("a block has no mass: set `block property density` before cycling")
        zst = ZoneStepper(m, RunError, warn)
        self._zstep = zst
        s = self.settings()
        g = np.asarray(m.settings.gravity, dtype=_F)
        mode, alpha = self.damping()
        full = self.full_inertia()
        large = bool(m.settings.large_strain)
        gstart, gmember = self._groups()
        self._group_cache = (gstart, gmember)
        ng = len(gstart) - 1
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
        progress = _Progress(nsteps, self)
        fresh = self._signature != self._geometry_signature()
        if fresh:
            self.detect()
        mixed = self._zone_contacts_check()
        last = s["dt_run"]
        # between two detections, where the last run ended: go on as that run would have
        between = not fresh and len(last) == 2 and int(last[1]) == m.step and m.step % interval != 0
        if mixed:
            wsub, wcon = self._mixed_weights(zst, recompute=not between)
        if warn is not None:
            msg = self.stiffness_warning()
            if msg:
                warn(msg)
        scaled = self.mass_scaling()

        def pick_dt() -> float:
            """Δt for the contacts as they are now (worked out again at every detection)."""
            if dt_fixed is not None:
                return dt_fixed
            dt_r = self._masses(gstart, gmember, gmass, giscalar, None)[0] if ng else math.inf
            d = (dt_r if ng else float(s["scale_timestep"] or 1.0)) if scaled else min(dt_r, zst.natural_timestep())
            return d if math.isfinite(d) and d > 0 else 1.0

        # as in `_cycle`: a run starting between detections where the last one ended goes on
        # with its Δt, so that split runs and save/restore change no number
        if dt_fixed is None and between:
            dt = float(last[0])
        else:
            dt = pick_dt()
        zst.set_masses(dt, scaled)
        if ng:
            _, gimass, gisc = self._masses(gstart, gmember, gmass, giscalar, dt)
        self.dt = dt
        radius = self._radii()
        acc = np.zeros(b.n)
        motion = np.zeros(2)
        trigger = 0.5 * self.tolerance()
        due = False
        loaded = large and "fstress" in m.faces and bool(np.any(m.faces["fstress"] != 0.0))
        try:
            while done < nsteps and not _StopFlag.requested:
                # with no rigid body and small strain nothing moves that could make a contact
                if (m.step % interval == 0 or due) and (ng or large):
                    self.detect()
                    mixed = self._zone_contacts_check()
                    acc[:] = 0.0
                    due = False
                    if mixed:
                        wsub, wcon = self._mixed_weights(zst)
                    old_dt, dt = dt, pick_dt()
                    self.dt = dt
                    if scaled and ng:
                        _, gimass, gisc = self._masses(gstart, gmember, gmass, giscalar, dt)
                    if mixed or dt != old_dt:
                        zst.set_masses(dt, scaled)
                    if loaded:
                        from dec3d.model.face_loads import recompute_fface
                        recompute_fface(m)
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
                t0 = _time.perf_counter()
                bad = -1
                n_ok = k
                if mixed:
                    n_ok = 0
                    self._mixed_steps(k, zst, wsub, wcon, dt, g, mode, alpha, servo, full, gstart, gmember, gmass,
                                      gimass, gisc, gprin, gaxes, gcen, fixity, large, vmax, out)
                    n_ok = k
                elif ng:
                    cs, ss = self.contacts, self.subcontacts
                    n_ok, bad = run_steps(k, dt, g, mode, alpha, servo, full, gstart, gmember, gmass, gimass, gisc,
                                          gprin, gaxes, gcen, b["mass"], fixity, b["force"], b["moment"], b["fapp"],
                                          b["mapp"], b["velocity"], b["spin"], b["centroid"], b["disp"],
                                          b["vert_start"], b["vert_count"], m.vertices["pos"], cs["a"], cs["b"],
                                          cs["normal"], cs["pos"], np.arange(cs.n, dtype=_I), cs["jmodel"],
                                          cs["prop"], ss["contact"], ss["pos"], ss["area"], ss["fn"], ss["fs"],
                                          ss["un"], ss["udil"], ss["us"], ss["state"], vmax, out, radius, acc,
                                          trigger, motion)
                    if bad >= 0:
                        raise self._blowup(bad, dt, motion[1] == 2.0)
                for _ in range(0 if mixed else n_ok):
                    zbad = zst.step(dt, g, mode, alpha, large, vmax)
                    if zbad >= 0:
                        raise zst.unstable(zbad, dt)
                zb = zst.blocks
                b["force"][zb] = 0.0            # contact forces on zoned blocks went to their gridpoints
                b["moment"][zb] = 0.0
                self.timings["cycle"] += _time.perf_counter() - t0
                due = motion[1] > 0.0
                m.step += n_ok
                m.time += n_ok * dt
                done += n_ok
                self._criteria = None
                self.kinetic = (float(out[2]) if ng else 0.0) + zst.kinetic
                t0 = _time.perf_counter()
                for hook in self.step_hooks:
                    hook(self)
                periodic_vtk(m)
                self.timings["hooks"] += _time.perf_counter() - t0
                progress.update(done)
                if stop is not None and stop(self):
                    break
        finally:
            self._group_cache = None
            progress.close()
            zst.finish(large)
            s["dt_run"] = [float(self.dt), int(m.step)]
            if ng:
                turn = np.einsum("gij,gkj->gik", gaxes, axes0)
                gid = np.repeat(np.arange(ng), np.diff(gstart))
                pa = b["principal_axes"]
                pa[gmember] = _orthonormal(np.einsum("bij,bjk->bik", turn[gid], pa[gmember]))
                lone = np.diff(gstart) == 1
                pa[gmember[gstart[:-1][lone]]] = gaxes[lone]
                b["inertia"][gmember] = np.einsum("bij,bj,bkj->bik", pa[gmember], b["principal_moment"][gmember],
                                                  pa[gmember])
            if mode == DAMP_ADAPTIVE:
                s["servo"] = [float(x) for x in servo[:NSERVO]]
        return done

    def _mixed_steps(self, k, zst, wsub, wcon, dt, g, mode, alpha, servo, full, gstart, gmember, gmass, gimass,
                     gisc, gprin, gaxes, gcen, fixity, large, vmax, out) -> None:
        """``k`` steps of a model where zoned and rigid blocks touch (3DEC theory, "Deformable
        blocks": a sub-contact on a deformable block moves with the gridpoints of the surface it
        lies on, its force goes to them by the interpolation factors): sub-contact forces
        (``gpcontact.mixed_subcontact_forces``), rigid motion, the zone step with the contact
        forces on the gridpoints, then the contact points move (``mixed_move_points``)."""
        m = self.model
        b, v = m.blocks, m.vertices
        cs, ss = self.contacts, self.subcontacts
        gvel = v["velocity"]
        gc = np.zeros((v.n, 3))
        touched = np.unique(np.concatenate((wsub[0].ravel(), wsub[2].ravel())))
        touched = touched[touched >= 0]
        cown = np.arange(cs.n, dtype=_I)
        for _ in range(k):
            facc = zst.begin()
            gc[touched] = 0.0
            mixed_subcontact_forces(dt, b["centroid"], b["velocity"], b["spin"], b["force"], b["moment"], gvel, gc,
                                    cs["a"], cs["b"], cs["normal"], cs["jmodel"], cs["prop"], ss["contact"], ss["pos"],
                                    ss["area"], ss["fn"], ss["fs"], ss["un"], ss["udil"], ss["us"], ss["state"],
                                    *wsub)
            facc[touched] += gc[touched]
            zst.fmag[touched] += np.linalg.norm(gc[touched], axis=1)
            if len(gmember):
                gbad = rigid_motion_groups(dt, g, mode, alpha, servo, full, gstart, gmember, gmass, gimass, gisc,
                                           gprin, gaxes, gcen, b["mass"], fixity, b["force"], b["moment"], b["fapp"],
                                           b["mapp"], b["velocity"], b["spin"], b["centroid"], b["disp"],
                                           b["vert_start"], b["vert_count"], v["pos"], vmax, out)
                if gbad >= 0 or not math.isfinite(out[0]):
                    raise self._blowup(int(gmember[gstart[gbad]]) if gbad >= 0 else int(gmember[0]), dt, False)
            zbad = zst.step(dt, g, mode, alpha, large, vmax, begun=True)
            if zbad >= 0:
                raise zst.unstable(zbad, dt)
            mixed_move_points(dt, cs["a"], cs["b"], cown, cs["pos"], b["centroid"], b["velocity"], b["spin"], gvel,
                              *wcon)
            mixed_move_points(dt, cs["a"], cs["b"], ss["contact"], ss["pos"], b["centroid"], b["velocity"],
                              b["spin"], gvel, *wsub)

    def timing_report(self) -> str:
        """The time spent per phase since the counters were last zeroed (seconds, share)."""
        t = self.timings
        tot = (t["detect"] + t["cycle"] + t["hooks"]) or 1e-30
        rows = [("detection", t["detect"]), ("  neighbour search", t["search"]),
                ("  sub-contacts", t["subcontacts"]), ("cycle kernel", t["cycle"]), ("histories, VTK", t["hooks"])]
        from dec3d.config import thread_report

        return "\n".join([f"{'phase':<20}{'seconds':>9}{'share':>8}"] +
                         [f"{k:<20}{v:9.3f}{100 * v / tot:7.1f}%" for k, v in rows] + [thread_report()])


def _orthonormal(a: np.ndarray) -> np.ndarray:
    """The nearest rotation to each (3, 3) matrix of ``a`` (the polar factor U Vᵀ of its SVD)."""
    ok = np.isfinite(a).all(axis=(1, 2))       # a blown-up run is rolled back; leave its NaN frames alone
    if not ok.any():
        return a
    out = a.copy()
    u, _, vt = np.linalg.svd(a[ok])
    out[ok] = u @ vt
    return out


def engine(model) -> RigidEngine:
    """The model's rigid engine, made on first use."""
    e = getattr(model, "rigid_engine", None)
    if e is None:
        e = RigidEngine(model)
        model.rigid_engine = e
    return e
