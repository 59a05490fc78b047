"""Strength reduction: the factor F by which c' and tan(phi') can be divided before the
static DEM solution fails (beyond the thesis; the finite-element form is Griffiths &
Lane 1999, after Zienkiewicz et al. 1975).

A trial divides the peak and residual cohesion and tan(phi) of every interface by F
(the tensile strength and the springs stay as they are) and runs the full load
history.  It *holds* when every load step converges and no block becomes unstable;
it *fails* otherwise (a secant iteration that does not settle within max_iterations,
or a mechanism found by the pivot test).  F is searched on a grid of `step` (0.005):
a bracket is grown from a first guess (Bishop's FS when known, else 1), then bisected, so that the result F_s is the smallest
grid value that fails while F_s - step holds.  Both trials are reported, with what the
failing one rests on (unstable blocks: a mechanism, a proof; or no convergence within
max_iterations: none).

The same search brackets the limit of a slope that does not hold at full strength;
limit_state() evaluates the DEM factor of safety (Eq. 2.6) there (analysis.run_problem).
"""
from __future__ import annotations

import copy
import math

import numpy as np

from . import safety, solve
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


def verdict(prob: Problem, st: solve.State) -> str:
    """Why a run does not hold, or "" when it holds (every step converged, nothing removed).

    "unstable blocks at step k" is a proof of failure (a mechanism: the pivot tests);
    "no convergence within N iterations at step k" is not: the step may settle later.
    """
    for r in st.steps:
        if r.n_unstable:
            return f"unstable blocks at step {r.step}"
        if not r.converged:
            return f"no convergence within {prob.settings.max_iter} iterations at step {r.step}"
    if len(st.steps) < prob.settings.n_steps:
        return f"stopped at step {len(st.steps)}"
    return ""


def trial(prob: Problem, factor: float) -> str:
    """verdict() of the static solution at strengths / factor (stops at the first failing step)."""
    return verdict(prob, solve.run(reduced(prob, factor), stop_on_failure=True))


def holds(prob: Problem, factor: float) -> bool:
    """True when the static solution at strengths / factor converges in every step, nothing removed."""
    return trial(prob, factor) == ""


def search(prob: Problem, step: float = STEP, guess: float = 1.0, progress=None) -> dict:
    """The strength-reduction factor of safety (see the module doc).

    `guess` (e.g. Bishop's FS) is where the bracket starts; it grows by doubling steps.
    Returns dict(fs, holds_at, fails_at, trials=[(F, held), ...]); fs is None (with a
    reason) when no failure is found up to F_MAX or the slope fails already at F_MIN.
    """
    trials: list[tuple[float, bool]] = []
    cache: dict[int, bool] = {}
    why: dict[int, str] = {}

    def test(k: int) -> bool:
        if k not in cache:
            f = k * step
            why[k] = trial(prob, f)
            cache[k] = why[k] == ""
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
                fails_because=why[hi], failure_proven=why[hi].startswith("unstable"), step=step, trials=trials,
                definition="smallest F (grid of step) at which the static DEM with c'/F and tan(phi')/F "
                           "does not converge or finds unstable blocks; it holds at F - step")


def limit_state(prob: Problem, search_result: dict) -> dict | None:
    """The DEM factor of safety of a slope that does not hold at full strength.

    At full strength the secant iteration has no equilibrium to settle on (or finds a
    mechanism), so Eq. 2.6 has no converged state to be evaluated on.  It is evaluated
    instead on the converged state nearest to failure: the run with c' and tan(phi')
    divided by F_hold, the largest factor on the search grid that holds; the stresses are
    that run's, the strengths the full ones, so FS = sum(tau_f L) / sum(tau_mob L) >= F_hold
    (1 - tol) (every spring is within its reduced strength, tau_mob <= tau_f / F_hold, to the
    iteration's tolerance tol).
    Returns None when no factor holds.
    """
    f = search_result.get("holds_at")
    if f is None:
        return None
    st = solve.run(reduced(prob, f))
    saf = safety.evaluate(prob, st)
    return dict(factor=f, fails_at=search_result["fails_at"], fails_because=search_result["fails_because"],
                failure_proven=search_result["failure_proven"], fs_dem=saf.fs_global, fs_dem_mean=saf.fs_mean,
                n_averaged=saf.n_averaged, iterations=[r.iterations for r in st.steps],
                definition="Eq. 2.6 with the full strengths on the converged state of the run with c' and "
                           "tan(phi') divided by the largest factor that holds (factor)")
