"""The cycle of one ``model cycle`` as an ordered list of steps (3DEC theory, Fig. 13).

``RigidEngine._cycle`` (``physics.rigid``) is the driver: detection when due, then per batch
each step's ``advance``. This module holds what one run works with (``_Run``: rigid groups,
damping state, Δt, the zone stepper) and the steps themselves:

    rigid blocks only:   RigidBatch → Clock → Hooks
    with zoned/FE blocks: MixedContacts → RigidBatch → ZoneStep → Clock → Hooks

(time functions put ``dynamic.TimeFunctions`` first; energy tracking wraps the force and motion
steps in ``energy.EnergyBefore``/``EnergyAfter``). The rigid kernels take named bundles of the
stores' arrays (``kernels.bundles``), made here from the declared stores.
"""
from __future__ import annotations

import math
import time as _time

import numpy as np

from dec3d.io.vtk import periodic_vtk
from dec3d.kernels.bundles import (NSERVO, Bodies, Bounds, Contacts, Groups, SubContacts, load_servo, new_damping,
                                   new_servo, servo_values)
from dec3d.kernels.contactmap import blocks_moved
from dec3d.kernels.joints import cycle_mask, model_mask
from dec3d.physics.jmodels import changing_stiffness
from dec3d.kernels.cycle import cycle_lists, run_steps
from dec3d.kernels.motion import DAMP_ADAPTIVE

from . import contacts as _contacts
from .contact_store import history_columns, property_columns
from .bodies import group_properties
from .cables import cable_steps
from .dynamic import TimeFunctions, has_timefns, maxwell_components, maxwell_timestep, stiffness_timestep
from .energy import is_active as is_energy_active
from .history import HistorySet
from .mixedcontacts import _deformable
from .rigid import RigidEngine, RunError, _has_gridpoints
from .runcontrol import _Progress, _StopFlag
from .water import refresh_if_stale
from .flownet import active as fluid_active, advance as fluid_advance, after_detection as fluid_after_detection
from .flownet import to_subcontacts as fluid_to_subcontacts

_F = np.float64
_I = np.int64

#: leave out a periodic detection that would look at no pair again (``_Run.quiet``)
SKIP_QUIET = True

#: target wall time of one kernel call [s]: Ctrl-C and progress are seen at least this often
CHUNK_SECONDS = 0.2


def _orthonormal(a: np.ndarray) -> np.ndarray:
    """The nearest rotation to each (3, 3) matrix of ``a`` (the polar factor U Vᵀ of its SVD)."""
    ok = np.isfinite(a).all(axis=(1, 2))       # a blown-up run is rolled back; leave its NaN frames alone
    if not ok.any():
        return a
    out = a.copy()
    u, _, vt = np.linalg.svd(a[ok])
    out[ok] = u @ vt
    return out


