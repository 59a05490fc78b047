"""Load increments, secant iteration and removal of unstable blocks (thesis Sec. 4.1.3-4.1.4).

    for each load step k = 1..n_steps (load factor k/n_steps):
        repeat:
            assemble K from the current secant springs
            drop floating blocks and blocks with (near-)zero pivots, with their interfaces
            solve K u = (k/n) f  (total load: secant stiffness relates totals)
            interface stresses -> spring laws -> new k_n, k_s (never larger)
        until max |k_s change| / k_s0 < tol and nothing new cracked or was removed

Unstable blocks are removed as the thesis does (Sec. 3.2.2): their DOFs and every
interface touching them leave the system, their loads go with them, and the
analysis continues; the step at which each left is recorded.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import springs
from .assemble import Assembler, local_stiffness, relative_motion, transfer_matrices
from .linsolve import Factor, floating_blocks
from .model import Problem


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
    load: float = 0.0
    steps: list = field(default_factory=list)
    factorizations: int = 0


def _active_interfaces(prob: Problem, st: State) -> np.ndarray:
    itf = prob.interfaces
    return ~(st.removed[itf.a] | st.removed[itf.b])


def _solve_with_removal(prob, st, Ta, Tb, f_total, step, cache):
    """Solve at the current springs, removing unstable blocks until K is regular.

    Returns the number of blocks removed.  `cache` keeps the Assembler between calls
    while the set of active DOFs does not change.
    """
    blk, itf, cfg = prob.blocks, prob.interfaces, prob.settings
    n_removed = 0
    while True:
        active = _active_interfaces(prob, st)
        free = ~blk.fixed & ~st.removed
        carries = active & ((st.kn > 0) | (st.ks > 0))
        floating = floating_blocks(blk.n, itf.a, itf.b, carries, blk.fixed) & free
        if floating.any():
            _remove(st, floating, step)
            n_removed += int(floating.sum())
            continue
        key = st.removed.tobytes()
        if cache.get("key") != key:
            dof_block = np.full(blk.n, -1, np.int64)
            dof_block[free] = np.arange(int(free.sum())) * 3
            cache.update(key=key, dof_block=dof_block,
                         asm=Assembler(itf.a, itf.b, Ta, Tb, dof_block))
        asm, dof_block = cache["asm"], cache["dof_block"]
        u = np.zeros((blk.n, 3))
        if asm.ndof == 0:
            st.u = u
            return n_removed
        kl = local_stiffness(st.kn, st.ks, itf.length) * active[:, None]
        K = asm.matrix(kl)
        fac = Factor(K, cfg.pivot_tol)
        st.factorizations += 1
        if len(fac.bad):
            owner = np.flatnonzero(free)[np.unique(fac.bad // 3)]
            mask = np.zeros(blk.n, bool)
            mask[owner] = True
            _remove(st, mask, step)
            n_removed += len(owner)
            continue
        rhs = f_total[free].ravel()
        u[free] = fac.solve(rhs).reshape(-1, 3)
        st.u = u
        return n_removed


def _remove(st: State, mask: np.ndarray, step: int) -> None:
    st.removed_step[mask & ~st.removed] = step
    st.removed |= mask


def stresses(prob: Problem, st: State, load: float):
    """Midpoint (= average) stresses of every interface at the current solution.

    Returns sigma_n (compression +), tau (along t, sign of the slip of b on a), sigma'_n.
    """
    itf, cfg = prob.interfaces, prob.settings
    sigma_n = -st.kn * st.rel[:, 0]
    tau = st.ks * st.rel[:, 1]
    sig_eff = springs.effective_normal(sigma_n, itf.u_pore, cfg.ru, cfg.ru_mode, load)
    return sigma_n, tau, sig_eff


def run(prob: Problem, progress=None) -> State:
    """Run the whole load history; `progress(step, n_steps, iteration)` is called if given."""
    blk, itf, cfg = prob.blocks, prob.interfaces, prob.settings
    Ta, Tb = transfer_matrices(blk, itf)
    st = State(kn=itf.kn.copy(), ks=itf.ks.copy(), cracked=np.zeros(itf.m, bool),
               removed=np.zeros(blk.n, bool), removed_step=np.full(blk.n, -1, np.int64),
               u=np.zeros((blk.n, 3)), rel=np.zeros((itf.m, 3)))
    cache: dict = {}
    for step in range(1, cfg.n_steps + 1):
        load = step / cfg.n_steps
        st.load = load
        f_total = load * blk.force
        converged, change, it = False, np.inf, 0
        for it in range(1, cfg.max_iter + 1):
            removed_now = _solve_with_removal(prob, st, Ta, Tb, f_total, step, cache)
            st.rel = relative_motion(st.u, itf.a, itf.b, Ta, Tb)
            active = _active_interfaces(prob, st)
            sigma_n, _, sig_eff = stresses(prob, st, load)
            kn, ks, cracked, new_crack = springs.update(
                st.kn, st.ks, st.cracked, itf.ks, st.rel[:, 1], sigma_n, sig_eff,
                itf.c_p, itf.tan_p, itf.c_r, itf.tan_r, itf.del_res, itf.tensile, itf.cutoff & active)
            scale = np.where(itf.ks > 0, itf.ks, 1.0)
            change = float(np.max(np.abs(ks - st.ks)[active] / scale[active], initial=0.0))
            new_crack = new_crack & active
            st.kn, st.ks, st.cracked = kn, ks, cracked
            if progress is not None:
                progress(step, cfg.n_steps, it)
            if change < cfg.tol and not new_crack.any() and removed_now == 0:
                converged = True
                break
        if step == cfg.n_steps:
            # the last update changed the springs a little: re-solve so that the reported
            # displacements and stresses belong to the final springs
            _solve_with_removal(prob, st, Ta, Tb, f_total, step, cache)
            st.rel = relative_motion(st.u, itf.a, itf.b, Ta, Tb)
        active = _active_interfaces(prob, st)
        yielded = active & (st.ks < itf.ks * (1 - 1e-9))
        disp = np.hypot(st.u[:, 0], st.u[:, 1])
        st.steps.append(StepRecord(step=step, load=load, iterations=it, converged=converged,
                                   n_yielded=int(yielded.sum()), n_cracked=int((st.cracked & active).sum()),
                                   n_unstable=int(st.removed.sum()),
                                   max_displacement=float(disp[~st.removed].max(initial=0.0)),
                                   max_change=change))
    return st
