"""The static answer of linear elastic zoned and FE blocks by a sparse solve (`model solve … implicit`).

The explicit, density-scaled and damped cycle of ``physics.zones`` reaches the equilibrium of its
own discretisation: at rest, the force of the zone and element stresses plus gravity, applied and
face forces vanishes at every free master gridpoint. In small strain that force is linear in the
displacement since the start of the solve: the geometry does not move, and every stress grows by
D : ε(v Δt) at each step (the zone step's nodal or hexahedral averaging of the volumetric strain is
linear too), so after displacements Δu the stresses are σ0 + D : ε(Δu) and

    F(Δu) = F(0) − K Δu,

with F(0) the force the engine's own step finds at rest now (``residual``) and K the stiffness of
exactly the kernels the explicit step runs. K Δu is evaluated by those kernels themselves
(``operator``: ``dynamic.zone_stiffness_damping``, the step on zero stresses with velocity Δu over
a unit time). The solve of K_ff Δu_f = F_f(0) on the free degrees of freedom (master gridpoints,
components not held, with stiffness):

- FE blocks and 10-node zones only: K is assembled from the step kernels by probing each element
  (``implicit_stiffness``), so it is the operator itself, and is solved by sparse LU
  (``scipy.sparse.linalg.splu``);
- with 4-node zones: conjugate gradients (the operator is symmetric and, held against rigid motion,
  positive definite) on ``operator``, preconditioned by the LU of the assembled stiffness with
  constant-strain tetrahedra in place of the averaged ones; 10-20 iterations on the D3 decks.

Either way the answer is refined with the engine's residual until it is below ``REFINE_TOL`` of the
first one. The stresses are then moved on by the step kernels with velocity Δu over a unit time, the
displacements by Δu (linked copies and FE slave nodes follow as in a step), velocities set to zero:
the state an explicit run that converged would leave, to rounding.

``model solve … implicit`` (``commands.model_solve``) calls ``implicit_static`` and then cycles as
usual: the explicit steps that follow find the model at rest, check the requested limits and stop
after their first batch (or carry on from there when the answer was not good enough). What this
solve cannot take stays with the explicit cycle: ``refusal`` and ``_Solve`` name why (rigid blocks,
contacts on deformable blocks, zone models other than elastic, large strain, dynamic mode, time
functions, quiet boundaries or table-driven face loads, energy tracking, FISH callbacks, held
components moving at a non-zero velocity, a stiffness that is singular).
"""
from __future__ import annotations

import time as _time

import numpy as np

from dec3d.kernels.zonestep import gp_externals

from .implicit_stiffness import assemble, element_stiffness, tet4_stiffness, tet10_stiffness

_F = np.float64
_I = np.int64

#: the refinement stops when the largest free unbalanced force is below this times the first one
REFINE_TOL = 1e-10
#: at most this many refinement solves (each one more residual and one more pair of triangular solves)
MAX_REFINE = 3
#: conjugate gradients (zoned blocks): relative residual and iteration limit of one solve
CG_TOL = 1e-11
CG_MAXITER = 5000
#: elements whose stiffness matrices are made and assembled at once (memory: about 90 kB each for bricks)
CHUNK_ELEMENTS = 2048
#: a solve whose residual stays above this times the first one is refused (singular stiffness)
ACCEPT_TOL = 1e-6


