"""Rigid-block engine: settings and the calculation cycle (3DEC theory, Fig. 13).

State lives in the model: contacts and sub-contacts are two stores (``contacts``,
``subcontacts``, saved and restored with the rest; ``contacts.py``), the engine settings and
detection bookkeeping are ``model.settings.mechanical`` (plain JSON) and a few vertex/block
fields. The ``RigidEngine`` object on the model holds only what can be rebuilt: the
candidate pairs, the time step and timings. A restored run continues bit for bit (with
`mass-scale body`: to round-off, its masses are worked out again from the geometry).

Detection is ``contacts.ContactDetection`` and contacts with a zoned side
``mixedcontacts.MixedContactSteps`` (both mixed in). Cycling (``_cycle``) drives the ordered
list of steps of ``physics.steps`` (``_Run``, ``RigidBatch`` → kernel ``cycle.run_steps``, …):
many steps per kernel call, up to the next detection, history sample, VTK snapshot or solve check.
"""
from __future__ import annotations

import copy
import math
import time as _time

import numpy as np

from dec3d.errors import Dec3dError
from dec3d.kernels.balance import body_balance
from dec3d.kernels.joints import P_KN, P_KS
from dec3d.kernels.motion import DAMP_ADAPTIVE, DAMP_COMBINED, DAMP_LOCAL, DAMP_NONE, DAMP_RAYLEIGH, block_timestep
from dec3d.model.store import Store
from dec3d.model.feblocks import has_feblocks
from dec3d.model.zones import has_zones
from dec3d.units import suffix

from .beams import beam_balance, has_beams
from .liners import has_liners, liner_balance
from .cables import cable_timestep, grouted_timestep
from .massscale import DensityScaling
from .water import total_normal_force
from .contact_store import contact_stores
from .contacts import ContactDetection, default_row
from .dynamic import DYN_DEFAULTS, rayleigh_coefficients
from .jmodels import JOINT_MODELS, contact_stiffness, missing
from .mixedcontacts import MixedContactSteps, _deformable
from . import runcontrol as _runcontrol
from .runcontrol import CycleInterrupted, _sigint_stops_cycling, _StopFlag

#: part of this module's API (Ctrl-C's effect without a signal: stop at the end of the batch)
request_stop = _runcontrol.request_stop

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
    "scaling": "auto",         # density scaling: eq87 (Eq. 87, masses only raised) | body (stiffness row sums)
                               # | raised (body, no mass lowered) | auto (raised in static runs with local or
                               # combined damping, else eq87: RigidEngine.scaling)
    "safety": None,            # body scaling: ω_max Δt ≤ 2 × safety (None: SAFETY by damping mode)
    "dt_run": [],              # [Δt, step]: the step the last rigid run ended on and the Δt it was using
    **DYN_DEFAULTS,            # dynamic mode, dynamic time, Rayleigh damping, time functions (physics.dynamic)
}


class RunError(Dec3dError):
    """The run became unstable (NaN or runaway velocity). The engine has put the model back
    to its state before the ``cycle`` call that failed."""


#: vertex fields the deformable step changes (saved before a run, put back if it fails)
_GP_STATE = ("velocity", "disp", "force", "mass", "imass", "vapp", "fapp", "maxwell")   # (vapp, fapp: time functions;
#                                                                     maxwell: physics.dynamic)


def _has_gridpoints(m) -> bool:
    return has_zones(m) or has_feblocks(m)

#: local/maximum ratios are scaled by this so that they mean about the same as the average
#: (Itasca, ``zone ratio`` / ``structure ratio`` command pages, see ``RigidEngine.criteria``)
RATIO_SCALE = 0.1


def mech(model) -> dict:
    """The model's engine settings, with every default filled in."""
    m = model.settings.mechanical
    for k, v in MECH_DEFAULTS.items():
        if k not in m:
            m[k] = dict(v) if isinstance(v, dict) else list(v) if isinstance(v, list) else v
    return m


