"""Energy tracking of the cycle (`model energy`, `model history energy …`).

3DEC keeps a running sum of each energy component, worked out at every step (3DEC theory, "Energy
Calculation": boundary work W, stored strain energy, energy dissipated in joint shear W_j, kinetic
energy U_k, work dissipated by mass damping W_k; docs.itascacg.com). dec3d does the same for its rigid
blocks, contacts and zones with two steps put around the cycle's own steps (``_Run`` in
``physics.steps``) while tracking is on:

    EnergyBefore → RigidBatch → EnergyAfter → Clock → Hooks
    EnergyBefore → MixedContacts → RigidBatch → ZoneStep → EnergyAfter → Clock → Hooks   (zoned blocks)

``EnergyBefore`` lets the batch take one step and copies the state before it; ``EnergyAfter`` reads
the state after it and adds the step's energies (kernels ``dec3d.kernels.energy``). Neither the joint
laws nor the motion kernels nor the zone step know about it, so tracking costs nothing while it is off
(while it is on, the cycle runs one step per kernel call: about half the speed on a 64-block stack).

Conventions (the leapfrog time levels, see ``kernels/energy.py``): every work of step n is the force
at tⁿ times the displacement with the mid velocity v̄ⁿ = (v(n−½) + v(n+½))/2, which is exactly what
changes the kinetic energy at the half steps; kinetic and strain energies are reported at t + Δt/2.
The components (running sums since tracking was switched on or reset, joules):

- ``block-kinetic``  kinetic energy of the rigid bodies (½ m V² + ½ ωᵀ J ω, full inertia tensor) and of the
  gridpoints of zoned blocks (½ m v²); the inertial masses the motion uses, i.e. the real ones unless
  density scaling is on;
- ``block-strain``   elastic strain energy of the zones, Σ V (p²/(2K) + s:s/(4G)), at t + Δt/2;
- ``contact-strain`` elastic energy of the contact springs, Σ Fn²/(2 kn A) + |Fs|²/(2 ks A), at t + Δt/2;
- ``stored``         block-kinetic + block-strain + contact-strain;
- ``block-plastic``  work done on the zones less the change of their elastic energy (plastic flow);
- ``contact-slip``   work done on the springs less the change of their elastic energy: what Coulomb slip
  and the tension cut-off dissipated;
- ``body``           work done by gravity and by the body forces of `block zone apply`;
- ``boundary``       work of the applied forces, moments and face stresses and of the reactions of fixed
  velocity or rotation components (applied velocities);
- ``damping``        work of all forces on the free components less the change of kinetic energy: what the
  mechanical damping (local, combined, adaptive global or viscous) took;
- ``strain-change``  strain energy that appeared (or vanished) between two steps without work: sub-contacts
  made or dropped at a detection, properties or stresses changed by a command;
- ``kinetic-change`` kinetic energy that appeared between steps without work: new masses of density scaling
  at a detection, velocities set by a command;
- ``error``          the balance: (stored now − at the start) + plastic + slip + damping − body − boundary
  − strain-change − kinetic-change; ``error-relative`` is |error| / (|body| + |boundary|).

Zoned blocks: 4-node zones (elastic, Mohr-Coulomb), also in contact with rigid blocks (a zoned side of a
sub-contact moves with, and loads, the gridpoints of its surface triangle by the interpolation weights of
``gpcontact``); FE blocks and 10-node zones are refused while tracking is on (``refuse_unsupported``). The
zone forces are f = −w V σ ∇N from the stresses the zone step leaves (the force it applies).

The state is plain JSON in ``model.settings.mechanical["energy"]``: saved and restored with the model, put
back by a failed cycle, and a run split into several commands gives the same sums.
"""
from __future__ import annotations

import numpy as np

from dec3d.io.state import register_known
from dec3d.kernels.joints import ST_NEW
from dec3d.physics.jmodels import stiffness as joint_stiffness
from dec3d.kernels.energy import (contact_strain, group_energy, group_kinetic, spring_work, subcontact_increments,
                                  zone_internal_forces, zone_strain)