def _chunks(rows: np.ndarray) -> list:
    """``rows`` in pieces of at most CHUNK_ELEMENTS."""
    return np.array_split(rows, -(-len(rows) // CHUNK_ELEMENTS)) if len(rows) else []


class Refusal(Exception):
    """The model is not one the implicit solve takes; the message says why."""


def refusal(eng) -> str | None:
    """Why the model cannot take the implicit solve (before any stepper is made), or None."""
    from dec3d.model.model import KIND_DEFORMABLE, KIND_FE

    from .dynamic import has_timefns
    from .energy import is_active
    from .history import HistorySet
    from .rigid import _has_gridpoints

    m = eng.model
    b = m.blocks
    s = eng.settings()
    if not _has_gridpoints(m):
        return "the model has no zoned or FE blocks"
    kind = b["kind"]
    if (~b["hidden"] & (kind != KIND_FE) & (kind != KIND_DEFORMABLE)).any():
        return "the model has rigid blocks"
    if m.settings.large_strain:
        return "large strain is on (`model large-strain off` first)"
    if s["dynamic"]:
        return "dynamic mode is on"
    if has_timefns(m):
        return "time functions drive loads or velocities"
    if is_active(m):
        return "energy tracking is on"
    from dec3d.model.beams import has_beams
    from dec3d.model.cables import has_cables
    from dec3d.model.liners import has_liners
    if has_cables(m) or has_beams(m) or has_liners(m):
        return "the model has cables, beams or liners (structural elements move explicitly)"
    if eng.pre_steps or any(not isinstance(h, HistorySet) for h in eng.step_hooks):
        return "FISH callbacks run during the cycle"
    return None


class _Solve:
    """The free degrees of freedom, the factorised stiffness, the engine's residual and operator of
    one implicit solve on the zoned and FE blocks of ``stepper`` (a ``physics.zones.ZoneStepper``)."""

    def __init__(self, model, stepper):
        from dec3d.model.zones import ZMODEL_ELASTIC

        self.m, self.zst, self.fe = model, stepper, stepper.fe
        v = model.vertices
        zst, fe = self.zst, self.fe
        if zst.quiet is not None or zst.dyn:
            raise Refusal("quiet boundaries or table-driven face loads act")
        zs = model.store("zones") if len(zst.rows4) or len(zst.rows10) else None
        if zs is not None and (zs["cmodel"][np.concatenate((zst.rows4, zst.rows10))] != ZMODEL_ELASTIC).any():
            raise Refusal("zones have a constitutive model other than elastic")
        self.M = M = zst.masters
        held = zst.held[M]
        nm = len(M)
        fixed = np.zeros((nm, 3), bool)
        for i in range(3):
            at_vapp = (held & (1 << i)) != 0
            at_now = (held & (8 << i)) != 0
            if (at_vapp & (zst.vapp[M, i] != 0.0)).any() or (at_now & ~at_vapp & (v["velocity"][M, i] != 0.0)).any():
                raise Refusal("a held gridpoint moves at a non-zero velocity (no static answer)")
            fixed[:, i] = at_vapp | at_now
        idx = np.full(v.n, -1, _I)
        idx[M] = np.arange(nm, dtype=_I)
        pos = self.pos = np.ascontiguousarray(v["pos"])
        n = 3 * nm
        K = assemble([], n)

        def dofs(rows_of_nodes):
            mn = idx[rows_of_nodes]
            if (mn < 0).any():
                raise Refusal("an element node is not a master gridpoint")
            return (3 * mn[:, :, None] + np.arange(3)).reshape(len(mn), -1)

        # (element matrices made and summed in chunks: 60 × 60 per brick would need 29 kB an element at once)
        for q, h, rows in (fe.groups if fe is not None else ()):
            for part in _chunks(rows):
                ke, ok = element_stiffness(pos, fe.nodes, part, fe.bulk, fe.shear, q, h)
                if not ok.all():
                    raise Refusal("an FE element has a non-positive Jacobian")
                K += assemble([(dofs(fe.mnodes[part]), ke)], n)
        for part in _chunks(zst.rows4):
            g = zs["gp"][part, :4]
            w = np.where(zs["overlay"][part] >= 0, 0.5, 1.0)
            K += assemble([(dofs(zst.node[g]), tet4_stiffness(pos[g], zst.bulk[part], zst.shear[part], w))], n)
        for part in _chunks(zst.rows10):
            ke, ok = tet10_stiffness(pos, zs["gp"], part, zst.bulk, zst.shear)
            if not ok:
                raise Refusal("a 10-node zone is inverted or flat")
            K += assemble([(dofs(zst.node[zs["gp"][part]]), ke)], n)
        diag = K.diagonal().reshape(nm, 3)
        #: free degrees of freedom (flattened master × component): not held, with stiffness
        self.free = free = (~fixed & (diag > 0.0)).ravel()
        self.nfree = int(free.sum())
        if not self.nfree:
            raise Refusal("no degree of freedom is free")
        #: the assembled stiffness is the step's own (FE and 10-node elements only): solve directly;
        #: else it preconditions conjugate gradients of the zone operator
        self.exact = not len(zst.rows4)
        from scipy.sparse.linalg import splu
        try:
            # (K_ff is symmetric positive definite: minimum degree on Kᵀ + K and diagonal pivots; on the
            # 2160-element cantilever 1.8 s and 33 M factor entries against 13.6 s and 85 M with COLAMD)
            self.lu = splu(K[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options={"SymmetricMode": True})
        except RuntimeError as exc:
            raise Refusal(f"the stiffness is singular ({exc}): is every block held against rigid motion?")
        self.zero = np.zeros((v.n, 3))
        self.g = np.asarray(model.settings.gravity, _F)
        self.iterations = 0

    def _velocity(self, du: np.ndarray) -> np.ndarray:
        """(nv, 3) velocities of master displacements du (nm, 3): linked copies and slave nodes follow."""
        zst, v = self.zst, self.m.vertices
        vel = np.zeros((v.n, 3))
        vel[self.M] = du
        lk = zst.linked
        vel[lk] = vel[v["link"][lk]]
        if self.fe is not None:
            self.fe.follow(vel)
        return vel

    def operator(self, x: np.ndarray) -> np.ndarray:
        """K x on the free degrees of freedom, by the step kernels themselves on zero stresses
        (``dynamic.zone_stiffness_damping``: −K v of the zones and FE elements), linked rows summed."""
        from .dynamic import zone_stiffness_damping

        v = self.m.vertices
        du = np.zeros(3 * len(self.M))
        du[self.free] = x
        f = np.zeros((v.n, 3))
        zone_stiffness_damping(self.zst, 1.0, self.pos, self._velocity(du.reshape(-1, 3)), f)
        lk = self.zst.linked
        np.add.at(f, v["link"][lk], f[lk])
        self.iterations += 1
        return -f[self.M].ravel()[self.free]

    def residual(self) -> np.ndarray:
        """The unbalanced force (nm, 3) of the master gridpoints at rest, as ``ZoneStepper.step`` sums it
        before the motion (zone and element forces, gravity, zone body forces, applied and face forces, linked
        rows onto masters, slave forces by Eq. 9); held components zero."""
        from dec3d.kernels.zone_step import zone_step_for

        zst, fe, v = self.zst, self.fe, self.m.vertices
        facc = zst.begin()
        pos, zero, g = self.pos, self.zero, self.g
        if zst.fast is not None:
            zone_step_for(zst.models)(pos, zero, zst.zmesh, zst.material(), zst.zplan, zst.zscratch, 1.0, False,
                                      zst.nmd, facc, zst.fmag)
        if zst.ho is not None:
            zs = self.m.store("zones")
            zst.ho(pos, zero, zs["gp"], zst.rows10, zst.bulk, zst.shear, 1.0, zs["gstress"], zs["stress"], facc)
        if fe is not None:
            fe.forces(pos, zero, 1.0, g, facc, zst.fmag)
        if len(zst.r10):
            zst._body_force10(g)
            facc[zst.r10] += zst.fb10
        if zst.zb is not None:
            facc[zst.zb[0]] += zst.zb[1]
        gp_externals(zst.rows, v["link"], zst.gmass, g, v["fapp"], v["fface"], facc, zst.fmag)
        if fe is not None:
            fe.slave_forces(facc)
        r = facc[self.M].copy()
        r.ravel()[~self.free] = 0.0
        return r

    def apply(self, du: np.ndarray) -> None:
        """Move the model by master displacements du (nm, 3): stresses by the step kernels with velocity
        du over a unit time, displacements, linked copies and slave nodes as a step does."""
        from dec3d.kernels.zone_step import zone_step_for

        zst, fe, v = self.zst, self.fe, self.m.vertices
        vel = self._velocity(du)
        f, fm = np.zeros((v.n, 3)), np.zeros(v.n)
        if zst.fast is not None:
            zone_step_for(zst.models)(self.pos, vel, zst.zmesh, zst.material(), zst.zplan, zst.zscratch, 1.0, False,
                                      zst.nmd, f, fm)
        if zst.ho is not None:
            zs = self.m.store("zones")
            zst.ho(self.pos, vel, zs["gp"], zst.rows10, zst.bulk, zst.shear, 1.0, zs["gstress"], zs["stress"], f)
        if fe is not None:
            fe.forces(self.pos, vel, 1.0, np.zeros(3), f)
        disp = v["disp"]
        disp[self.M] += du
        lk = zst.linked
        disp[lk] = disp[v["link"][lk]]
        if fe is not None:
            fe.follow(disp)

    def correction(self, r: np.ndarray) -> np.ndarray:
        """The displacements (nm, 3) that remove the residual r: K_ff⁻¹ r directly, or by conjugate
        gradients of the step's operator preconditioned by the assembled stiffness."""
        b = r.ravel()[self.free]
        if self.exact:
            x = self.lu.solve(b)
        else:
            from scipy.sparse.linalg import LinearOperator, cg

            n = self.nfree
            A = LinearOperator((n, n), matvec=self.operator, dtype=_F)
            P = LinearOperator((n, n), matvec=self.lu.solve, dtype=_F)
            x, _ = cg(A, b, rtol=CG_TOL, atol=0.0, maxiter=CG_MAXITER, M=P)
        du = np.zeros(3 * len(self.M))
        du[self.free] = x
        return du.reshape(-1, 3)

    def solve(self) -> dict:
        r0 = self.residual()
        first = float(np.abs(r0).max())
        r, refines = r0, 0
        while True:
            du = self.correction(r)
            if not np.isfinite(du).all():
                raise Refusal("the stiffness is singular: is every block held against rigid motion?")
            self.apply(du)
            r = self.residual()
            left = float(np.abs(r).max())
            if left <= REFINE_TOL * first or refines >= MAX_REFINE:
                break
            refines += 1
        if not left <= ACCEPT_TOL * max(first, 1e-300) and first > 0.0:
            raise Refusal(f"the solve left an unbalanced force of {left:.3g} N of {first:.3g} N: the stiffness is "
                          "singular or ill-conditioned (is every block held against rigid motion?)")
        return {"unknowns": self.nfree, "first": first, "left": left, "refines": refines,
                "iterations": self.iterations, "residual": r}


def implicit_static(eng, warn=None) -> dict:
    """Solve the model's zoned and FE blocks to static equilibrium (module text) and leave them at
    rest there. Returns {"unknowns", "first", "left", "refines", "iterations", "seconds"}; raises
    ``Refusal`` (the model unchanged) when the model is not one it takes."""
    t0 = _time.process_time()
    why = refusal(eng)
    if why:
        raise Refusal(why)
    m = eng.model
    if eng._signature != eng._geometry_signature():
        eng.detect()
    if eng._zone_contacts_check():
        raise Refusal("contacts act on deformable blocks")
    from .rigid import RunError
    from .zone_cache import stepper_cache
    from .zones import ZoneStepper

    zst = ZoneStepper(m, RunError, warn, stepper_cache(eng))
    v = m.vertices
    keep = [(v, {k: v[k].copy() for k in ("disp", "velocity", "force")})]
    for name in ("feblocks", "zones"):
        if name in m.stores:
            st = m.store(name)
            keep.append((st, {k: st[k].copy() for k in ("gstress", "stress") if k in st}))
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            out = _Solve(m, zst).solve()
    except BaseException:
        for store, arrays in keep:
            for k, a in arrays.items():
                store[k][:] = a
        raise
    v["velocity"][zst.rows] = 0.0
    v["force"][zst.masters] = out.pop("residual")
    eng._criteria = None
    out["seconds"] = _time.process_time() - t0
    return out
