"""A static answer for linear elastic FE blocks in one sparse direct solve (`model solve … implicit`).

The explicit, density-scaled and damped cycle of ``physics.zones`` reaches the equilibrium of its
own discretisation: at rest, the force of the element stresses plus gravity, applied and face forces
vanishes at every free master node. In small strain that force is linear in the displacement since
the start of the solve: the geometry does not move, and every element stress grows by
D : ε(v Δt) at each step, so after displacements Δu the stresses are σ0 + D : ε(Δu) and

    F(Δu) = F(0) − K Δu,

with F(0) the force the engine's own step finds at rest now (``residual``) and K the stiffness of
exactly the element pass the explicit step runs (its Gauss rule, the hourglass control of 2×2×2
elements). K is assembled here from that pass itself: each element is run alone (on a copy of its
20 nodes) with a unit velocity on each of its 60 degrees of freedom over a unit time, from zero
stress, and the negated nodal forces are its stiffness columns (``element_stiffness``); no second
formulation of the element exists to drift from the first. K_ff Δu_f = F_f(0) on the free degrees of
freedom (master nodes, components not held, with stiffness) is solved by sparse LU
(``scipy.sparse.linalg.splu``), refined with the engine's residual until it is below
``REFINE_TOL`` of the first one. The stresses are then moved on by the engine's element pass with
"velocity" Δu over a unit time, the displacements by Δu (linked copies and slave nodes follow as in
a step), velocities set to zero: the state an explicit run that converged would leave, to rounding.

``model solve … implicit`` (``commands.model_solve``) calls ``implicit_static`` and then cycles as
usual: the explicit steps that follow find the model at rest, check the requested ratio and stop
after their first batch (or carry on from there when the answer was not good enough). What this
solve cannot take stays with the explicit cycle: ``refusal`` names why (zones, rigid blocks,
contacts on deformable blocks, large strain, dynamic mode, time functions, quiet boundaries,
energy tracking, FISH callbacks, held components moving at a non-zero velocity).
"""
from __future__ import annotations

import time as _time

import numpy as np

from dec3d.kernels.feblock import feb_element_pass_serial
from dec3d.kernels.zonestep import gp_externals

_F = np.float64
_I = np.int64

#: the refinement stops when the largest free unbalanced force is below this times the first one
REFINE_TOL = 1e-10
#: at most this many refinement solves (each one more residual and one more pair of triangular solves)
MAX_REFINE = 3
#: a solve whose residual stays above this times the first one is refused (singular stiffness)
ACCEPT_TOL = 1e-6


class Refusal(Exception):
    """The model is not one the implicit solve takes; the message says why."""


def element_stiffness(pos, nodes, rows, bulk, shear, nq, hg) -> tuple[np.ndarray, np.ndarray]:
    """(ke (len(rows), 60, 60), ok (len(rows),) bool): the stiffness of each element of ``rows``
    as the explicit element pass (``feb_element_pass_serial``) computes forces from velocities:
    ke[k, 3a+i, 3b+j] = −(force on node a, component i, of element k) for a unit velocity of node
    b in direction j over a unit time from zero stress. Each element runs on its own copy of its
    nodes, so the 60 passes give every element's columns at once."""
    nr = len(rows)
    xp = np.ascontiguousarray(pos[nodes[rows]].reshape(nr * 20, 3))
    pnodes = np.arange(nr * 20, dtype=_I).reshape(nr, 20)
    prow = np.arange(nr, dtype=_I)
    bk = np.ascontiguousarray(bulk[rows])
    sh = np.ascontiguousarray(shear[rows])
    vel = np.zeros((nr * 20, 3))
    gs = np.zeros((nr, 27, 6))
    st = np.zeros((nr, 6))
    fe = np.empty((nr, 20, 3))
    ok = np.ones(nr, np.bool_)
    okk = np.empty(nr, np.bool_)
    ke = np.empty((nr, 60, 60))
    for a in range(20):
        for i in range(3):
            vel[:] = 0.0
            vel[a::20, i] = 1.0
            gs[:] = 0.0
            feb_element_pass_serial(xp, vel, pnodes, prow, bk, sh, 1.0, gs, st, fe, okk, nq, hg)
            ok &= okk
            ke[:, :, 3 * a + i] = -fe.reshape(nr, 60)
    return ke, ok


def refusal(eng) -> str | None:
    """Why the model cannot take the implicit solve (before any stepper is made), or None."""
    from dec3d.model.feblocks import has_feblocks
    from dec3d.model.model import KIND_DEFORMABLE, KIND_FE

    from .dynamic import has_timefns
    from .energy import is_active
    from .history import HistorySet

    m = eng.model
    b = m.blocks
    s = eng.settings()
    if not has_feblocks(m):
        return "the model has no FE blocks (the implicit solve takes FE blocks only)"
    live = ~b["hidden"]
    kind = b["kind"]
    if (live & (kind == KIND_DEFORMABLE)).any():
        return "the model has zoned blocks (the implicit solve takes FE blocks only)"
    if (live & (kind != KIND_FE) & (kind != KIND_DEFORMABLE)).any():
        return "the model has rigid blocks"
    if m.settings.large_strain:
        return "large strain is on (`model large-strain off` first)"
    if s["dynamic"]:
        return "dynamic mode is on"
    if has_timefns(m):
        return "time functions drive loads or velocities"
    if is_active(m):
        return "energy tracking is on"
    if eng.pre_steps or any(not isinstance(h, HistorySet) for h in eng.step_hooks):
        return "FISH callbacks run during the cycle"
    return None