# ------------------------------------------------------------------ the cycle as a list of steps
class _Run:
    """What one ``model cycle`` works with, set up once (rigid groups and their properties,
    damping/servo state, fixity, Δt, the zone stepper of zoned blocks), and its list of steps:

    rigid blocks only:  RigidBatch → Clock → Hooks
    with zoned blocks:  MixedContacts → RigidBatch → ZoneStep → Clock → Hooks

    Each step has ``prepare()`` (after every detection) and ``advance(n) -> n`` (n steps of
    the batch; a step may take fewer, e.g. the rigid kernel stops early when a block has moved
    far enough to need a detection, and passes on how many it took). ``finish()`` stores what
    the next run continues from (principal axes, servo state, ``dt_run``)."""

    def __init__(self, eng: RigidEngine, nsteps: int, warn):
        self.eng = eng
        m = self.m = eng.model
        b = self.b = m.blocks
        self.zoned = _has_gridpoints(m)
        body = ~b["hidden"] & ~_deformable(b["kind"]) if self.zoned else ~b["hidden"]
        if (b["mass"][body] <= 0).any():
            raise RunError("a block has no mass: set `block property density` before cycling")
        self.zst = None
        if self.zoned:
            from .zone_cache import stepper_cache
            from .zones import ZoneStepper

            self.zst = eng._zstep = ZoneStepper(m, RunError, warn, stepper_cache(eng))
        s = self.s = eng.settings()
        self.g = np.asarray(m.settings.gravity, dtype=_F)
        self.mode, self.alpha = eng.damping()
        self.full = eng.full_inertia()
        self.large = bool(m.settings.large_strain)
        gstart, gmember = self.gstart, self.gmember = eng._groups()
        eng._group_cache = (gstart, gmember)
        self.ng = len(gstart) - 1
        # orientation of each block: its principal axes are kept current (finish)
        inertia = np.einsum("bij,bj,bkj->bik", b["principal_axes"], b["principal_moment"], b["principal_axes"])
        (self.gmass, self.gcen, _, self.gprin, self.gaxes,
         self.giscalar) = group_properties(gstart, gmember, b["mass"], b["centroid"], inertia, b["inertia_approx"],
                                           b["principal_moment"], b["principal_axes"])
        self.axes0 = self.gaxes.copy()
        servo = new_servo(ratio=float(s["servo_ratio"]))
        if self.mode == DAMP_ADAPTIVE and len(s["servo"]) == NSERVO:
            load_servo(servo, s["servo"])
        servo.hist[0] = 0.0             # (no previous forces of these groups yet)
        #: the damping state of the run (``kernels.bundles.Damping``: mode, α, servo, previous forces)
        self.damping = new_damping(self.mode, self.alpha, self.ng, servo)
        self.fixity = (b["fixity"] | b["apply_fix"]).astype(np.uint8)
        self.dt_fixed = float(s["timestep"]) if s["timestep"] else None
        self.gimass = self.gisc = None
        self.out = np.zeros(4)
        self.vmax = 1e6
        self.interval = max(1, int(m.settings.update_interval))
        self.done = 0
        self.progress = _Progress(nsteps, eng)
        self.steps = ([MixedContacts(self), RigidBatch(self, chunked=False), ZoneStep(self)] if self.zoned
                      else [RigidBatch(self, chunked=True)]) + [Clock(self), Hooks(self)]
        self.beta = eng.rayleigh_beta()
        #: Maxwell damping's components (physics.dynamic): zones and FE elements only
        self.maxwell = maxwell_components(m)
        if self.zst is not None:
            self.zst.beta = self.beta
            self.zst.maxwell = self.maxwell
        self.dynamic = bool(s["dynamic"])
        # grouted cables (``physics.cables``): their forces at t go into the host blocks' applied loads
        self.steps[:0] = cable_steps(self)
        if has_timefns(m):
            self.steps.insert(0, TimeFunctions(self))
        if is_energy_active(m):
            # energy tracking (`model energy active on`): EnergyBefore → … → EnergyAfter → Clock → Hooks
            from .energy import energy_steps
            self.steps = energy_steps(self, self.steps, RunError)
        self.steps[:0] = [make(self) for make in eng.pre_steps]
        fresh = eng._signature != eng._geometry_signature()
        if fresh:
            eng.detect()
        elif self.zoned and not self.ng and not self.large:
            # (zoned blocks alone in small strain never reach a periodic detection: the contacts
            # take the material-table defaults set since the last one here)
            eng.follow_defaults()
        #: a detection has run in this run (``quiet`` never leaves out the first one)
        self.looked = fresh
        self.mixed = eng._zone_contacts_check() if self.zoned else False
        # Δt follows the contact stiffnesses: worked out again at every detection. A run that
        # starts between two detections, on the step where the last run ended and with the
        # geometry as it left it, goes on with that run's Δt (and contact-point weights), so
        # that a run split into several commands (or saved and restored in between) takes
        # exactly the steps of one run
        last = s["dt_run"]
        between = not fresh and len(last) == 2 and int(last[1]) == m.step and m.step % self.interval != 0
        # ... unless the masses or the damping's time-step rule changed since (dynamic mode, damping)
        self.dt_mode = [bool(eng.mass_scaling()), float(eng.rayleigh_beta())] + (
            [sum(a for a, _ in self.maxwell)] if self.maxwell else [])
        between = between and s.get("dt_mode", self.dt_mode) == self.dt_mode
        if self.mixed:
            self.wsub, self.wcon = eng._mixed_weights(self.zst, recompute=not between)
        history_columns(eng.subcontacts, eng.contacts["jmodel"])   # (a restored or edited model)
        property_columns(eng.contacts, model_mask(eng.contacts["jmodel"]))
        refresh_if_stale(eng)              # pore pressures (physics.water) after a change of their sources
        #: steps per batch at most: 1 while flow in the joints is coupled to moving blocks (physics.flownet)
        self.fluid_cap = 2 ** 62
        if fluid_active(m):
            fluid_after_detection(eng)
            self.steps.insert(self.steps.index(next(s for s in self.steps if isinstance(s, Clock))), FluidStep(self))
            moving = self.zoned or bool(np.any((self.fixity[~b["hidden"]] & 7) != 7))
            self.fluid_cap = 1 if moving else 2 ** 62
        bad = eng.property_problem()
        if bad:
            raise RunError(bad)
        if warn is not None:
            msg = eng.stiffness_warning()
            if msg:
                warn(msg)
            if self.maxwell and (self.ng or eng.contacts.n or not self.zoned):
                warn("maxwell damping acts on the zones and FE elements only: "
                     + ("this model has none, so nothing is damped" if not self.zoned else
                        "its rigid blocks and contacts are not damped by it"))
        self.scaled = eng.mass_scaling()
        # density scaling by body works its masses out from the geometry, which moves between
        # detections: a run that starts on the step where the last one ended takes that run's
        # masses and Δt back (block fields ``scaled_mass``, ``scaled_inertia``) unless what they
        # depend on besides the geometry changed, so a split run takes exactly the steps of one run
        self.by_body = self.scaled and eng.scaling() in ("body", "raised") and self.ng > 0
        self.scale_key = self._scale_key() if self.by_body else ""
        self.body_dt_set = False
        resume = (self.by_body and not fresh and len(last) == 2 and int(last[1]) == m.step
                  and s.get("dt_mode", self.dt_mode) == self.dt_mode and s.get("scale_key") == self.scale_key
                  and bool(np.all(b["scaled_mass"][gmember] > 0)))
        between = between or (resume and self.dt_fixed is None)
        dt_last = float(last[0]) if self.dt_fixed is None and between else None
        if self.zoned:
            if dt_last is not None and not self.scaled and getattr(self.zst, "cdash", None) is not None:
                dt_last = min(dt_last, self.zst.natural_timestep())    # quiet faces applied since
            dt = dt_last if dt_last is not None else self._zoned_dt()
            self.zst.set_masses(dt, self.scaled)
            if self.ng:
                self.masses(dt)
        elif resume:
            lead = gmember[gstart[:-1]]
            self.gimass, self.gisc = b["scaled_mass"][lead].copy(), b["scaled_inertia"][lead].copy()
            self.body_dt_set = True
            dt = dt_last if dt_last is not None else self.dt_fixed
        else:
            dt = self.masses(dt_last if dt_last is not None else self.dt_fixed)
        self.dt = eng.dt = dt
        servo = self.damping.servo
        if self.mode == DAMP_ADAPTIVE and self.by_body and not servo.alpha[0] > 0.0:
            # a fresh servo starts where it aims for the fastest mode density scaling by body lets
            # through, ω = 2 s / Δt: R = π α_v / (2ω) = ratio (``kernels.motion``). The 0.02/Δt
            # the kernel starts from otherwise left a block set down on an incline ringing at
            # ω Δt ≈ 1 for some 300 steps, sliding 65 mm where it then held (1.4 mm with Eq. 87)
            servo.alpha[0] = 2.0 * float(s["servo_ratio"]) * (2.0 * eng.body_safety() / dt) / math.pi
        # detection also runs as soon as a block has moved CTOL/2 since the last one, so
        # that two blocks approaching each other cannot close more than CTOL unseen
        # (the rigid kernel's motion bounds: no rigid body, no use for them — a pass over every gridpoint)
        self.radius = eng._radii() if self.ng else np.zeros(b.n)
        self.acc = np.zeros(b.n)
        self.motion = np.zeros(2)
        self.trigger = 0.5 * eng.tolerance()
        self.due = False
        self.loaded = (self.large and "fstress" in m.faces and bool(np.any(m.faces["fstress"] != 0.0)))

    def groups(self) -> Groups:
        """The rigid groups of the run as the motion kernel takes them (their inertial masses
        change with Δt, so the bundle is made again per kernel call)."""
        return Groups(self.gstart, self.gmember, self.gmass, self.gimass, self.gisc, self.gprin, self.gaxes, self.gcen)

    def bodies(self) -> Bodies:
        """The block store's motion fields and the vertex positions, as the kernels take them."""
        b = self.b
        return Bodies(b["mass"], self.fixity, b["force"], b["moment"], b["fapp"], b["mapp"], b["velocity"], b["spin"],
                      b["centroid"], b["disp"], b["vert_start"], b["vert_count"], self.m.vertices["pos"])

    def masses(self, dt, near=None):
        """Inertial masses of the rigid groups for Δt ``dt`` (None: Δt from the stiffnesses, or
        ``near`` when it is close, by body); returns Δt."""
        dt, self.gimass, self.gisc = self.eng._masses(self.gstart, self.gmember, self.gmass, self.giscalar, dt,
                                                      near, self.gprin)
        if self.by_body:
            # (Δt set from contacts: from now on it never grows in this run, ``_body_masses``)
            self.body_dt_set = self.body_dt_set or self.eng.body_dt_from_contacts
            counts = np.diff(self.gstart)
            self.b["scaled_mass"][self.gmember] = np.repeat(self.gimass, counts)
            self.b["scaled_inertia"][self.gmember] = np.repeat(self.gisc, counts)
        return dt

    def _scale_key(self) -> str:
        """What density scaling by body depends on besides the geometry and the contacts: its
        settings and the bodies (membership, fixity, masses), as a short digest."""
        import hashlib

        s = self.s
        h = hashlib.sha1(repr((self.eng.scaling(), s["safety"], s["scale_timestep"], s["damping"],
                               self.full)).encode())
        for a in (self.gstart, self.gmember, self.fixity, self.gmass, self.giscalar):
            h.update(np.ascontiguousarray(a).tobytes())
        return h.hexdigest()[:16]

    def _keeps_masses(self) -> bool:
        """A detection that kept every contact as it was leaves density scaling by body as it is
        (as a detection left out does, ``quiet``: a run resumed there then agrees with one run)."""
        return (self.by_body and self.eng.detect_kept_all and self.gimass is not None
                and not changing_stiffness(self.eng.contacts))

    def _zoned_dt(self) -> float:
        """Δt of a model with zoned blocks for the contacts as they are now."""
        if self.dt_fixed is not None:
            return self.dt_fixed
        ng = self.ng
        near = getattr(self, "dt", None) if self.by_body and self.body_dt_set else None
        dt_r = (self.eng._masses(self.gstart, self.gmember, self.gmass, self.giscalar, None, near, self.gprin)[0] if ng
                else math.inf)
        d = ((dt_r if ng else float(self.s["scale_timestep"] or 1.0)) if self.scaled
             else min(dt_r, maxwell_timestep(stiffness_timestep(self.zst.natural_timestep(), self.beta),
                                             self.maxwell)))
        return d if math.isfinite(d) and d > 0 else 1.0

    def detection_due(self) -> bool:
        # (with zoned blocks, no rigid body and small strain nothing moves that could make a contact)
        return ((self.m.step % self.interval == 0 or self.due)
                and (not self.zoned or bool(self.ng) or self.large))

    def quiet(self) -> bool:
        """Whether the detection now due may be left out (``SKIP_QUIET``): no block has moved more
        than QUIET × CTOL since it was last looked at, so detection would look at no pair again
        and keep every contact and sub-contact as it is. Never for the first detection of a run
        (commands between runs may have changed contact defaults, which a detection applies), nor
        with zoned blocks, a motion trigger, a geometry change, or a step hook other than
        histories (a FISH callback may change what a detection reads), nor when a joint model in use
        answers its own stiffness (it changes with the joint's state, not with motion: Δt and the
        masses follow it at every detection)."""
        eng = self.eng
        if (not SKIP_QUIET or not self.looked or self.zoned or self.due or _contacts.QUIET <= 0.0
                or changing_stiffness(eng.contacts)
                or eng._signature != eng._geometry_signature() or eng.settings().get("grid") is None
                or any(not isinstance(h, HistorySet) for h in eng.step_hooks)):
            return False
        t0 = _time.perf_counter()
        b, v = self.b, self.m.vertices
        moved = np.zeros(b.n, bool)
        blocks_moved(v["pos"], v["look_pos"], b["vert_start"], b["vert_count"], _contacts.QUIET * eng.tolerance(),
                     moved)
        eng.timings["detect"] += _time.perf_counter() - t0
        return not moved.any()

    def skipped(self) -> None:
        """A detection left out: what one that keeps every contact would do — the motion
        bounds start again; contacts, Δt and masses stay."""
        self.acc[:] = 0.0
        self.due = False

    def detected(self) -> None:
        """After a detection: contacts changed, so the steps prepare again and Δt and the
        masses follow the new stiffnesses."""
        eng = self.eng
        self.looked = True
        # large strain: the zones' stiffness (Δt, scaled masses) follows the geometry at every
        # detection step that is a multiple of the update interval — the step number alone, so
        # a split or restored run takes the same steps (``ZoneStepper.regeometry``)
        regeo = self.zoned and self.large and self.m.step % self.interval == 0
        if regeo:
            self.zst.regeometry()
        if self.zoned:
            self.mixed = eng._zone_contacts_check()
        self.acc[:] = 0.0
        self.due = False
        for st in self.steps:
            st.prepare()
        if not self.zoned:
            if self._keeps_masses():
                return
            if self.dt_fixed is None:
                # the contacts made or lost change the stiffness each body feels
                self.dt = eng.dt = self.masses(None, self.dt if self.by_body and self.body_dt_set else None)
            elif eng.mass_scaling():
                self.masses(self.dt)
            return
        old_dt, self.dt = self.dt, self._zoned_dt()
        eng.dt = self.dt
        if self.scaled and self.ng:
            self.masses(self.dt)
        if self.mixed or self.dt != old_dt or regeo:
            self.zst.set_masses(self.dt, self.scaled)
        if self.loaded:
            from dec3d.model.face_loads import recompute_fface
            recompute_fface(self.m)

    def finish(self) -> None:
        eng, m, b, s = self.eng, self.m, self.b, self.s
        eng._group_cache = None
        self.progress.close()
        if self.zoned:
            self.zst.finish(self.large)
        s["dt_run"] = [float(eng.dt), int(m.step)]
        s["dt_mode"] = self.dt_mode
        s["scale_key"] = self.scale_key
        if self.ng or not self.zoned:
            # keep each block's principal axes turning with its body
            gstart, gmember, gaxes = self.gstart, self.gmember, self.gaxes
            pa = b["principal_axes"]
            lone = np.diff(gstart) == 1
            joined = np.flatnonzero(~lone)
            if len(joined):
                # the members of joined groups turn with their group; re-orthonormalised (polar
                # factor): a slightly skew frame would grow threefold per call (Q A Aᵀ A), and
                # after ~30 `model cycle` commands Euler's equations blow up
                turn = np.einsum("gij,gkj->gik", gaxes[joined], self.axes0[joined])
                gid = np.repeat(np.arange(self.ng), np.diff(gstart))
                sel = ~lone[gid]
                rows = gmember[sel]
                k = (np.cumsum(~lone) - 1)[gid[sel]]          # each member's row of ``turn``
                pa[rows] = _orthonormal(np.einsum("bij,bjk->bik", turn[k], pa[rows]))
            # a lone block takes back the kernel's own frame unchanged: the next run starts from
            # exactly the axes this one ended with, so splitting a run into several `model cycle`
            # commands (or save/restore between them) changes no bit
            pa[gmember[gstart[:-1][lone]]] = gaxes[lone]
            b["inertia"][gmember] = np.einsum("bij,bj,bkj->bik", pa[gmember], b["principal_moment"][gmember],
                                              pa[gmember])
        if self.mode == DAMP_ADAPTIVE:
            s["servo"] = servo_values(self.damping.servo)


