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

import math
import sys
import time as _time

import numpy as np

from dec3d.errors import Dec3dError
from dec3d.io.vtk import periodic_vtk
from dec3d.kernels.cycle import run_steps
from dec3d.kernels.jointlaw import P_KN, P_KS
from dec3d.kernels.motion import DAMP_ADAPTIVE, DAMP_COMBINED, DAMP_LOCAL, DAMP_NONE, NSERVO, S_HIST, block_timestep
from dec3d.model.store import Store

from .bodies import group_properties, inertial_masses, new_servo
from .contacts import ContactDetection, contact_stores
from .jmodels import JOINT_MODELS

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
}


class RunError(Dec3dError):
    """The run became unstable (NaN or runaway velocity)."""


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
            # re-orthonormalised (polar factor): a slightly skew frame would grow threefold per
            # call (Q A Aᵀ A), and after ~30 `model cycle` commands Euler's equations blow up
            pa[gmember] = _orthonormal(np.einsum("bij,bjk->bik", turn[gid], pa[gmember]))
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


def _orthonormal(a: np.ndarray) -> np.ndarray:
    """The nearest rotation to each (3, 3) matrix of ``a`` (the polar factor U Vᵀ of its SVD)."""
    if not len(a):
        return a
    u, _, vt = np.linalg.svd(a)
    return u @ vt


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
