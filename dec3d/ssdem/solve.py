"""Load increments, secant iteration and removal of unstable blocks (thesis Sec. 4.1.3-4.1.4).

    for each load step k = 1..n_steps (load factor k/n_steps):
        repeat:
            assemble K from the current secant springs
            drop floating blocks and blocks with (near-)zero pivots, with their interfaces
            solve K u = (k/n) f  (total load: secant stiffness relates totals)
            interface stresses -> spring laws -> new k_n, k_s (never larger)
            now and then, and at convergence: the mechanism test on the tangent matrix
        until max |k_s change| / k_s < tol, nothing new cracked or was removed

The change is measured against the spring's current stiffness, not its initial one
(thesis Sec. 4.1.4: "changes in boundary stiffness less than a user defined value").
(k_s,old - k_s,new) / k_s,old = 1 - tau_strength / tau_trial is the fraction by which the
shear stress of the last solve exceeds the strength: converged means every spring is
within `tol` of its law.  Measured against k_s0 instead, a spring already softened a
hundredfold would count its changes a hundred times smaller, and a block creeping
towards a mechanism (its secant falling like 1/slip) would pass for converged.

Two rank tests find instability (thesis Sec. 3.2.2):
  * the secant matrix: a floating block (no spring left to a fixed one), or a DOF
    whose pivot is ~0 (e.g. a block on a cracked or zero-stiffness interface);
  * the tangent matrix: springs carrying their full strength add no shear stiffness.
    A zero pivot there is a plastic mechanism: blocks that can slide with every
    resisting spring at its strength.  The secant matrix alone would not show it (a
    block overloaded in shear just softens and slides further every iteration).
Pivots are compared with the intact stiffness of the same DOF (Factor's scale).
With no-tension interfaces (settings.interfaces, contact.py) the contact of every
interface is a third thing the iteration settles: each solve uses the last contact,
the next contact comes from its motion, and a step converges only when the contacts
stop moving (by less than `tol` of the interface length).  The tangent test then holds
open interfaces shut (an opening can widen, not close through), so what it finds is
still a mechanism; a block whose contacts are all open when the step settles is removed.
Unstable blocks are removed as the thesis does: their DOFs and every interface
touching them leave the system, their loads go with them, and the analysis goes on.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import contact, springs
from .assemble import Assembler, local_stiffness, relative_motion, transfer_matrices
from .linsolve import Factor, floating_blocks
from .model import Problem

#: secant iterations between two mechanism (tangent matrix) tests in a step
TANGENT_EVERY = 10
#: normal stiffness left to a wholly open no-tension interface, relative to k_n (solve.local)
EPS_OPEN = 1e-6
#: largest over-relaxation of a secant update (_Relaxation); 1 turns it off
OMEGA_MAX = 64.0


@dataclass
class StepRecord:
    step: int
    load: float
    iterations: int
    converged: bool
    n_yielded: int
    n_cracked: int
    n_unstable: int
    max_displacement: float
    max_change: float


@dataclass
class State:
    """Arrays that evolve during the analysis (m interfaces, n blocks)."""

    kn: np.ndarray
    ks: np.ndarray
    cracked: np.ndarray
    removed: np.ndarray
    removed_step: np.ndarray
    u: np.ndarray
    rel: np.ndarray
    plastic: np.ndarray
    ks_before: np.ndarray = None      # k_s before the last update (the over-relaxation needs it)
    s1: np.ndarray = None             # contact [s1, s2] of each interface along t from its midpoint
    s2: np.ndarray = None             # (contact.py; the whole length unless no-tension and open)
    load: float = 0.0
    steps: list = field(default_factory=list)
    factorizations: int = 0


class _Context:
    """What stays fixed while the set of active DOFs does not change."""

    def __init__(self, prob: Problem, removed: np.ndarray, Ta, Tb):
        blk, itf = prob.blocks, prob.interfaces
        self.key = removed.tobytes()
        self.live = ~blk.fix & ~removed[:, None]
        dof = np.full((blk.n, 3), -1, np.int64)
        dof[self.live] = np.arange(int(self.live.sum()))
        self.owner = np.nonzero(self.live)[0]              # block of each reduced DOF
        self.asm = Assembler(itf.a, itf.b, Ta, Tb, dof)
        active = ~(removed[itf.a] | removed[itf.b])
        intact = local_stiffness(itf.kn, itf.ks, itf.length) * active[:, None]
        self.scale = self.asm.matrix(intact).diagonal() if self.asm.ndof else np.zeros(0)
        self.factor = None


def no_tension(prob: Problem) -> np.ndarray | None:
    """(m,) True where the interface cannot pull (settings.interfaces), None when none is."""
    if prob.settings.interfaces != "no-tension":
        return None
    return np.ones(prob.interfaces.m, bool)


def local(prob: Problem, st: State, active: np.ndarray, ks: np.ndarray | None = None) -> np.ndarray:
    """Local stiffness of every interface: diagonals (m, 3) when every contact is the whole
    interface, else the contact matrices (m, 3, 3) of contact.local_matrix; 0 where inactive."""
    itf = prob.interfaces
    ks = st.ks if ks is None else ks
    if st.s1 is None:
        return local_stiffness(st.kn, ks, itf.length) * active[:, None]
    h = 0.5 * itf.length
    # an open interface keeps EPS_OPEN of its normal springs: a block whose contacts the
    # last solve all opened is held (far off) instead of floating, and the next solve
    # closes them again if it falls back on them (_open_blocks removes it if they stay open)
    shut = st.s2 - st.s1 <= 0
    gap = contact.local_matrix(np.where(shut, EPS_OPEN * st.kn, 0.0), 0.0 * ks, -h, h)
    return (contact.local_matrix(st.kn, ks, st.s1, st.s2) + gap) * active[:, None, None]


def contact_length(prob: Problem, st: State) -> np.ndarray:
    """Length of each interface in contact (the whole length unless no-tension and open)."""
    return prob.interfaces.length if st.s1 is None else st.s2 - st.s1


def _active(prob: Problem, st: State) -> np.ndarray:
    itf = prob.interfaces
    return ~(st.removed[itf.a] | st.removed[itf.b])


def _remove(st: State, mask: np.ndarray, step: int) -> int:
    new = mask & ~st.removed
    st.removed_step[new] = step
    st.removed |= new
    return int(new.sum())


def _context(prob, st, Ta, Tb, cache) -> _Context:
    if cache.get("ctx") is None or cache["ctx"].key != st.removed.tobytes():
        cache["ctx"] = _Context(prob, st.removed, Ta, Tb)
    return cache["ctx"]


def _solve_with_removal(prob, st, Ta, Tb, f_total, step, cache, refactor=True) -> int:
    """Solve at the current springs, removing unstable blocks until K is regular.

    Returns the number of blocks removed.  With refactor=False the last factor
    preconditions conjugate gradients instead of a new factorisation; if CG stalls,
    K is factored afresh and its pivots tested as usual.
    """
    blk, itf, cfg = prob.blocks, prob.interfaces, prob.settings
    n_removed = 0
    while True:
        active = _active(prob, st)
        carries = active & ((st.kn > 0) | (st.ks > 0))
        floating = floating_blocks(blk.n, itf.a, itf.b, carries, blk.fix.any(axis=1))
        floating &= ~blk.fixed & ~st.removed
        if floating.any():
            n_removed += _remove(st, floating, step)
            continue
        ctx = _context(prob, st, Ta, Tb, cache)
        u = np.zeros((blk.n, 3))
        if ctx.asm.ndof == 0:
            st.u = u
            return n_removed
        K = ctx.asm.matrix(local(prob, st, active))
        if not refactor and ctx.factor is not None:
            x = ctx.factor.pcg(K, f_total[ctx.live], st.u[ctx.live])
            if x is not None:
                u[ctx.live] = x
                st.u = u
                return n_removed
        fac = Factor(K, cfg.pivot_tol, ctx.scale)
        st.factorizations += 1
        if len(fac.bad):
            mask = np.zeros(blk.n, bool)
            mask[ctx.owner[fac.bad]] = True
            n_removed += _remove(st, mask, step)
            continue
        ctx.factor = fac
        u[ctx.live] = fac.solve(f_total[ctx.live])
        st.u = u
        return n_removed


def _open_blocks(prob, st, step) -> int:
    """Remove the groups of blocks that no closed contact ties to a fixed block."""
    blk, itf = prob.blocks, prob.interfaces
    carries = _active(prob, st) & ((st.kn > 0) | (st.ks > 0)) & (contact_length(prob, st) > 0)
    floating = floating_blocks(blk.n, itf.a, itf.b, carries, blk.fix.any(axis=1))
    return _remove(st, floating & ~blk.fixed & ~st.removed, step)


def _mechanisms(prob, st, Ta, Tb, step, cache) -> int:
    """Rank test of the tangent matrix; removes the blocks of plastic mechanisms."""
    itf, cfg = prob.interfaces, prob.settings
    active = _active(prob, st)
    if not (st.plastic & active).any():
        return 0
    ctx = _context(prob, st, Ta, Tb, cache)
    if ctx.asm.ndof == 0:
        return 0
    ks_t = np.where(st.plastic, 0.0, st.ks)
    if st.s1 is None:
        Kt = ctx.asm.matrix(local(prob, st, active, ks_t))
    else:
        # an open no-tension interface may open further but not close through: the test
        # holds it shut (normal and rotation springs over its whole length, no shear), so
        # a mechanism found is one that moves no open interface, admissible and a proof;
        # one that would open them further is left to the secant iteration
        shut = (st.s2 - st.s1) <= 0
        h = 0.5 * itf.length
        Kl = contact.local_matrix(st.kn, np.where(shut, 0.0, ks_t), np.where(shut, -h, st.s1),
                                  np.where(shut, h, st.s2))
        Kt = ctx.asm.matrix(Kl * active[:, None, None])
    fac = Factor(Kt, cfg.pivot_tol, ctx.scale)
    st.factorizations += 1
    if not len(fac.bad):
        return 0
    mask = np.zeros(prob.blocks.n, bool)
    mask[ctx.owner[fac.bad]] = True
    return _remove(st, mask, step)


def stiffness_change(ks_old: np.ndarray, ks_new: np.ndarray, active: np.ndarray) -> float:
    """max (k_s,old - k_s,new) / k_s,old over active springs that still have stiffness:
    by how much (as a fraction) the last solve's shear stress overshoots the strength."""
    use = active & (ks_old > 0)
    return float(np.max(np.abs(ks_old[use] - ks_new[use]) / ks_old[use], initial=0.0))