_F = np.float64
_I = np.int64

#: the accumulated components (running sums)
SUMS = ("body", "boundary", "damping", "contact-slip", "block-plastic", "strain-change", "kinetic-change")
#: every quantity `model history energy` and `model energy list` know, in the order they are listed
QUANTITIES = ("block-kinetic", "block-strain", "contact-strain", "stored", "block-plastic", "contact-slip", "body",
              "boundary", "damping", "strain-change", "kinetic-change", "error", "error-relative")
#: the state keys besides the sums: kinetic and strain energy after the last step, and at the start
STATE = ("kinetic", "strain", "zstrain", "kinetic0", "strain0", "zstrain0")


def new_state(active: bool) -> dict:
    d = {"active": bool(active), "started": False}
    for k in SUMS + STATE:
        d[k] = 0.0
    return d


def energy_state(model) -> dict:
    """The model's energy record (made, inactive, on first use)."""
    m = model.settings.mechanical
    e = m.get("energy")
    if not isinstance(e, dict):
        e = m["energy"] = new_state(False)
    return e


def is_active(model) -> bool:
    e = model.settings.mechanical.get("energy")
    return isinstance(e, dict) and bool(e.get("active"))


def state_problem(e) -> str | None:
    """What is wrong with a saved energy record (None: nothing); ``dec3d.io.state`` asks."""
    if not isinstance(e, dict):
        return "is not an object"
    if not isinstance(e.get("active"), bool) or not isinstance(e.get("started"), bool):
        return "`active` or `started` is not true or false"
    for k in SUMS + STATE:
        v = e.get(k)
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not np.isfinite(v):
            return f"`{k}` is not a finite number"
    extra = set(e) - set(SUMS + STATE) - {"active", "started"}
    if extra:
        return f"unknown entries {', '.join(sorted(extra))}"
    return None


def values(model) -> dict[str, float]:
    """Every quantity of QUANTITIES [J] (error-relative: a fraction) as the record holds them."""
    e = energy_state(model)
    out = {"block-kinetic": e["kinetic"], "block-strain": e["zstrain"], "contact-strain": e["strain"]}
    out["stored"] = e["kinetic"] + e["strain"] + e["zstrain"]
    for k in SUMS:
        out[k] = e[k]
    err = ((out["stored"] - e["kinetic0"] - e["strain0"] - e["zstrain0"]) + e["contact-slip"] + e["block-plastic"]
           + e["damping"] - e["body"] - e["boundary"] - e["strain-change"] - e["kinetic-change"])
    out["error"] = err
    done = abs(e["body"]) + abs(e["boundary"])
    out["error-relative"] = abs(err) / done if done > 0.0 else 0.0
    return {q: float(out[q]) for q in QUANTITIES}


def value(model, quantity: str) -> float:
    return values(model)[quantity]


def refuse_unsupported(run, error) -> None:
    """Energy tracking covers rigid blocks and zoned blocks of 4-node zones of isotropic elasticity: FE
    blocks, 10-node zones and anisotropic zones are refused with ``error`` (the engine's RunError)
    before anything cycles."""
    zst = run.zst
    what = None
    if zst is not None and zst.fe is not None:
        what = "FE blocks"
    elif zst is not None and len(zst.rows10):
        what = "10-node zones"
    elif zst is not None and len(zst.rows4):
        from dec3d.physics.cmodels import MODEL_BY_CODE

        # the strain energy here is that of isotropic elasticity, from the stress and K, G
        codes = np.unique(run.m.store("zones")["cmodel"][zst.rows4])
        own = sorted(MODEL_BY_CODE[int(c)].name for c in codes if MODEL_BY_CODE[int(c)].moduli is not None)
        if own:
            what = f"zones of the anisotropic models {', '.join(own)}"
    if what:
        raise error(f"energy tracking (`model energy active on`) covers rigid blocks and 4-node zones; {what} "
                    "are not supported yet: switch it off with `model energy active off`")


