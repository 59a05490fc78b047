"""The deformable step of the cycle: zoned blocks move by their gridpoints.

``ZoneStepper`` is made by ``RigidEngine`` at the start of every ``model cycle`` / ``solve`` on a
model with zones (state is the model's: ``zones`` store and the gridpoint fields of
``vertices``, see ``dec3d.model.zones``; the stepper holds only what it can rebuild; what it
derives from the mesh and the zones' models and properties is taken from the engine's
``zone_cache.StepperCache`` when its inputs are bit for bit those of the command that made it):

1. checks: every zoned block has zones with a model (``RunError`` naming the blocks otherwise);
   the zones of each model by its registry entry (``physics.cmodels``: every property in its
   range, then the model's own check; errors stop the run naming the zones, warnings go to the
   engine's ``warn``); 10-node zones take every model: elastic ones step in ``zones_ho.tet10_step``,
   any other model through ``zones_ho_models.tet10_model_step`` (the model's update at each Gauss
   point, a history per Gauss point in ``zones.ghist``);
2. lumped masses and the node stiffness of Eq. (86) (kernel ``zonestep.zone_mass_stiffness``)
   of the 4-node zones; for 10-node zones HRZ lumped masses (``zones_ho.tet10_lumped_mass``) and
   twice the Gershgorin row-sum stiffness (``zones_ho.tet10_stiffness``); summed onto link masters
   (joined blocks share gridpoints by linking);
3. time step and inertial masses. Static runs (the engine's mass scaling on): density scaling
   (3DEC theory, "Mass (Density) Scaling"): the inertial mass of each gridpoint is set so that
   the step of Eq. (84), Δt = 2 (m/k)^½, is the run's Δt: m = k Δt² / 4, with Δt = 1 (FLAC3D's
   and 3DEC's choice for static runs with deformable zones) unless rigid blocks cycle too (then
   the rigid Δt) or a time step was fixed (``block mechanical timestep`` / ``mass-scale
   timestep``). Dynamic runs: real masses and Δt = min over gridpoints of Eq. (84), and of the
   rigid Δt when rigid blocks cycle;
4. each step (``step``): zone forces of the 4-node zones (mixed discretization in hexahedral
   sets and nodal mixed discretization, NMD, for the other tetrahedra when
   ``settings.mechanical["nmd"]`` is on, the default, ``block zone nodal-mixed-discretization``):
   by ``zone_step.zone_step`` (each zone's model update from ``kernels/zmodels``; one chunk per
   thread from PARALLEL_MIN_ZONES zones on, the same bits for any chunk count); 10-node zones
   by ``zones_ho.tet10_step``), gravity (m g
   on the gridpoints of 4-node zones, the consistent loads of ``zones_ho.tet10_body_force`` on
   those of 10-node zones, both counted in the applied-force magnitudes of the equilibrium
   ratio), body forces of `block zone apply` (``physics.zone_loads``), applied and face forces
   (``model.face_loads``: 6-node faces of 10-node zones by
   ``zones_ho.tri6_traction_loads``, hexahedral zone faces as quadrilaterals) and the sum onto masters (``gp_externals``), damping and
   motion (``gp_motion_ws``, the bits of ``gp_motion`` on threads).

Zoned blocks are not bodies of the rigid motion kernel (``RigidEngine._groups`` leaves them
out). Contacts between a zoned block and a rigid or another zoned block add their forces to the
gridpoints (``RigidEngine._mixed_steps``, kernels of ``gpcontact``); between zoned blocks of one
joined set they carry none (shared gridpoints).
"""
from __future__ import annotations

import math

import numpy as np

from dec3d.errors import Dec3dError
from dec3d.kernels.bundles import ZoneMaterial
from dec3d.kernels.zmodels import model_mask
from dec3d.kernels.zone_step import zone_step_for
from dec3d.kernels.zonestep import gp_externals, gp_motion, gp_motion_ws, zone_mass_stiffness
from dec3d.model.feblocks import has_feblocks
from dec3d.model.zones import zone_stores
from dec3d.physics.cmodels import MODEL_BY_CODE
from dec3d.units import suffix