def stresses(prob: Problem, st: State, load: float):
    """Midpoint (= average) stresses of every interface at the current solution.

    Returns sigma_n (compression +), tau (along t, sign of the slip of b on a), sigma'_n.
    On a partly open no-tension interface they are the stresses on its contact (averaged
    over it: sigma_n = -N/a); on an open one sigma_n = 0.
    """
    itf, cfg = prob.interfaces, prob.settings
    if st.s1 is None:
        sigma_n = -st.kn * st.rel[:, 0]
    else:
        a, S1, _ = contact.moments(st.s1, st.s2)
        with np.errstate(divide="ignore", invalid="ignore"):
            sigma_n = np.where(a > 0, -st.kn * (st.rel[:, 0] - np.where(a > 0, S1 / a, 0.0) * st.rel[:, 2]), 0.0)
    tau = st.ks * st.rel[:, 1]
    sig_eff = springs.effective_normal(sigma_n, itf.u_pore, cfg.ru, cfg.ru_mode, load)
    return sigma_n, tau, sig_eff


class _ContactDamping:
    """Under-relaxed contact updates where the contact iteration oscillates.

    The contacts of partly open interfaces can cycle (open a little, close, open more,
    ..., several interfaces in turn) instead of settling.  Each time an interface's
    contact length changes direction within a load step its step is cut: after r
    reversals the new contact is s + theta (s_computed - s), theta = 1/(1 + r) (at least
    1/64), a diminishing step that ends a cycle however many interfaces take part.
    The fixed point is the same (converged means s_computed = s), only the path to it
    changes.
    """

    def __init__(self, m: int):
        self.reversals = np.zeros(m)
        self.last = np.zeros(m)

    def step(self, s1, s2, n1, n2, length, tol):
        da = (n2 - n1) - (s2 - s1)
        self.reversals += (da * self.last < 0) & (np.abs(da) > tol * length)
        self.last = da
        theta = np.maximum(1.0 / (1.0 + self.reversals), 1.0 / 64.0)
        return s1 + theta * (n1 - s1), s2 + theta * (n2 - s2)


