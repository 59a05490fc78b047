"""Strength reduction: the factor F by which c' and tan(phi') can be divided before the
static DEM solution fails (beyond the thesis; the finite-element form is Griffiths &
Lane 1999, after Zienkiewicz et al. 1975).

A trial divides the peak and residual cohesion and tan(phi) of every interface by F
(the tensile strength and the springs stay as they are) and runs the full load
history.  It *holds* when every load step converges and no block becomes unstable;
it *fails* otherwise (a secant iteration that does not settle within max_iterations,
or a mechanism found by the pivot test).  F is searched on a grid of `step` (0.005):
a bracket is grown from a first guess (Bishop's FS when known, else 1), then bisected, so that the result F_s is the smallest
grid value that fails while F_s - step holds.  Both trials are reported.
"""
from __future__ import annotations

import copy
import math

import numpy as np

from . import solve
from .model import Problem

STEP = 0.005          # resolution of the reduction factor
F_MIN, F_MAX = 0.05, 50.0


def reduced(prob: Problem, factor: float) -> Problem:
    """A copy of `prob` with c and tan(phi) (peak and residual) divided by `factor`."""
    out = copy.copy(prob)
    itf = copy.copy(prob.interfaces)
    itf.c_p, itf.c_r = prob.interfaces.c_p / factor, prob.interfaces.c_r / factor
    itf.tan_p, itf.tan_r = prob.interfaces.tan_p / factor, prob.interfaces.tan_r / factor
    out.interfaces = itf
    return out


def holds(prob: Problem, factor: float) -> bool:
    """True when the static solution at strengths / factor converges in every step, nothing removed."""
    st = solve.run(reduced(prob, factor), stop_on_failure=True)
    return len(st.steps) == prob.settings.n_steps and all(r.converged for r in st.steps) \
        and not st.removed.any()


def search(prob: Problem, step: float = STEP, guess: float = 1.0, progress=None) -> dict:
    """The strength-reduction factor of safety (see the module doc).

    `guess` (e.g. Bishop's FS) is where the bracket starts; it grows by doubling steps.
    Returns dict(fs, holds_at, fails_at, trials=[(F, held), ...]); fs is None (with a
    reason) when no failure is found up to F_MAX or the slope fails already at F_MIN.
    """
    trials: list[tuple[float, bool]] = []
    cache: dict[int, bool] = {}

    def test(k: int) -> bool:
        if k not in cache:
            f = k * step
            cache[k] = holds(prob, f)
            trials.append((round(f, 10), cache[k]))
            if progress is not None:
                progress(f, cache[k])
        return cache[k]

    k_min, k_max = math.ceil(F_MIN / step), int(F_MAX / step)
    k = min(max(round(guess / step) if np.isfinite(guess) else round(1.0 / step), k_min), k_max)
    size = max(1, round(0.02 / step))
    if test(k):                      # grow upwards until a trial fails
        lo, hi = k, None
        while hi is None:
            if lo == k_max:
                return dict(fs=None, reason=f"the slope still holds at F = {F_MAX:g}", trials=trials)
            nxt = min(lo + size, k_max)
            if test(nxt):
                lo, size = nxt, 2 * size
            else:
                hi = nxt
    else:                            # shrink until a trial holds
        hi, lo = k, None
        while lo is None:
            if hi == k_min:
                return dict(fs=None, reason=f"the slope fails even at F = {F_MIN:g}", trials=trials)
            nxt = max(hi - size, k_min)
            if test(nxt):
                lo = nxt
            else:
                hi, size = nxt, 2 * size
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if test(mid):
            lo = mid
        else:
            hi = mid
    return dict(fs=round(hi * step, 10), holds_at=round(lo * step, 10), fails_at=round(hi * step, 10),
                step=step, trials=trials,
                definition="smallest F (grid of step) at which the static DEM with c'/F and tan(phi')/F "
                           "does not converge or finds unstable blocks; it holds at F - step")
