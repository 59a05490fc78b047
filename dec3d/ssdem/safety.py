"""Factors of safety, yield and the failure surface from a solved state.

Per interface (thesis Sec. 4.1.5, ERRATA): FS = tau_available / tau_mobilised with
    tau_mobilised = |k_s delta_s|                 (the secant spring's stress)
    tau_available = strength at the current slip  (tau_p before the peak, then the
                    interpolated / residual strength of springs.strength_at)
Yield (thesis Sec. 4.2.1, after Rodriguez-Marek 1996) = 100 (1 - k_s / k_s0) %;
a cracked interface is at 100 %.

Failure surface: the interfaces of a prescribed surface when the input gives one;
otherwise every interface that has passed its peak or cracked, plus the edges
between removed (unstable) blocks and the rest (the displacement discontinuity).

Global FS, two averages over the failure-surface interfaces, both reported:
  * `fs` (primary) = sum(tau_available L) / sum(tau_mobilised L): the average of the
    interface FS weighted by the shear force each mobilises, i.e. Eq. (2.6) of the
    thesis (Rodriguez-Marek 1996).  Independent of how finely the surface is cut.
  * `fs_mean` = arithmetic mean of the interface FS, as in the thesis's Appendix C.
Cracked and removed interfaces carry no stress and add nothing to either.  Shear
that acts against the overall sense of sliding counts negative in the weighted sum.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import springs
from .model import Problem
from .solve import State, contact_length, stresses

ELASTIC, YIELDED, CRACKED, REMOVED = 0, 1, 2, 3
STATE_NAMES = {ELASTIC: "elastic", YIELDED: "yielded", CRACKED: "cracked", REMOVED: "removed"}


@dataclass
class Safety:
    sigma_n: np.ndarray
    tau: np.ndarray
    sig_eff: np.ndarray
    tau_avail: np.ndarray
    tau_mob: np.ndarray
    fs: np.ndarray          # inf where nothing is mobilised, nan where removed
    yield_pct: np.ndarray
    state: np.ndarray
    failure: np.ndarray     # (m,) bool: on the failure surface
    fs_global: float        # shear-force weighted (Eq. 2.6), nan if no surface
    fs_mean: float          # arithmetic mean (Appendix C), nan if no surface
    n_averaged: int
    surface_kind: str       # "prescribed", "yield", or "none"
    slide_sign: np.ndarray  # (m,) +1 where the shear resists the overall sliding


def evaluate(prob: Problem, st: State) -> Safety:
    itf = prob.interfaces
    active = ~(st.removed[itf.a] | st.removed[itf.b])
    sigma_n, tau, sig_eff = stresses(prob, st, st.load)
    tau_p, tau_r = springs.strengths(sig_eff, itf.c_p, itf.tan_p, itf.c_r, itf.tan_r)
    tau_av, _ = springs.strength_at(st.rel[:, 1], tau_p, tau_r, itf.ks, itf.del_res)
    tau_av = np.where(st.cracked, 0.0, tau_av)
    lc = contact_length(prob, st)          # the length in contact (no-tension interfaces may open)
    tau_mob = np.where(lc > 0, np.abs(tau), 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        fs = np.where(tau_mob > 0, tau_av / tau_mob, np.inf)
        yield_pct = np.where(itf.ks > 0, 100.0 * (1.0 - st.ks / itf.ks), 0.0)
    yield_pct = np.where(st.cracked, 100.0, np.clip(yield_pct, 0.0, 100.0))
    state = np.full(itf.m, ELASTIC)
    state[yield_pct > 1e-7] = YIELDED
    state[st.cracked] = CRACKED
    state[~active] = REMOVED
    fs[~active] = np.nan
    fs[st.cracked & active] = np.nan

    if itf.on_surface is not None and itf.on_surface.any():
        failure, kind = itf.on_surface.copy(), "prescribed"
    else:
        edge = st.removed[itf.a] ^ st.removed[itf.b]
        failure = (((state == YIELDED) | (state == CRACKED)) & active) | edge
        kind = "yield" if failure.any() else "none"

    # sense of sliding: slip of the upper block relative to the lower one, horizontal part
    up = np.where(itf.normal[:, 1] >= 0, 1.0, -1.0)           # +1 when b is above a
    tvec = np.column_stack([-itf.normal[:, 1], itf.normal[:, 0]])
    slip_x = up * st.rel[:, 1] * tvec[:, 0]
    use = failure & active & ~st.cracked
    dominant = np.sign(np.sum((tau_mob * lc * np.sign(slip_x))[use])) or 1.0
    slide_sign = np.where(np.sign(slip_x) * dominant < 0, -1.0, 1.0)

    if use.any():
        num = np.sum((tau_av * lc)[use])
        den = np.sum((slide_sign * tau_mob * lc)[use])
        fs_global = float(num / den) if den > 0 else float("inf")
        finite = use & np.isfinite(fs)
        fs_mean = float(np.mean(fs[finite])) if finite.any() else float("nan")
    else:
        fs_global = fs_mean = float("nan")
    return Safety(sigma_n=sigma_n, tau=tau, sig_eff=sig_eff, tau_avail=tau_av, tau_mob=tau_mob,
                  fs=fs, yield_pct=yield_pct, state=state, failure=failure, fs_global=fs_global,
                  fs_mean=fs_mean, n_averaged=int(use.sum()), surface_kind=kind, slide_sign=slide_sign)