class _Step:
    """One step of the cycle: ``prepare()`` after each detection, ``advance(n)`` for n steps of a
    batch (returns the steps taken); ``timing``: the counter of ``engine.timings`` it adds to."""
    timing = "cycle"

    def __init__(self, run: _Run):
        self.run = run

    def prepare(self) -> None:
        pass

    def advance(self, n: int) -> int:
        return n

    def __repr__(self) -> str:
        return type(self).__name__


class MixedContacts(_Step):
    """Where zoned and rigid blocks touch: whole steps of sub-contact forces on gridpoints,
    rigid motion and the zone step together (``RigidEngine._mixed_steps``)."""

    def prepare(self) -> None:
        r = self.run
        if r.mixed:
            r.wsub, r.wcon = r.eng._mixed_weights(r.zst)

    def advance(self, n: int) -> int:
        r = self.run
        if r.mixed:
            r.eng._mixed_steps(n, r.zst, r.wsub, r.wcon, r.dt, r.g, r.full, r.damping, r.groups(), r.bodies(),
                               r.large, r.vmax, r.out)
        return n


class RigidBatch(_Step):
    """Contact forces and motion of the rigid bodies: the fused kernel ``cycle.run_steps``.
    ``chunked``: in kernel calls of about CHUNK_SECONDS each, so that Ctrl-C and progress are
    seen in time (the split changes no number: the kernel carries its state in the arrays)."""

    def __init__(self, run: _Run, chunked: bool):
        super().__init__(run)
        self.chunked = chunked
        self.chunk = 10                  # steps per kernel call, adapted to CHUNK_SECONDS
        #: ``cycle.cycle_lists`` of the contacts as last detected, and that detection's number
        self.lists = None
        self.listed = -1

    def advance(self, k: int) -> int:
        r = self.run
        if r.mixed or not r.ng:
            return k
        eng, m = r.eng, r.m
        cs, ss = eng.contacts, eng.subcontacts
        contacts = Contacts(cs["a"], cs["b"], cs["normal"], cs["pos"], np.arange(cs.n, dtype=_I), cs["jmodel"],
                            cs["prop"])
        subs = SubContacts(*(ss[k] for k in SubContacts._fields))
        bounds = Bounds(r.radius, r.acc, r.trigger, r.motion)
        if self.listed != eng.detections:        # (made once per detection, not per kernel call)
            self.lists = cycle_lists(r.b.n, contacts, subs, r.gmember)
            self.listed = eng.detections
        n_ok = 0
        bad = -1
        while n_ok < k:
            kk = min(k - n_ok, self.chunk) if self.chunked else k
            t0 = _time.perf_counter()
            # (the joint models in use, every call: a callback may assign one between batches; O(nc))
            models = cycle_mask(cs["jmodel"])
            c_ok, bad = run_steps(kk, r.dt, r.g, r.full, r.damping, r.groups(), r.bodies(), contacts, subs, bounds,
                                  r.vmax, r.out, r.beta, self.lists, models)
            spent = _time.perf_counter() - t0
            n_ok += c_ok
            if bad >= 0 or r.motion[1] > 0.0 or c_ok < kk or not self.chunked:
                break
            if c_ok > 0:
                self.chunk = max(1, min(100000, int(c_ok * CHUNK_SECONDS / max(spent, 1e-9))))
            r.progress.update(r.done + n_ok)
            if _StopFlag.requested:
                break
        if bad >= 0:
            # (a rigid-only run names the step its batch reached, a zoned one the step it began at)
            raise eng._blowup(bad, r.dt, r.motion[1] == 2.0, m.step + (n_ok if self.chunked else 0))
        return n_ok