class _Relaxation:
    """Over-relaxed secant update, undone when it softens a spring past its law.

    Near a limit state the secant iteration creeps: every solve the yielding springs
    overshoot their strength by a fraction that shrinks by a nearly constant ratio rho
    (~0.99 and more), so hundreds of iterations pass before the overshoot is below
    `tol`.  The springs then lose stiffness by nearly the same factor each iteration.
    After a plain update that softened springs by k_new/k_old, the springs softened are
    taken further, to k_old (k_new/k_old)^omega, omega = 1/(1 - rho) (Aitken's estimate of
    the remaining steps of a geometric sequence), at most twice the last omega and
    OMEGA_MAX, rho the ratio of the last two overshoots.  Only springs at a constant
    strength (no softening, or past delta_res) are extrapolated.
    The fixed point is the plain iteration's: the next solve is checked, and if any
    extrapolated spring's law now gives a stiffness above the one it was given (softened
    too far: it would unload), the extrapolation is undone (the plain update's springs
    are restored and solved) and omega starts again at 1.  An accepted extrapolation
    leaves every spring at or above its law, i.e. still on the plain iteration's side of
    its fixed point, which the plain updates then reach.
    """

    def __init__(self, tol: float):
        self.tol = tol
        self.omega = 1.0
        self.last = np.inf              # overshoot (stiffness_change) of the previous iteration
        self.base = None                # plain-update springs under an extrapolation
        self.mask = None

    def extrapolate(self, prob: Problem, st: State, change: float, active: np.ndarray, plain: bool) -> None:
        rho = change / self.last if self.last > 0 else np.inf
        self.last = change
        self.base = None
        if not plain or not 0.0 < rho < 1.0 or OMEGA_MAX <= 1.0:
            self.omega = 1.0
            return
        self.omega = min(1.0 / (1.0 - rho), 2.0 * self.omega, OMEGA_MAX)
        prev = st.ks_before
        itf = prob.interfaces
        # not on a softening branch (strength falling with slip), where going further would
        # change the path (the peak "missed", thesis Sec. 4.1.4), not only speed it up
        plastic = ((itf.c_r == itf.c_p) & (itf.tan_r == itf.tan_p)) | (np.abs(st.rel[:, 1]) >= itf.del_res)
        mask = active & plastic & (st.ks < prev) & (prev > 0) & (st.ks > 0)
        if self.omega <= 1.0 or not mask.any():
            return
        self.base, self.mask = st.ks.copy(), mask
        st.ks = st.ks.copy()
        st.ks[mask] = prev[mask] * (st.ks[mask] / prev[mask]) ** self.omega

    def undo(self, st: State) -> None:
        """Drop an extrapolation not yet checked by a solve."""
        if self.base is not None:
            st.ks, self.base = self.base, None

    def overshot(self, prob: Problem, st: State, sig_eff: np.ndarray, active: np.ndarray) -> bool:
        """After the solve with extrapolated springs: True (and the plain springs restored)
        when an extrapolated spring's law asks for more stiffness than it was given."""
        if self.base is None:
            return False
        itf = prob.interfaces
        tau_p, tau_r = springs.strengths(sig_eff, itf.c_p, itf.tan_p, itf.c_r, itf.tan_r)
        ks_law, _ = springs.secant_ks(st.rel[:, 1], tau_p, tau_r, itf.ks, itf.del_res)
        m = self.mask & active
        bad = bool(np.any(ks_law[m] > st.ks[m] * (1.0 + self.tol)))
        if bad:
            st.ks = self.base
            self.omega, self.last = 1.0, np.inf
        self.base = None
        return bad