from .cables import gridpoint_grout_stiffness
from .zone_cache import StepperCache, same
from .zone_loads import body_loads
from .zone_setup import _zone_models, _zone_plan, zone_tables, zoned_blocks

_F = np.float64
_I = np.int64

#: factor on the Gershgorin stiffness of 10-node zones (``zones_ho.tet10_stiffness``): the bound
#: itself puts density-scaled masses (m = k Δt²/4) at the very limit of stability, with nothing to
#: spare; the D3 10-node hole deck went unstable at step 130 with it and runs with twice it
TET10_STIFFNESS_MARGIN = 2.0

#: 4-node zones from which the zone step runs in one chunk per thread (``zone_step`` gives the
#: same bits for any chunk count, so the choice never changes a result)
PARALLEL_MIN_ZONES = 20000


class ZoneStepper:
    def __init__(self, model, error, warn=None, cache=None):
        """``error``: the exception class to raise (the engine's ``RunError``); ``warn``: where the
        warnings of the property checks go (the engine's warn callback), or None; ``cache``: the
        engine's ``zone_cache.StepperCache`` (what an earlier command derived from the same
        inputs is taken from it), or None (everything derived anew)."""
        self.model = model
        self.error = error
        zs = zone_stores(model)
        b, v = model.blocks, model.vertices
        c = self._cache = cache if cache is not None else StepperCache(off=True)
        self.blocks = zoned_blocks(model)
        c.see("blocks", (self.blocks, b.n))
        for k in ("block", "cmodel", "nnode", "hex", "overlay"):
            c.see(k, zs[k])
        c.see("prop", zs["prop"], runs=True)
        c.see("gp4", zs["gp"][:, :4])
        c.see("link", v["link"])
        zm = c.get("zones", ("blocks", "block", "cmodel", "prop", "nnode"),
                   lambda: _zone_models(model, zs, self.blocks, error), keep=lambda z: not z["warnings"])
        #: warnings of the property checks (also given to ``warn`` when there is one)
        self.warnings = list(zm["warnings"])
        if warn is not None:
            for w in self.warnings:
                warn(w)
        on = zm["on"].copy()
        #: the zone moduli the mass scaling and time step take (each model's ``moduli``)
        self.bulk, self.shear, self.density = zm["bulk"], zm["shear"], zm["density"]
        self.rows4, self.rows10 = zm["rows4"], zm["rows10"]
        self.nmd = bool(model.settings.mechanical.get("nmd", True))
        #: some 4-node zone's model returns a mean-stress correction (a plastic model, or an
        #: anisotropic one): the step's third sweep averages it
        self.plastic = zm["plastic"]
        #: the models among the 4-node zones: the step is compiled for these (``model_mask``)
        self.models = zm["models"]
        self.ho = None
        #: β [s] of Rayleigh damping's stiffness term (set by the engine's run; 0: none)
        self.beta = 0.0
        #: Maxwell damping's components (αᵢ, τᵢ [s]) (set by the engine's run; []: none)
        self.maxwell = []
        if len(self.rows10):
            from dec3d.kernels import zones_ho
            self.ho = zones_ho.tet10_step
            codes10 = np.unique(zs["cmodel"][self.rows10])
            if any(MODEL_BY_CODE[int(c)].name != "elastic" for c in codes10):
                # some 10-node zone has a model other than isotropic elasticity: the model's update at
                # every Gauss point (``zones_ho_models``; Hooke gives the same bits as tet10_step)
                from dec3d.kernels.zones_ho_models import tet10_model_step_for
                step10 = tet10_model_step_for(model_mask(codes10))

                def ho(pos, vel, gp, rows, bulk, shear, dt, gstress, stress, force):
                    bad = step10(pos, vel, gp, rows, self.material(stress=stress), zs["ghist"], dt, gstress, force)
                    return bad
                self.ho = ho
        #: the 4-node step (``zone_step.zone_step``): chunks (one per thread from PARALLEL_MIN_ZONES
        #: zones on; any count gives the same bits), plans and scratch, made once per mesh
        import numba
        nch = numba.get_num_threads() if len(self.rows4) >= PARALLEL_MIN_ZONES else 1
        c.see("nch", nch)
        # (of the zones entry the plan takes the 4-node rows and the plastic flag: compared with its own)
        pl = c.get("plan", ("gp4", "hex", "overlay", "link", "nch"),
                   lambda: _zone_plan(zs, v, self.rows4, self.plastic, nch),
                   valid=lambda p: p["plastic"] == self.plastic and same(p["rows4"], self.rows4))
        #: NMD averaging node of each vertex row: its link master (one gridpoint of a joined set) or itself
        self.node = pl["node"]
        # mixed-discretization sets of the 4-node zones: compact set numbers
        self.weight, self.zset, self.nset, self.fast = pl["weight"], pl["zset"], pl["nset"], pl["fast"]
        if self.fast is not None:
            self.zmesh, self.zplan, self.zscratch = pl["bundles"]
        #: the tables the zone models read (``table`` ids named by table properties)
        self.tables = zone_tables(model, error)
        # FE blocks (issue 12): their nodes move with the gridpoints; forces, masses and slave
        # nodes come from dec3d.physics.feblocks.FeStepper
        self.fe = None
        # reference positions (``_references``): of the masses (kept) and of the stiffness
        self.large = bool(model.settings.large_strain)
        if has_feblocks(model):
            from .feblocks import FeStepper, fe_blocks
            on[fe_blocks(model)] = True
            self.ref, geo = self._references(on)
            self.fe = FeStepper(model, error, self.ref, geo)
        else:
            self.ref, geo = self._references(on)
        # gridpoints: rows of the zoned blocks, masters and linked copies (FE slave nodes are neither)
        vb = v["block"]
        gpmask = v["zoned"] & on[np.maximum(vb, 0)] & (vb >= 0)
        self.rows = np.flatnonzero(gpmask).astype(_I)
        link = v["link"]
        slave = v["feslave"][self.rows] if "feslave" in v else np.zeros(len(self.rows), bool)
        self.masters = np.ascontiguousarray(self.rows[(link[self.rows] < 0) & ~slave])
        self.linked = np.ascontiguousarray(self.rows[link[self.rows] >= 0])
        held = v["apply_fix"] | ((v["fixity"] & 7) << 3) | ((b["fixity"][np.maximum(vb, 0)] & 7) << 3)
        held = held.astype(np.uint8)
        # a condition set on a linked copy holds its master (the one gridpoint they both are)
        lk = self.linked
        self.vapp = v["vapp"].copy()
        if len(lk):
            for i in range(3):
                bit = np.uint8(1 << i)
                own = (held[lk] & bit) != 0
                mst = link[lk[own]]
                self.vapp[mst, i] = np.where((held[mst] & bit) != 0, self.vapp[mst, i], v["vapp"][lk[own], i])
            np.bitwise_or.at(held, link[lk], held[lk])
        self.held = np.ascontiguousarray(held)
        # real masses on the reference positions, stiffness on the geometry of the last update
        n = v.n
        c.see("rows", (self.rows, n))
        c.see("ref", self.ref[self.rows])
        c.see("gp10", zs["gp"][self.rows10])
        ms = c.get("mass", ("zones", "gp4", "gp10", "overlay", "rows", "ref"), lambda: self._real_masses(zs, n),
                   keep=lambda x: x["inside"])
        mass = ms["mass"].copy()
        #: mass whose weight is lumped (m g per gridpoint): that of the 4-node zones; 10-node zones
        #: load their gridpoints with the consistent body force instead (``tet10_body_force``)
        self.gmass, self.r10 = ms["gmass"], ms["r10"]
        self._g10 = None
        if self.fe is not None:
            mass += self.fe.mass
        v["mass"][self.rows] = mass[self.rows]
        if self.fe is not None:
            self.blocks = np.concatenate((self.blocks, self.fe.blocks))
        mtot = mass.copy()
        lk = self.linked
        np.add.at(mtot, link[lk], mass[lk])
        self.mtot = mtot
        #: body forces of `block zone apply` on the gridpoints, (rows, forces, magnitudes) or None (``zone_loads``)
        self.zb = body_loads(model, self.ref, self.rows4, self.rows10)
        #: contact stiffness of the joint term of Eq. (85) per master (``set_contact_stiffness``)
        self.kj = None
        self._stiffness(geo, fe=False)
        #: model time of the next step (table loads are evaluated at it)
        self.clock = float(model.time)
        self.facc = np.zeros((n, 3))
        #: scratch of ``gp_motion_ws`` (threaded motion, big models only)
        self.mwork = np.empty((len(self.masters) if len(self.rows4) >= PARALLEL_MIN_ZONES else 0, 5))
        self.fmag = np.zeros(n)
        self.out = np.zeros(4)

    def _real_masses(self, zs, n) -> dict:
        """The real lumped masses on ``ref`` (4-node zones, then with the 10-node zones'), the mass
        whose weight is lumped (``gmass``), the gridpoints of 10-node zones, and whether every
        gridpoint of the zones is a row of ``rows`` (what the cache compares: else not kept)."""
        mass = np.zeros(n)
        zone_mass_stiffness(self.ref, zs["gp"], zs["nnode"], zs["overlay"], self.rows4, self.bulk, self.shear,
                            self.density, mass, np.zeros(n))
        gmass = mass.copy()
        r10 = np.zeros(0, _I)
        inside = np.zeros(n, bool)
        inside[self.rows] = True
        ok = bool(inside[zs["gp"][self.rows4, :4]].all())
        if len(self.rows10):
            from dec3d.kernels import zones_ho
            self._bad10(zones_ho.tet10_lumped_mass(self.ref, zs["gp"], self.rows10, self.density, mass))
            g10 = zs["gp"][self.rows10]
            r10 = np.unique(g10[g10 >= 0]).astype(_I)
            ok = ok and bool(inside[r10].all())
        return {"mass": mass, "gmass": gmass, "r10": r10, "inside": ok}

    def _references(self, on) -> tuple[np.ndarray, np.ndarray]:
        """(positions of the real masses, positions of the stiffness), each (nv, 3), for the
        gridpoints of the blocks ``on``. Mass is conserved: the lumped masses (and consistent
        gravity loads) are those of the geometry a gridpoint had when a run first used it
        (``vertices.gpos0``). The stiffness (Eq. 86, hence Δt and the density-scaled masses), the
        quiet dashpots and table-driven face loads follow the geometry in large strain, worked out
        again at every detection step (``regeometry``, a multiple of the update interval: a rule
        of the step number alone); a run starts from the positions of the last such update
        (``vertices.gpos_geo``), so a run split into several commands, or saved and restored in
        between, takes exactly the steps of one run. In small strain both are the positions."""
        v = self.model.vertices
        vb = v["block"]
        rows = np.flatnonzero(v["zoned"] & on[np.maximum(vb, 0)] & (vb >= 0))
        pos, flag = v["pos"], v["gref"]
        new = rows[(flag[rows] & 1) == 0]
        v["gpos0"][new] = pos[new]
        flag[new] |= 1
        ref = pos.copy()
        ref[rows] = v["gpos0"][rows]
        if not self.large:
            v["gpos_geo"][rows] = pos[rows]
            flag[rows] |= 2
            return ref, pos
        new = rows[(flag[rows] & 2) == 0]
        v["gpos_geo"][new] = pos[new]
        flag[new] |= 2
        geo = pos.copy()
        geo[rows] = v["gpos_geo"][rows]
        return ref, geo

    def _bad10(self, bad: int) -> None:
        if bad >= 0:
            zs, b = self.model.store("zones"), self.model.blocks
            raise self.error(f"10-node zone {int(zs['id'][bad])} of block {int(b['id'][zs['block'][bad]])} is "
                             "inverted or flat (its Jacobian is not positive at a Gauss point)")

    def _stiffness(self, geo, fe: bool = True) -> None:
        """The node stiffness of the zones (and FE elements; ``fe``: work theirs out again too) on
        the positions ``geo``, summed onto masters (``kzone``, ``ktot`` with the contacts' joint
        term), and the quiet dashpots and table face loads on them."""
        m = self.model
        v = m.vertices
        n = v.n
        c = self._cache
        c.see("geo", geo[self.rows])
        stiff = c.get("stiff", ("zones", "gp4", "gp10", "overlay", "rows", "geo"), lambda: self._zone_stiffness(geo))
        stiff = stiff.copy()
        if self.fe is not None:
            if fe:
                self.fe.stiffness(geo)
            stiff += self.fe.stiff
        stiff += gridpoint_grout_stiffness(m, n)        # grout of cables hosted by zones (physics.cables)
        lk = self.linked
        np.add.at(stiff, v["link"][lk], stiff[lk])
        self.kzone = stiff
        self.ktot = stiff.copy() if self.kj is None else self.kzone + self.kj
        pos = v["pos"]
        if np.shares_memory(geo, pos):
            self._quiet_setup(m)
        else:
            # the dashpots and face-load shares read the model's positions: on ``geo`` for a moment
            now = pos.copy()
            pos[:] = geo
            try:
                self._quiet_setup(m)
            finally:
                pos[:] = now

    def _zone_stiffness(self, geo) -> np.ndarray:
        """The node stiffness of the 4- and 10-node zones on the positions ``geo`` (per vertex row)."""
        zs = self.model.store("zones")
        n = len(geo)
        stiff = np.zeros(n)
        zone_mass_stiffness(geo, zs["gp"], zs["nnode"], zs["overlay"], self.rows4, self.bulk, self.shear,
                            self.density, np.zeros(n), stiff)
        if len(self.rows10):
            from dec3d.kernels import zones_ho
            k10 = np.zeros(n)
            self._bad10(zones_ho.tet10_stiffness(geo, zs["gp"], self.rows10, self.bulk, self.shear, k10))
            stiff += TET10_STIFFNESS_MARGIN * k10
        return stiff

    def regeometry(self) -> None:
        """Large strain, at a detection step: stiffness, dashpots and table face loads on the
        positions now (``_references``); the caller sets the masses again (``set_masses``)."""
        v = self.model.vertices
        v["gpos_geo"][self.rows] = v["pos"][self.rows]
        v["gref"][self.rows] |= 2
        self._stiffness(v["pos"])

    def _quiet_setup(self, model) -> None:
        """Quiet boundaries and table-driven face stresses (``dec3d.model.quiet``): the dashpot
        matrices per gridpoint row, each master's largest dashpot coefficient (Gershgorin bound of
        its summed matrix, for Δt and the scaled masses) and the clock of the table loads."""
        from dec3d.model.quiet import dynamic_face_loads, quiet_dashpots
        self.quiet = quiet_dashpots(model)
        self.cdash = None
        if self.quiet is not None:
            rows, c = self.quiet
            link = model.vertices["link"]
            cm = np.zeros((len(self.mtot), 3, 3))
            cm[rows] = c
            lk = self.linked
            np.add.at(cm, link[lk], cm[lk])
            cd = np.abs(cm).sum(axis=2).max(axis=1)
            if self.fe is not None:
                self.fe.slave_stiffness(cd)          # slave nodes' dashpots bound their masters'
            self.cdash = cd
        self.dyn = dynamic_face_loads(model)

    # ------------------------------------------------------------ time step and masses
    def natural_timestep(self) -> float:
        """Eq. (84): 2 min (m/k)^½ over the master gridpoints that have stiffness [s]. With quiet
        boundaries a gridpoint with dashpot coefficient c takes the central-difference limit with
        damping, Δt = (2/ω)((1 + ξ²)^½ − ξ), ω² = k/m, ξ = c/(2mω) (Belytschko, Liu and Moran,
        "Nonlinear Finite Elements for Continua and Structures", explicit time integration), that
        is k Δt²/4 + c Δt/2 = m: Δt = ((c² + 4km)^½ − c)/k."""
        m, k = self.mtot[self.masters], self.ktot[self.masters]
        if self.cdash is not None:
            c = self.cdash[self.masters]
            on = ((k > 0) | (c > 0)) & (m > 0)
            m, k, c = m[on], k[on], c[on]
            with np.errstate(divide="ignore", invalid="ignore"):
                dt = np.where(k > 0, (np.sqrt(c * c + 4.0 * k * m) - c) / np.where(k > 0, k, 1.0), 2.0 * m / c)
            return float(dt.min()) if len(dt) else math.inf
        on = (k > 0) & (m > 0)
        return float(2.0 * np.sqrt(m[on] / k[on]).min()) if on.any() else math.inf

    def set_masses(self, dt: float, scaled: bool) -> None:
        """Inertial masses: density-scaled to Δt (m = k Δt²/4, Eq. 84; + c Δt/2 at a gridpoint with
        dashpots of a quiet boundary, see ``natural_timestep``) or the real ones."""
        v = self.model.vertices
        im = self.ktot * dt * dt / 4.0 if scaled else self.mtot.copy()
        if scaled and self.cdash is not None:
            im += self.cdash * dt / 2.0
            im[(self.ktot <= 0) & (self.cdash <= 0)] = 0.0
        else:
            im[self.ktot <= 0] = 0.0
        v["imass"][self.masters] = im[self.masters]
        lk = self.linked
        v["imass"][lk] = v["imass"][v["link"][lk]]
        self.dt = dt

    def set_contact_stiffness(self, rows: np.ndarray, k: np.ndarray) -> None:
        """The joint term of Eq. (85) (contact stiffness at boundary gridpoints, N/m, per vertex
        row, summed onto masters): the density-scaled masses follow at the next ``set_masses``."""
        link = self.model.vertices["link"]
        rows = np.where(link[rows] >= 0, link[rows], rows)
        kj = np.zeros(len(self.ktot))
        np.add.at(kj, rows, k)
        if self.fe is not None:
            self.fe.slave_stiffness(kj)
        self.kj = kj
        self.ktot = self.kzone + kj

    # ------------------------------------------------------------ one step
    def material(self, stress=None, state=None, cmodel=None) -> ZoneMaterial:
        """The zones' ``ZoneMaterial`` (stress, state, model codes as given, else the store's)."""
        zs = self.model.store("zones")
        return ZoneMaterial(zs["cmodel"] if cmodel is None else cmodel, zs["prop"], zs["hist"], self.bulk, self.shear,
                            zs["stress"] if stress is None else stress, zs["state"] if state is None else state,
                            self.tables)

    def begin(self) -> np.ndarray:
        """Start a step: the gridpoint force accumulator zeroed and returned (contact forces
        may be added to it before ``step(…, begun=True)``)."""
        if 2 * len(self.rows) > len(self.fmag):
            # (rows off the zoned blocks are never written: zeroing all of it is the same, and
            # cheaper than the indexed write when most rows are gridpoints)
            self.facc[:] = 0.0
            self.fmag[:] = 0.0
        else:
            self.facc[self.rows] = 0.0
            self.fmag[self.rows] = 0.0
        return self.facc

    def step(self, dt: float, gravity: np.ndarray, mode: int, alpha: float, large: bool, vmax: float,
             begun: bool = False) -> int:
        """One step of every zoned block; returns the first unstable gridpoint row or −1."""
        m = self.model
        v, zs = m.vertices, m.store("zones")
        facc, fmag = self.facc, self.fmag
        if not begun:
            self.begin()
        pos, vel = v["pos"], v["velocity"]
        if self.fast is not None:
            zone_step_for(self.models)(pos, vel, self.zmesh, self.material(), self.zplan, self.zscratch, dt, large,
                                       self.nmd, facc, fmag)
        if self.ho is not None:
            self.ho(pos, vel, zs["gp"], self.rows10, self.bulk, self.shear, dt, zs["gstress"], zs["stress"], facc)
        if self.beta > 0.0:             # Rayleigh damping's stiffness term (physics.dynamic)
            from .dynamic import zone_stiffness_damping
            zone_stiffness_damping(self, self.beta, pos, vel, facc)
        if self.maxwell:                # Maxwell damping's components (physics.dynamic)
            from .dynamic import zone_maxwell_damping
            zone_maxwell_damping(self, self.maxwell, dt, pos, vel, facc)
        fe = self.fe
        if fe is not None:
            e = fe.forces(pos, vel, dt, gravity, facc, fmag)
            if e >= 0:
                es = m.store("feblocks")
                raise self.error(f"at step {m.step} FE element {int(es['id'][e])} (block "
                                 f"{int(m.blocks['id'][es['block'][e]])}) turned inside out (det J not positive); "
                                 "the model is back at its state before this command")
        if len(self.r10):
            self._body_force10(gravity)
            facc[self.r10] += self.fb10
            fmag[self.r10] += self.fb10mag
        if self.quiet is not None or self.dyn:
            self._boundary_forces(vel, dt)
        if self.zb is not None:
            facc[self.zb[0]] += self.zb[1]
            fmag[self.zb[0]] += self.zb[2]
        gp_externals(self.rows, v["link"], self.gmass, gravity, v["fapp"], v["fface"], facc, fmag)
        if fe is not None:
            fe.slave_forces(facc)
        # (threads pay from a few thousand gridpoints on; both give the same bits)
        move = gp_motion_ws if len(self.rows4) >= PARALLEL_MIN_ZONES else gp_motion
        bad = move(self.masters, self.linked, v["link"], facc, v["force"], self.mtot, v["imass"], self.held,
                   self.vapp, vel, v["disp"], pos, dt, mode, alpha, large, vmax, self.out,
                   *((self.mwork,) if move is gp_motion_ws else ()))
        if fe is not None:
            fe.follow(vel, v["disp"], *((pos,) if large else ()))
        return bad

    def _boundary_forces(self, vel, dt) -> None:
        """Dashpot forces −C v of the quiet boundaries (velocities of the last step) and the
        table-driven face loads at the model time of this step (``dec3d.model.quiet``)."""
        facc, fmag = self.facc, self.fmag
        if self.quiet is not None:
            rows, c = self.quiet
            facc[rows] -= np.einsum("kij,kj->ki", c, vel[rows])
        if self.dyn:
            from dec3d.model.quiet import table_value
            for xs, ys, rows, unit in self.dyn:
                f = table_value(xs, ys, self.clock) * unit
                facc[rows] += f
                fmag[rows] += np.sqrt((f * f).sum(axis=1))
        self.clock += dt

    def _body_force10(self, gravity) -> None:
        """The consistent gravity loads of the 10-node zones (FE-block text 003_*, "Gravity
        Forces": F_a = ρ g ∫ N_a dV), on the reference geometry of the masses (``_references``), made again when the
        gravity changes: ``fb10`` (per row of ``r10``) and their magnitudes ``fb10mag``."""
        g = tuple(float(x) for x in gravity)
        if g == self._g10:
            return
        from dec3d.kernels.zones_ho import tet10_body_force
        m = self.model
        f = np.zeros((m.vertices.n, 3))
        tet10_body_force(self.ref, m.store("zones")["gp"], self.rows10, self.density, np.asarray(g, _F), f)
        self.fb10 = f[self.r10]
        self.fb10mag = np.sqrt((self.fb10 ** 2).sum(axis=1))
        self._g10 = g

    @property
    def kinetic(self) -> float:
        return float(self.out[2])

    def balance(self) -> tuple[np.ndarray, np.ndarray]:
        """(unbalanced force, applied force magnitude) of the free master gridpoints at the last
        step: a gridpoint takes part unless all three components are held or it has no mass."""
        v = self.model.vertices
        r = self.masters
        h = self.held[r]
        free = (((h | (h >> 3)) & 7) != 7) & (v["imass"][r] > 0)
        r = r[free]
        f = v["force"][r]
        return np.hypot(np.hypot(f[:, 0], f[:, 1]), f[:, 2]), self.fmag[r]     # (hypot: no overflow)

    def finish(self, large: bool) -> None:
        """After a run: zone volumes follow the geometry in large strain."""
        if not large:
            return
        m = self.model
        zs, p = m.store("zones"), m.vertices["pos"]
        g = zs["gp"][: zs.n, :4]
        if not zs.n:
            return
        a, b, c, d = (p[g[:, i]] for i in range(4))
        zs["volume"][:] = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6.0

    def unstable(self, row: int, dt: float) -> Dec3dError:
        m = self.model
        v = m.vertices
        sp = math.hypot(*v["velocity"][row])
        bid = int(m.blocks["id"][v["block"][row]])
        x, y, z = (float(c) for c in v["pos"][row])
        return self.error(f"the run became unstable at step {m.step}: a gridpoint of block {bid} at "
                          f"({x:.4g}, {y:.4g}, {z:.4g}) reached velocity {sp:.3g}{suffix(m, 'velocity')} (time step {dt:.3g}"
                          f"{suffix(m, 'time')}); "
                          "the model is back at its state before this command")

