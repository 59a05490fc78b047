"""One SSDEM analysis end to end: read, solve, evaluate, compare with Bishop."""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import bishop, reduction, safety, solve
from .model import Problem
from .readers import read


@dataclass
class Analysis:
    problem: Problem
    state: solve.State
    safety: safety.Safety
    bishop: dict | None = None
    reduction: dict | None = None     # strength-reduction search (reduction.search), when asked for
    limit: dict | None = None         # the run does not hold at full strength: the bracket and the
                                      # FS at the limit state (reduction.limit_state), see run_problem
    timings: dict = field(default_factory=dict)


def analyse(path: str | Path, fmt: str = "auto", compare_bishop: bool = False,
            progress=None, strength_reduction: bool = False, **reader_options) -> Analysis:
    """Read `path` and run it (see `run_problem`)."""
    t0 = time.perf_counter()
    prob = read(path, fmt, **reader_options)
    out = run_problem(prob, compare_bishop, progress, strength_reduction)
    t = out.timings
    t["read"] = time.perf_counter() - t0 - t["solve"] - t["post"] - t["reduction"]
    return out


def run_problem(prob: Problem, compare_bishop: bool = False, progress=None,
                strength_reduction: bool = False, reduction_progress=None) -> Analysis:
    """Solve, evaluate the factors of safety, optionally compare with Bishop and search
    the strength-reduction factor (also when the input's [analysis] asks for it)."""
    t1 = time.perf_counter()
    st = solve.run(prob, progress=progress)
    t2 = time.perf_counter()
    saf = safety.evaluate(prob, st)
    out = Analysis(problem=prob, state=st, safety=saf)
    if compare_bishop:
        out.bishop = compare(prob, saf)
    t3 = time.perf_counter()
    fails = reduction.verdict(prob, st)
    if fails.startswith("unstable") and st.cracked.any():
        fails = ""      # blocks freed by tension cracks: the thesis's own outcome, no strength factor helps
    search = None
    if strength_reduction or prob.settings.strength_reduction or fails:
        search = reduction.search(prob, guess=_guess(prob, out.bishop), progress=reduction_progress)
    if strength_reduction or prob.settings.strength_reduction:
        out.reduction = search
    if fails:
        # no converged state at full strength for Eq. 2.6: bracket the strength factor at
        # which the slope stops holding and evaluate Eq. 2.6 at the last state that holds
        out.limit = dict(full_strength=fails, bracket=search, state=reduction.limit_state(prob, search))
    out.timings = dict(solve=t2 - t1, post=t3 - t2, reduction=time.perf_counter() - t3,
                       per_step=(t2 - t1) / max(prob.settings.n_steps, 1))
    return out


def _guess(prob: Problem, bishop_result: dict | None) -> float:
    """Where the strength-reduction bracket starts: a Bishop FS of this slope if known."""
    for res in ((bishop_result or {}).get("on_surface"), (prob.surface or {}).get("search")):
        if res and res.get("fs") is not None and np.isfinite(res["fs"]):
            return float(res["fs"])
    return 1.0


def compare(prob: Problem, saf: safety.Safety) -> dict:
    """Bishop's simplified method on the DEM failure surface and the minimum over circles.

    The failure surface: the prescribed circle itself; otherwise (polyline or yield
    surface) the least-squares circle through the failure-surface interface midpoints,
    since Bishop's moment equation needs a centre.
    """
    slope = prob.slope
    if slope is None:
        return dict(available=False,
                    reason="Appendix A files carry no ground profile or unit weight; Bishop needs the TOML input")
    res: dict = dict(available=True)
    surf = prob.surface
    if surf is not None and surf.get("type") == "circle":
        res["on_surface"] = bishop.bishop(slope, surf["centre"], surf["radius"])
        res["on_surface"]["how"] = "the prescribed circle"
    else:
        pts = prob.interfaces.mid[saf.failure]
        if len(pts) >= 3:
            centre, r = bishop.fit_circle(pts)
            res["on_surface"] = bishop.bishop(slope, centre, r)
            res["on_surface"]["how"] = f"circle fitted to {len(pts)} failure-surface interface midpoints"
        else:
            res["on_surface"] = None
    bottom = prob.bottom
    if surf is not None and surf.get("search"):
        res["search"] = dict(surf["search"])
    else:
        res["search"] = bishop.search(slope, bottom=bottom)
    res["search"]["how"] = "grid of centres and radii, then Nelder-Mead"
    return res


def summary_numbers(an: Analysis) -> dict:
    """The headline quantities (also what verify.quantities returns)."""
    s = an.safety
    lim = (an.limit or {}).get("state")
    q = dict(fs_dem=s.fs_global if lim is None else lim["fs_dem"],
             fs_dem_mean=s.fs_mean if lim is None else lim["fs_dem_mean"],
             n_surface=float(s.n_averaged if lim is None else lim["n_averaged"]),
             n_unstable=float(an.state.removed.sum()), n_yielded=float(np.sum(s.state == safety.YIELDED)),
             n_cracked=float(np.sum(s.state == safety.CRACKED)),
             converged=float(all(r.converged for r in an.state.steps)),
             max_displacement=float(an.state.steps[-1].max_displacement) if an.state.steps else 0.0)
    b = an.bishop
    if b and b.get("available"):
        if b.get("on_surface"):
            q["fs_bishop"] = b["on_surface"]["fs"]
            q["fs_ordinary"] = b["on_surface"]["fs_ordinary"]
        if b.get("search") and b["search"].get("fs") is not None:
            q["fs_bishop_min"] = b["search"]["fs"]
    if an.reduction is not None and an.reduction.get("fs") is not None:
        q["fs_reduction"] = an.reduction["fs"]
    if lim is not None:
        q["fs_dem_full_strength"] = s.fs_global          # on the state the run stopped in: not converged
        q["limit_holds_at"] = lim["factor"]
        q["limit_fails_at"] = lim["fails_at"]
    return q