class RigidEngine(DensityScaling, ContactDetection, MixedContactSteps):
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
        #: factories ``make(run) -> step`` put first in every run's step list, before the forces
        #: (FISH callbacks at negative cycle-sequence positions, ``commands.fish_cmds``)
        self.pre_steps: list = []
        #: seconds per phase; "hooks" covers histories and periodic VTK snapshots
        self.timings = {"detect": 0.0, "search": 0.0, "subcontacts": 0.0, "cycle": 0.0, "hooks": 0.0}
        self._cand = None             # candidate pairs (rows A, rows B) of the last cell map
        #: detections that installed the contacts anew (what was made from the contact and
        #: sub-contact rows, e.g. the cycle kernel's lists, is made again when it changes)
        self.detections = 0
        #: the deformable step of the last run on a model with zones (``physics.zones``), or None
        self._zstep = None
        #: what zone steppers derived from the model, kept for the next command's (``physics.zone_cache``)
        self._zcache = None
        #: the steps of the last run's cycle, in order (``_Run``: RigidBatch, Clock, Hooks, ...)
        self.steps: list = []
        #: the last detection kept every contact as it was (``ContactDetection.detect``)
        self.detect_kept_all = False
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
        # the defaults this model has (a table may hold another model's properties, e.g. friction
        # set for mohr before `jmodel assign elastic`)
        drow = default_row(s, JOINT_MODELS[s["jmodel"]].code)
        kn = max(drow[P_KN], drow[P_KS])
        # Eqs. (87)-(88) over the blocks that move: a block whose six velocity components are all
        # held (`block fix`, `block apply velocity …`, or those of the leader it is joined to) takes
        # no force-driven step, so neither its mass nor its faces (a large fixed base) bound Δt
        live = (b["mass"] > 0) & ~b["hidden"]
        moving = live & ~self._held_still()
        if moving.any():
            live = moving
        c = self.contacts
        if c.n:
            on = live[c["a"]] | live[c["b"]]
            if on.any():
                kn = max(kn, float(np.maximum(*contact_stiffness(c, self.subcontacts))[on].max()))
        f = self.model.faces
        fb = f["block"]
        fa = f["area"][(fb >= 0) & live[np.maximum(fb, 0)]]
        area = float(fa.max()) if len(fa) else 1.0
        mmin = float(b["mass"][live].min()) if live.any() else 1.0
        dt = block_timestep(mmin, kn * area, float(s["frac"])) or 1e-3
        dt = min(dt, grouted_timestep(self.model, float(s["frac"]), live))   # blocks held by cable grout
        # cable nodes with their real masses (no density scaling: they are scaled to Δt otherwise)
        return dt if self.mass_scaling() else min(dt, cable_timestep(self.model))

    def _held_still(self) -> np.ndarray:
        """Per block: all six velocity components held (bits 0-5 of ``fixity | apply_fix``, of the
        block or of the leader of its joined group)."""
        b = self.model.blocks
        held = (b["fixity"] | b["apply_fix"]).astype(_I)
        lead = b["leader"]
        held = np.where(lead >= 0, held[np.maximum(lead, 0)], held)
        return (held & 63) == 63

    def damping(self) -> tuple[int, float]:
        """(damping mode code, α) for the motion kernel (Rayleigh: α is its mass term's viscous
        coefficient; in dynamic mode the static forms are off, physics.dynamic)."""
        s = self.settings()
        if s["damping"] == "rayleigh":
            return DAMP_RAYLEIGH, rayleigh_coefficients(self.model)[0]
        if s["dynamic"] or s["damping"] == "maxwell":
            return DAMP_NONE, 0.0
        code = {"none": DAMP_NONE, "local": DAMP_LOCAL, "combined": DAMP_COMBINED, "global": DAMP_ADAPTIVE}
        return code[s["damping"]], float(s["alpha"])

    def rayleigh_beta(self) -> float:
        """β [s] of Rayleigh damping's stiffness term on the contacts (0: none)."""
        return rayleigh_coefficients(self.model)[1] if self.settings()["damping"] == "rayleigh" else 0.0

    def _dynamic_style(self) -> bool:
        """Real masses and full inertia: dynamic mode, or no (or Rayleigh) damping."""
        s = self.settings()
        return bool(s["dynamic"]) or s["damping"] in ("none", "rayleigh", "maxwell")

    def mass_scaling(self) -> bool:
        s = self.settings()
        return s["mass_scale"] == "on" or (s["mass_scale"] == "auto" and not self._dynamic_style())

    def scaling(self) -> str:
        """Density scaling in effect when on: ``body`` (every body at the same critical step),
        ``raised`` (the same, no mass below its real value) or ``eq87``. Default (``auto``) of a
        static run with local or combined damping on rigid blocks only: ``raised`` (3DEC theory
        text, "Mass (Density) Scaling": "Density scaling is the default mode for static analysis",
        "inertial densities may be increased"); else Eq. (87) (see the command page)."""
        s = self.settings()
        if s["scaling"] != "auto":
            return s["scaling"]
        static = s["mass_scale"] == "auto" and s["damping"] in ("local", "combined")
        # (zoned or FE blocks: Eq. 87, the mixed energy balance measured 5e-9 instead of < 1e-9)
        return "raised" if static and not _has_gridpoints(self.model) else "eq87"

    def full_inertia(self) -> bool:
        s = self.settings()
        return s["inertia"] == "full" or (s["inertia"] == "auto" and self._dynamic_style())

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
                         cs["a"], cs["b"], cs["normal"], ss["contact"], total_normal_force(ss), ss["fs"],
                         np.empty((b.n, 3)),
                         np.empty(b.n), un, A)
        free = (held & 7) != 7
        un = un[free]
        A = A[free]
        if zst is not None:
            # gridpoints of zoned blocks count as bodies (Itasca's own definitions are for gridpoints)
            gu, ga = zst.balance()
            un = np.concatenate((un, gu))
            A = np.concatenate((A, ga))
        if has_beams(m):
            # beam nodes count as bodies too (``physics.beams.beam_balance``)
            bu, ba = beam_balance(m)
            un, A = np.concatenate((un, bu)), np.concatenate((A, ba))
        if has_liners(m):
            # liner nodes too (``physics.liners.liner_balance``)
            lu, la = liner_balance(m)
            un, A = np.concatenate((un, lu)), np.concatenate((A, la))
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

    def property_problem(self) -> str | None:
        """Why the joints cannot run (a contact in use lacks a property its model needs), or None:
        the run stops before its first step with this message (``jmodels.missing``)."""
        cs = self.contacts
        if self.model.blocks.n == 0 or cs.n == 0:
            return None
        follow = cs["own_props"] == 0
        prop = cs["prop"].copy()
        for code in np.unique(cs["jmodel"][follow]):
            prop[follow & (cs["jmodel"] == code)] = default_row(self.settings(), int(code), prop.shape[1])
        return missing(cs, prop)

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
        follow = cs["own_props"] == 0             # these take the defaults at the next detection
        codes = [int(code) for code in np.unique(cs["jmodel"][follow])]
        rows = {code: default_row(self.settings(), code, cs["prop"].shape[1]) for code in codes}
        if (all(r[P_KN] > 0.0 and r[P_KS] > 0.0 for r in rows.values())
                and (cs["prop"][:, P_KN] > 0.0).all() and (cs["prop"][:, P_KS] > 0.0).all()):
            return None                           # (every stiffness set: no copy of the table)
        used = cs["sub_count"] > 0
        prop = cs["prop"].copy()
        for code, row in rows.items():
            prop[follow & (cs["jmodel"] == code)] = row
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

    def predict_timestep(self) -> float:
        """The time step the next cycle would start with (detection, masses and zone steps worked
        out as a run does), the model left exactly as it was: for listings before the first cycle
        (3DEC's `model dynamic list` prints the step it will use). Raises RunError when the model
        cannot cycle yet (a block without mass, properties missing)."""
        from .steps import _Run

        snap = self._snapshot()
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                return float(_Run(self, 0, None).dt)
        finally:
            self._restore(snap)

    def _snapshot(self) -> dict:
        m = self.model
        b, v = m.blocks, m.vertices
        hs = getattr(m, "history_set", None)
        return {"blocks": {k: b[k].copy() for k in b.fields},
                "vertices": {k: v[k].copy() for k in ("pos", "map_pos", "look_pos", "turn_pos")
                             + (_GP_STATE if _has_gridpoints(m) else ()) if k in v},
                "zones": ({k: m.store("zones")[k].copy() for k in ("stress", "gstress", "volume", "state", "hist", "ghist")
                           if k in m.store("zones")} if has_zones(m) else {}),
                "feblocks": ({k: m.store("feblocks")[k].copy() for k in ("stress", "gstress")}
                             if has_feblocks(m) else {}),
                # cable nodes, elements and dowels, beam nodes and elements: every field, rolled back with the blocks
                "cables": {n: {k: m.stores[n][k].copy() for k in m.stores[n].fields}
                           for n in ("cable_nodes", "cable_segments", "cable_dowels", "beam_nodes", "beam_elements",
                                     "liner_nodes", "liner_elements")
                           if n in m.stores},
                # (to_arrays gives views where it can: copy them)
                "contacts": {k: a.copy() for k, a in self.contacts.to_arrays().items()},
                "subcontacts": {k: a.copy() for k, a in self.subcontacts.to_arrays().items()},
                # the flow network (physics.flownet): rebuilt in a run, so its row counts too
                "flow": {n: {k: a.copy() for k, a in m.stores[n].to_arrays().items()}
                         for n in ("flowknots", "flowzones", "flowpipes", "flowsubs") if n in m.stores},
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
        for n, fields in snap.get("cables", {}).items():
            for k, a in fields.items():
                m.stores[n].full(k)[: len(a)] = a
        self.contacts.load_arrays(snap["contacts"])
        self.subcontacts.load_arrays(snap["subcontacts"])
        for n, arrays in snap.get("flow", {}).items():
            m.stores[n].load_arrays(arrays)
        mechanical = m.settings.mechanical
        mechanical.clear()
        mechanical.update(snap["mech"])
        m.time, m.step = snap["time"], snap["step"]
        self.dt, self.kinetic, self._cand, self._criteria = snap["engine"]
        for h, ns, nt, nv in snap["histories"]:
            del h.steps[ns:], h.times[nt:], h.values[nv:]

    def _blowup(self, bad: int, dt: float, far: bool, step: int | None = None) -> RunError:
        """The message of a run that became unstable at block row ``bad`` (at ``step``, default
        the model's): a spin blow-up names the angular speed [rad/s], a translation blow-up the
        speed [m/s]."""
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
            what = (f"spins at {w:.3g}{suffix(m, 'angular-velocity')} ({w * dt:.3g} rad in one step of {dt:.3g}"
                    f"{suffix(m, 'time')})" if math.isfinite(w)
                    else "has a spin that is not a finite number")
        elif far:
            what = (f"moved farther than its own size in one step (speed {v:.3g}{suffix(m, 'velocity')}, time step "
                    f"{dt:.3g}{suffix(m, 'time')})")
        else:
            what = (f"reached velocity {v:.3g}{suffix(m, 'velocity')} (time step {dt:.3g}{suffix(m, 'time')} too large "
                    "or stiffness too high)")
        tail = ": it can pass through other blocks unseen" if far and not spin else ""
        return RunError(f"the run became unstable at step {m.step if step is None else step}: block {bid} {what}{tail}; "
                        "the model is back at its state before this command")

    def _cycle(self, nsteps: int, stop, max_time, warn=None) -> int:
        """The cycle (3DEC theory, Fig. 13) as one driver over an ordered list of steps
        (``self.steps``, built per run by ``_Run``): detection when due, then per batch of k
        steps each step's ``advance`` in order, the clock, the hooks. Batches end at the next
        detection, history sample, VTK snapshot, ``max_time`` or ``nsteps``."""
        m = self.model
        from .steps import _Run

        run = _Run(self, nsteps, warn)
        self.steps = run.steps
        interval = run.interval
        try:
            while run.done < nsteps and not _StopFlag.requested:
                if run.detection_due():
                    if run.quiet():
                        run.skipped()
                    else:
                        self.detect()
                        run.detected()
                k = min(nsteps - run.done, interval - m.step % interval, run.fluid_cap)
                for h in self.step_hooks:
                    hi = int(getattr(h, "interval", 0) or 0)
                    if hi > 0:
                        k = min(k, hi - m.step % hi)
                vtk = m.outputs.get("vtk")
                if vtk and vtk["interval"] > 0:
                    k = max(1, min(k, vtk["last_step"] + vtk["interval"] - m.step))
                if max_time is not None:
                    left = int(math.ceil((max_time - m.time) / run.dt - 1e-9))
                    if left <= 0:
                        break
                    k = min(k, left)
                n = k                    # each step passes on how many steps the batch really took
                for st in run.steps:
                    t0 = _time.perf_counter()
                    n = st.advance(n)
                    if st.timing:
                        self.timings[st.timing] += _time.perf_counter() - t0
                run.progress.update(run.done)
                if stop is not None and stop(self):
                    break
        finally:
            run.finish()
            # the steps hold their run (``self.run``) and the run its steps: left so, each `model cycle`
            # command's run (with its zone stepper, hundreds of MB at 1e6 zones) would live on until
            # Python's cyclic collector happened to run. The engine keeps the last run's steps
            # (``self.steps``, and through them that run) until the next command replaces them
            run.steps = []
        return run.done

    def timing_report(self) -> str:
        """The time spent per phase since the counters were last zeroed (seconds, share)."""
        t = self.timings
        tot = (t["detect"] + t["cycle"] + t["hooks"]) or 1e-30
        rows = [("detection", t["detect"]), ("  neighbour search", t["search"]),
                ("  sub-contacts", t["subcontacts"]), ("cycle kernel", t["cycle"]), ("histories, VTK", t["hooks"])]
        from dec3d.config import thread_report

        return "\n".join([f"{'phase':<20}{'seconds':>9}{'share':>8}"] +
                         [f"{k:<20}{v:9.3f}{100 * v / tot:7.1f}%" for k, v in rows] + [thread_report()])


def engine(model) -> RigidEngine:
    """The model's rigid engine, made on first use."""
    e = getattr(model, "rigid_engine", None)
    if e is None:
        e = RigidEngine(model)
        model.rigid_engine = e
    return e