class ZoneStep(_Step):
    """The zoned (and FE) blocks: gridpoint forces from zone stresses, gridpoint motion
    (``physics.zones.ZoneStepper``), n steps with the Δt of the rigid bodies (done within
    ``MixedContacts`` where zoned and rigid blocks touch); contact forces on zoned blocks went
    to their gridpoints, so the blocks' own sums are cleared."""

    def advance(self, n: int) -> int:
        r = self.run
        zst = r.zst
        for _ in range(0 if r.mixed else n):
            zbad = zst.step(r.dt, r.g, r.mode, r.alpha, r.large, r.vmax)
            if zbad >= 0:
                raise zst.unstable(zbad, r.dt)
        zb = zst.blocks
        r.b["force"][zb] = 0.0
        r.b["moment"][zb] = 0.0
        return n


class FluidStep(_Step):
    """Flow in the joints over the batch's time (``physics.flownet.advance``: apertures from the normal
    displacements, explicit flow steps within the stable Δt), then the knot pressures to the sub-contacts."""

    def advance(self, n: int) -> int:
        r = self.run
        fluid_advance(r.eng, n * r.dt)
        fluid_to_subcontacts(r.eng)
        return n


class Clock(_Step):
    """Step count and time move on by the steps taken; kinetic energy; detection due?"""
    timing = None

    def advance(self, n: int) -> int:
        r = self.run
        eng, m = r.eng, r.m
        r.due = r.motion[1] > 0.0
        m.step += n
        m.time += n * r.dt
        if r.dynamic:
            r.s["dyn_time"] += n * r.dt
        r.done += n
        eng._criteria = None
        eng.kinetic = (((float(r.out[2]) if r.ng else 0.0) + r.zst.kinetic) if r.zoned else float(r.out[2]))
        return n


class Hooks(_Step):
    """The engine's step hooks (histories, FISH callbacks) and the periodic VTK snapshot."""
    timing = "hooks"

    def advance(self, n: int) -> int:
        eng = self.run.eng
        for hook in eng.step_hooks:
            hook(eng)
        periodic_vtk(eng.model)
        return n