def run(prob: Problem, progress=None, stop_on_failure: bool = False) -> State:
    """Run the whole load history; `progress(step, n_steps, iteration)` is called if given.

    stop_on_failure: return after the first load step that does not converge or
    removes a block (the strength-reduction search only needs to know that it fails).
    """
    blk, itf, cfg = prob.blocks, prob.interfaces, prob.settings
    Ta, Tb = transfer_matrices(blk, itf)
    st = State(kn=itf.kn.copy(), ks=itf.ks.copy(), cracked=np.zeros(itf.m, bool),
               removed=np.zeros(blk.n, bool), removed_step=np.full(blk.n, -1, np.int64),
               u=np.zeros((blk.n, 3)), rel=np.zeros((itf.m, 3)), plastic=np.zeros(itf.m, bool))
    nt = no_tension(prob)
    if nt is not None:
        st.s1, st.s2 = -0.5 * itf.length, 0.5 * itf.length
    cache: dict = {}
    for step in range(1, cfg.n_steps + 1):
        load = step / cfg.n_steps
        st.load = load
        f_total = load * blk.force
        converged, change, it = False, np.inf, 0
        fresh = True                      # a new step, a crack or a removal gets a new factor
        relax, carried = _Relaxation(cfg.tol), 0
        damp = _ContactDamping(itf.m) if nt is not None else None
        for it in range(1, cfg.max_iter + 1):
            removed = carried + _solve_with_removal(prob, st, Ta, Tb, f_total, step, cache, refactor=fresh)
            carried = 0
            st.rel = relative_motion(st.u, itf.a, itf.b, Ta, Tb)
            active = _active(prob, st)
            sigma_n, _, sig_eff = stresses(prob, st, load)
            if relax.overshot(prob, st, sig_eff, active):
                carried = removed         # springs back to the plain secant update, solved again
                continue
            kn, ks, cracked, new_crack, plastic = springs.update(
                st.kn, st.ks, st.cracked, itf.ks, st.rel[:, 1], sigma_n, sig_eff,
                itf.c_p, itf.tan_p, itf.c_r, itf.tan_r, itf.del_res, itf.tensile, itf.cutoff & active)
            moved = 0.0
            if nt is not None:
                # an open interface carries no shear: its spring keeps its state; then the
                # contact of the next solve comes from this one's motion
                shut = contact_length(prob, st) <= 0
                ks, plastic = np.where(shut, st.ks, ks), plastic & ~shut
                s1, s2 = contact.zone(st.rel, itf.length, nt)
                moved = float(np.max(((np.abs(s1 - st.s1) + np.abs(s2 - st.s2)) / itf.length)[active], initial=0.0))
                st.s1, st.s2 = damp.step(st.s1, st.s2, s1, s2, itf.length, cfg.tol)
            change = stiffness_change(st.ks, ks, active)
            st.ks_before = st.ks
            new_crack &= active
            st.kn, st.ks, st.cracked, st.plastic = kn, ks, cracked, plastic & active
            done = change < cfg.tol and moved < cfg.tol and not new_crack.any() and removed == 0
            if done and nt is not None:
                # settled with every contact of some blocks open: nothing holds them
                removed += _open_blocks(prob, st, step)
                done = removed == 0
            if done or it % TANGENT_EVERY == 0:
                removed += _mechanisms(prob, st, Ta, Tb, step, cache)
                done = done and removed == 0
            if progress is not None:
                progress(step, cfg.n_steps, it)
            fresh = bool(new_crack.any()) or removed > 0
            if done:
                converged = True
                break
            relax.extrapolate(prob, st, change, active, plain=not fresh)
        relax.undo(st)                    # out of iterations: keep the plain update's springs
        if step == cfg.n_steps:
            # the last update changed the springs a little: re-solve so that the reported
            # displacements and stresses belong to the final springs
            _solve_with_removal(prob, st, Ta, Tb, f_total, step, cache, refactor=False)
            st.rel = relative_motion(st.u, itf.a, itf.b, Ta, Tb)
        active = _active(prob, st)
        yielded = active & (st.ks < itf.ks * (1 - 1e-9))
        disp = np.hypot(st.u[:, 0], st.u[:, 1])
        st.steps.append(StepRecord(step=step, load=load, iterations=it, converged=converged,
                                   n_yielded=int(yielded.sum()), n_cracked=int((st.cracked & active).sum()),
                                   n_unstable=int(st.removed.sum()),
                                   max_displacement=float(disp[~st.removed].max(initial=0.0)),
                                   max_change=change))
        if stop_on_failure and not (converged and not st.removed.any()):
            break
    return st