def energy_steps(run, steps: list, error) -> list:
    """The run's step list (… → Clock → Hooks) with the energy steps put in: EnergyBefore first,
    EnergyAfter just before the clock."""
    refuse_unsupported(run, error)
    tr = _Tracker(run, error)
    return [EnergyBefore(run, tr)] + steps[:-2] + [EnergyAfter(run, tr)] + steps[-2:]


class _Tracker:
    """The state before a step (copies) and the group map, shared by the two steps."""

    def __init__(self, run, error):
        self.run = run
        self.error = error
        self.before = None

    # ------------------------------------------------------------ rigid blocks and contacts
    def _gid(self):
        r = self.run
        gid = np.full(r.b.n, -1, dtype=_I)
        gid[r.gmember] = np.repeat(np.arange(r.ng, dtype=_I), np.diff(r.gstart))
        return gid

    def _strain(self, fn, du, flag):
        eng = self.run.eng
        cs, ss = eng.contacts, eng.subcontacts
        return contact_strain(cs["normal"], cs["jmodel"], cs["prop"], ss["contact"], ss["area"], fn, ss["fs"], ss["hist"],
                              du, flag)

    def _normal_forces(self):
        """The sub-contact normal forces as the joint law holds them. A detection makes the normal force
        of every sub-contact it recomputes zero and keeps its normal displacement uⁿ: the law sets
        Fn = −kn A (uⁿ − u_dil) again at the next update (Eq. 24). Such a stale zero (Fn = 0 while the
        spring is closed, uⁿ − u_dil < 0, which no update leaves) is taken as that force, so that a
        detection neither makes nor loses strain energy."""
        eng = self.run.eng
        cs, ss = eng.contacts, eng.subcontacts
        fn = ss["fn"].copy()
        closed = ss["un"] - ss["udil"]
        ka = joint_stiffness(cs, ss)[0] * ss["area"]
        stale = (fn == 0.0) & (closed < 0.0) & (ka > 0.0)
        fn[stale] = -ka[stale] * closed[stale]
        return fn

    def _du(self):
        r = self.run
        eng, b = r.eng, r.b
        cs, ss = eng.contacts, eng.subcontacts
        du = np.empty((ss.n, 3))
        subcontact_increments(r.dt, b["centroid"], b["velocity"], b["spin"], cs["a"], cs["b"], ss["contact"],
                              ss["pos"], du)
        if r.mixed:
            # a zoned side moves with the gridpoints of the surface triangle under the point (gpcontact)
            gv = r.m.vertices["velocity"]
            for nodes, w, sign in ((r.wsub[2], r.wsub[3], 1.0), (r.wsub[0], r.wsub[1], -1.0)):
                z = nodes[:, 0] >= 0
                if not z.any():
                    continue
                side = cs["b"] if sign > 0 else cs["a"]
                blk = side[ss["contact"][z]]
                x = ss["pos"][z]
                rigid = b["velocity"][blk] + np.cross(b["spin"][blk], x - b["centroid"][blk])
                ww = np.where(nodes[z] >= 0, w[z], 0.0)
                interp = (ww[:, :, None] * gv[np.maximum(nodes[z], 0)]).sum(axis=1)
                du[z] += sign * (interp - rigid) * r.dt
        return du

    def _contact_on_gridpoints(self):
        """The sub-contact forces on the gridpoints of zoned sides (shared by the interpolation weights),
        summed onto the master gridpoints."""
        r = self.run
        cs, ss = r.eng.contacts, r.eng.subcontacts
        v = r.m.vertices
        f = np.zeros((v.n, 3))
        if r.mixed:
            c = ss["contact"]
            fb = ss["fn"][:, None] * cs["normal"][c] + ss["fs"]
            for nodes, w, sign in ((r.wsub[2], r.wsub[3], 1.0), (r.wsub[0], r.wsub[1], -1.0)):
                on = nodes >= 0
                s_idx = np.nonzero(on)[0]
                np.add.at(f, nodes[on], sign * w[on][:, None] * fb[s_idx])
        return self._to_masters(f)

    def _rigid_kinetic(self) -> float:
        r = self.run
        b = r.b
        if not r.ng:
            return 0.0
        return float(group_kinetic(r.full, r.gstart, r.gmember, r.gmass, r.gimass, r.gisc, r.gprin, b["centroid"],
                                   r.gcen, b["velocity"], b["spin"], r.gaxes))

    # ------------------------------------------------------------ zoned blocks (gridpoints)
    def _zone_forces(self, pos):
        """Internal forces of the zones on the master gridpoints (linked copies summed onto them)."""
        r = self.run
        zst, v = r.zst, r.m.vertices
        f = np.zeros((v.n, 3))
        zone_internal_forces(pos, r.m.store("zones")["gp"], zst.rows4, zst.weight, r.m.store("zones")["stress"], f)
        return self._to_masters(f)

    def _to_masters(self, f):
        zst, v = self.run.zst, self.run.m.vertices
        lk = zst.linked
        if len(lk):
            np.add.at(f, v["link"][lk], f[lk])
        return f[zst.masters]

    def _zone_strain(self, pos) -> float:
        r = self.run
        zst, zs = r.zst, r.m.store("zones")
        return float(zone_strain(pos, zs["gp"], zst.rows4, zst.weight, zs["stress"], zst.bulk, zst.shear))

    def _zone_now(self):
        """(master velocities, inertial masses, kinetic energy, internal forces, U, U at the half step)."""
        r = self.run
        zst, v = r.zst, r.m.vertices
        vm = v["velocity"][zst.masters].copy()
        im = v["imass"][zst.masters]
        k = 0.5 * float((im[:, None] * vm * vm).sum())
        fi = self._zone_forces(v["pos"])
        u = self._zone_strain(v["pos"])
        return vm, k, fi, u, u - 0.5 * r.dt * float((fi * vm).sum())

    # ------------------------------------------------------------ the two halves of a step
    def begin(self) -> None:
        r = self.run
        refuse_unsupported(r, self.error)
        e = energy_state(r.m)
        bf = {}
        k = u_half = uz_half = 0.0
        if r.ng:
            b = r.b
            ss = r.eng.subcontacts
            du = self._du()
            flag = (ss["state"] & ST_NEW) != 0
            fn = self._normal_forces()
            u_n, u_half, u_flag = self._strain(fn, du, flag)
            k = self._rigid_kinetic()
            bf.update({"du": du, "flag": flag, "u_n": u_n, "u_flag": u_flag, "centroid": b["centroid"].copy(),
                       "velocity": b["velocity"].copy(), "spin": b["spin"].copy(), "gcen": r.gcen.copy(),
                       "gaxes": r.gaxes.copy(), "sc_pos": ss["pos"].copy(), "fn": fn, "fs": ss["fs"].copy(),
                       "gid": self._gid()})
        if r.zst is not None:
            vm, kz, fi, uz, uz_half = self._zone_now()
            k += kz
            bf.update({"vm": vm, "kz": kz, "fi": fi, "uz": uz, "pos": r.m.vertices["pos"].copy()})
        if not e["started"]:
            e["started"] = True
            e["kinetic0"] = e["kinetic"] = k
            e["strain0"] = e["strain"] = float(u_half)
            e["zstrain0"] = e["zstrain"] = float(uz_half)
        # what changed between the last step and this one without work
        e["kinetic-change"] += k - e["kinetic"]
        e["strain-change"] += (float(u_half) - e["strain"]) + (uz_half - e["zstrain"])
        self.before = bf

    def end(self, n: int) -> None:
        r = self.run
        if n <= 0 or self.before is None:
            return
        e = energy_state(r.m)
        bf = self.before
        self.before = None
        k = 0.0
        if r.ng:
            b = r.b
            cs, ss = r.eng.contacts, r.eng.subcontacts
            out = np.zeros(7)
            group_energy(r.dt, r.g, r.full, r.gstart, r.gmember, r.gmass, r.gimass, r.gisc, r.gprin, r.fixity,
                         b["mass"], b["fapp"], b["mapp"], bf["centroid"], bf["gcen"], bf["velocity"], bf["spin"],
                         bf["gaxes"], b["centroid"], r.gcen, b["velocity"], b["spin"], r.gaxes, bf["gid"], cs["a"],
                         cs["b"], cs["normal"], ss["contact"], bf["sc_pos"], ss["fn"], ss["fs"], out)
            flag = bf["flag"]
            w, w_flag = spring_work(cs["normal"], ss["contact"], bf["fn"], bf["fs"], ss["fn"], ss["fs"], bf["du"],
                                    flag)
            u_n, u_half, u_flag = self._strain(ss["fn"], self._du(), flag)
            e["body"] += float(out[0])
            e["boundary"] += float(out[1] + out[2])
            e["damping"] += float(out[6])
            # slip: work on the springs less the change of their elastic energy; the sub-contacts made at
            # the last detection (flag) take their force from their gap: what they gain is no slip
            e["contact-slip"] += float((w - w_flag) - ((u_n - u_flag) - (bf["u_n"] - bf["u_flag"])))
            e["strain-change"] += float((u_flag - bf["u_flag"]) - w_flag)
            e["strain"] = float(u_half)
            k += float(out[5])
        if r.zst is not None:
            k += self._zone_end(e, bf)
        e["kinetic"] = k

    def _zone_end(self, e: dict, bf: dict) -> float:
        """The gridpoints' part of a step: works with the mid velocity, damping as the work of every force
        on the free components less the change of kinetic energy, the zones' plastic work."""
        r = self.run
        zst, v = r.zst, r.m.vertices
        dt = r.dt
        vm1, k1, fi_now, uz1, uz_half = self._zone_now()
        large = bool(r.large)
        # the forces the step used: stresses now, geometry before it (they differ only in large strain)
        fi = self._zone_forces(bf["pos"]) if large else fi_now
        rows = zst.rows
        grav = np.zeros((v.n, 3))
        app = np.zeros((v.n, 3))
        grav[rows] = zst.gmass[rows, None] * np.asarray(r.g, _F)[None, :]
        if zst.zb is not None:                  # body forces of `block zone apply` work as gravity does
            grav[zst.zb[0]] += zst.zb[1]
        app[rows] = v["fapp"][rows] + v["fface"][rows]
        grav, app = self._to_masters(grav), self._to_masters(app)
        vm0 = bf["vm"]
        step = 0.5 * (vm0 + vm1) * dt
        h = zst.held[zst.masters].astype(np.int64)
        im = v["imass"][zst.masters]
        held = np.stack([((h >> i) & 1) | ((h >> (3 + i)) & 1) for i in range(3)], axis=1).astype(bool)
        held |= (im <= 0.0)[:, None]
        con = self._contact_on_gridpoints()
        total = fi + grav + app + con
        w_body = float((grav * step).sum())
        w_app = float((app * step).sum())
        w_react = -float((total * step)[held].sum())
        w_int = float((fi * step).sum())
        w_con = float((con * step).sum())
        e["body"] += w_body
        e["boundary"] += w_app + w_react
        e["damping"] += (w_body + w_app + w_react + w_int + w_con) - (k1 - bf["kz"])
        # the zones' stresses took the increment v(n−½) Δt: trapezoid work on them less the change of U
        w_zone = -0.5 * dt * float(((bf["fi"] + fi) * vm0).sum())
        e["block-plastic"] += w_zone - (uz1 - bf["uz"])
        e["zstrain"] = uz_half
        return k1


class _EnergyStep:
    timing = "cycle"

    def __init__(self, run, tracker):
        self.run = run
        self.tracker = tracker

    def prepare(self) -> None:
        pass

    def __repr__(self) -> str:
        return type(self).__name__


class EnergyBefore(_EnergyStep):
    """Energy tracking, first half: the batch takes one step; the state before it is copied."""

    def advance(self, n: int) -> int:
        if n <= 0 or not (self.run.ng or self.run.zst is not None):
            return n
        self.tracker.begin()
        return 1


class EnergyAfter(_EnergyStep):
    """Energy tracking, second half: the energies of the step just taken are added up."""

    def advance(self, n: int) -> int:
        self.tracker.end(n)
        return n


register_known(energy_problem=state_problem)