class _Solve:
    """The free degrees of freedom, the factorised stiffness and the engine's residual of one
    implicit solve on the FE blocks of ``stepper`` (a ``physics.zones.ZoneStepper``)."""

    def __init__(self, model, stepper):
        self.m, self.zst, self.fe = model, stepper, stepper.fe
        v = model.vertices
        zst, fe = self.zst, self.fe
        if fe is None or len(zst.rows4) or len(zst.rows10):
            raise Refusal("the model has zoned blocks (the implicit solve takes FE blocks only)")
        if zst.quiet is not None or zst.dyn:
            raise Refusal("quiet boundaries or table-driven face loads act")
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
        pos = np.ascontiguousarray(v["pos"])
        ii, jj, kk = [], [], []
        for q, h, rows in fe.groups:
            if not len(rows):
                continue
            ke, ok = element_stiffness(pos, fe.nodes, rows, fe.bulk, fe.shear, q, h)
            if not ok.all():
                raise Refusal("an FE element has a non-positive Jacobian")
            mn = idx[fe.mnodes[rows]]
            if (mn < 0).any():
                raise Refusal("an element node is not a master gridpoint")
            dof = (3 * mn[:, :, None] + np.arange(3)).reshape(len(rows), 60)
            ii.append(np.repeat(dof[:, :, None], 60, axis=2).ravel())
            jj.append(np.repeat(dof[:, None, :], 60, axis=1).ravel())
            kk.append(ke.ravel())
        from scipy.sparse import coo_matrix
        from scipy.sparse.linalg import splu

        n = 3 * nm
        K = coo_matrix((np.concatenate(kk), (np.concatenate(ii), np.concatenate(jj))), shape=(n, n)).tocsc()
        diag = K.diagonal().reshape(nm, 3)
        #: free degrees of freedom (flattened master × component): not held, with stiffness
        self.free = free = (~fixed & (diag > 0.0)).ravel()
        self.nfree = int(free.sum())
        if not self.nfree:
            raise Refusal("no degree of freedom is free")
        Kff = K[free][:, free].tocsc()
        try:
            self.lu = splu(Kff)
        except RuntimeError as exc:
            raise Refusal(f"the stiffness is singular ({exc}): is every block held against rigid motion?")
        self.zero = np.zeros((v.n, 3))
        self.g = np.asarray(model.settings.gravity, _F)

    def residual(self) -> np.ndarray:
        """The unbalanced force (nm, 3) of the master nodes at rest, as ``ZoneStepper.step`` sums it
        before the motion (element forces, consistent gravity, applied and face forces, linked
        rows onto masters, slave forces by Eq. 9); held components zero."""
        zst, fe, v = self.zst, self.fe, self.m.vertices
        facc = zst.begin()
        fe.forces(np.ascontiguousarray(v["pos"]), self.zero, 1.0, self.g, facc, zst.fmag)
        gp_externals(zst.rows, v["link"], zst.gmass, self.g, v["fapp"], v["fface"], facc, zst.fmag)
        fe.slave_forces(facc)
        r = facc[self.M].copy()
        r.ravel()[~self.free] = 0.0
        return r

    def apply(self, du: np.ndarray) -> None:
        """Move the model by master displacements du (nm, 3): stresses by the element pass with
        velocity du over a unit time, displacements, linked copies and slave nodes as a step does."""
        zst, fe, v = self.zst, self.fe, self.m.vertices
        vel = np.zeros((v.n, 3))
        vel[self.M] = du
        lk = zst.linked
        link = v["link"]
        vel[lk] = vel[link[lk]]
        fe.follow(vel)
        fe.forces(np.ascontiguousarray(v["pos"]), vel, 1.0, np.zeros(3), np.zeros((v.n, 3)))
        disp = v["disp"]
        disp[self.M] += du
        disp[lk] = disp[link[lk]]
        fe.follow(disp)

    def solve(self) -> dict:
        r0 = self.residual()
        first = float(np.abs(r0).max())
        r, refines = r0, 0
        while True:
            du = np.zeros(r.shape)
            du.ravel()[self.free] = self.lu.solve(r.ravel()[self.free])
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
        return {"unknowns": self.nfree, "first": first, "left": left, "refines": refines, "residual": r}


def implicit_static(eng, warn=None) -> dict:
    """Solve the model's FE blocks to static equilibrium in one sparse solve (module text) and
    leave them at rest there. Returns {"unknowns", "first", "left", "refines", "seconds"}; raises
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
    from .zones import ZoneStepper

    zst = ZoneStepper(m, RunError, warn)
    v, es = m.vertices, m.store("feblocks")
    keep = {k: v[k].copy() for k in ("disp", "velocity", "force")}
    keep_s = {k: es[k].copy() for k in ("gstress", "stress")}
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            out = _Solve(m, zst).solve()
    except BaseException:
        for k, a in keep.items():
            v[k][:] = a
        for k, a in keep_s.items():
            es[k][:] = a
        raise
    v["velocity"][zst.rows] = 0.0
    v["force"][zst.masters] = out.pop("residual")
    eng._criteria = None
    out["seconds"] = _time.process_time() - t0
    return out
