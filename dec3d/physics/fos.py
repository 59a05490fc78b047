"""Factor of safety by strength reduction (`model factor-of-safety`).

Method (Itasca, FLAC3D/3DEC manual, "Strength Reduction Procedure in FLAC3D and 3DEC" and
"Computational Methods for Factor of Safety Calculation of Slopes", docs.itascacg.com; the
bracketing of Dawson, Roth & Drescher 1999, Géotechnique 49(6)): every trial factor F divides the
joint strengths, c/F, tan φ/F (and the tensile strength T/F); each trial is solved from the same
initial state and is *stable* when it reaches equilibrium, *unstable* otherwise; the bracket
[stable F, unstable F] is halved until it is narrower than the resolution.

This module holds the bracketing logic (``bracket_fos``, independent of the engine: a trial is any
callable F -> bool) and the rigid-block trial (``ContactStrengthTrials``): reduce the `mohr`
contacts' strengths, cycle, judge, put the model back exactly.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field

import numpy as np

from dec3d.kernels.joints.mohr import CODE as MODEL_MOHR
from dec3d.kernels.joints.mohr import P_COH, P_COH_RES, P_TANDIL, P_TANF, P_TANF_RES, P_TEN, P_TEN_RES

#: equilibrium ratio of a stable trial (Itasca's equilibrium ratio, "Reaching Equilibrium": 1e-5)
STABLE_RATIO = 1e-5
#: the bracket is narrowed until it is at most this wide when no `resolution` is given
DEFAULT_RESOLUTION = 0.005
#: steps a trial may take to reach the stable ratio before it is judged unstable (dec3d's default)
DEFAULT_TRIAL_STEPS = 10000
#: automatic bracketing (no `bracket`): F is doubled (or halved) from 1 at most this many times
MAX_DOUBLINGS = 10


class FosError(Exception):
    """A factor-of-safety search that cannot give a value (the command turns it into a CommandError)."""


@dataclass
class FosResult:
    fs: float                 # the largest F found stable (the stable end of the final bracket)
    stable: float             # = fs
    unstable: float           # the smallest F found unstable
    trials: list = field(default_factory=list)   # (F, stable?) in the order they were run


def bracket_fos(trial, lo: float | None = None, hi: float | None = None,
                resolution: float = DEFAULT_RESOLUTION, points: int = 1, run_many=None) -> FosResult:
    """Find the factor of safety with ``trial(F) -> bool`` (True: stable at strengths / F).

    With ``lo``/``hi`` (the `bracket`), ``lo`` must be stable and ``hi`` unstable, else
    ``FosError`` says on which side the factor of safety lies. Without them F = 1 is tried and
    doubled (stable) or halved (unstable) until the other state is met (at most MAX_DOUBLINGS
    times). Then, while the bracket [s, u] is wider than ``resolution``, each round tries the
    ``points`` factors s + (u − s) i / (points + 1), i = 1..points (1: bisection) and keeps the
    lowest unstable one and the highest stable one below it. ``run_many(list of F) -> list of
    bool`` runs the factors of one round (in parallel, say; default: ``trial`` on each in turn):
    the factors tried depend only on ``points`` and the answers, never on how a round is run.
    """
    if resolution is None or not resolution > 0.0:
        raise FosError(f"the resolution must be > 0 (got {resolution!r})")
    if int(points) < 1:
        raise FosError(f"the trials per round must be at least 1 (got {points!r})")
    points = int(points)
    runs: list[tuple[float, bool]] = []
    many = run_many if run_many is not None else (lambda fs: [bool(trial(f)) for f in fs])

    def run_round(fs: list[float]) -> list[bool]:
        oks = [bool(x) for x in many(list(fs))]
        runs.extend(zip(fs, oks))
        return oks

    def run(f: float) -> bool:
        return run_round([f])[0]

    if lo is not None or hi is not None:
        if lo is None or hi is None or not (0.0 < lo < hi):
            raise FosError(f"the bracket must be two factors 0 < lo < hi (got {lo!r} {hi!r})")
        if points > 1:
            ok_lo, ok_hi = run_round([lo, hi])
        else:
            ok_lo = run(lo)
            ok_hi = run(hi) if ok_lo else False
        if not ok_lo:
            raise FosError(f"the model is unstable at the lower bracket F = {lo:g}: the factor of safety is "
                           f"below the bracket")
        if ok_hi:
            raise FosError(f"the model is stable at the upper bracket F = {hi:g}: the factor of safety is "
                           f"above the bracket")
        s, u = lo, hi
    else:
        f = 1.0
        if run(f):
            s = f
            for _ in range(MAX_DOUBLINGS):
                f *= 2.0
                if not run(f):
                    break
                s = f
            else:
                raise FosError(f"the model is still stable at F = {f:g}: the factor of safety is above it")
            u = f
        else:
            u = f
            for _ in range(MAX_DOUBLINGS):
                f *= 0.5
                if run(f):
                    break
                u = f
            else:
                raise FosError(f"the model is still unstable at F = {f:g}: the factor of safety is below it")
            s = f
    while u - s > resolution:
        fs = [s + (u - s) * i / (points + 1) for i in range(1, points + 1)]
        oks = run_round(fs)
        first_bad = next((i for i, ok in enumerate(oks) if not ok), None)
        if first_bad is not None:
            u = fs[first_bad]
            oks, fs = oks[:first_bad], fs[:first_bad]
        s = max([s] + [f for f, ok in zip(fs, oks) if ok])
    return FosResult(fs=s, stable=s, unstable=u, trials=runs)


def reduce_rows(prop: np.ndarray, factor: float, associated: bool) -> None:
    """Divide the strengths of `mohr` property rows (k, NPROP) in place by ``factor``: cohesion,
    tension and tan φ (peak and residual; a NaN residual friction keeps following the peak).
    Dilation: with ``associated`` tan ψ = the reduced tan φ; otherwise tan ψ is kept but never
    above the reduced tan φ ("the dilation is not allowed to become greater than the friction",
    `model factor-of-safety` command page)."""
    for col in (P_TANF, P_COH, P_TEN, P_TANF_RES, P_COH_RES, P_TEN_RES):
        prop[:, col] = prop[:, col] / factor
    if associated:
        prop[:, P_TANDIL] = prop[:, P_TANF]
    else:
        prop[:, P_TANDIL] = np.minimum(prop[:, P_TANDIL], prop[:, P_TANF])


def reduce_defaults(props: dict, factor: float, associated: bool) -> dict:
    """The material-table defaults (user units: degrees, Pa) with their strengths divided by ``factor``."""
    out = dict(props)

    def angle(v):
        return math.degrees(math.atan(math.tan(math.radians(float(v))) / factor))

    for k in ("friction", "friction-residual"):
        if k in out:
            out[k] = angle(out[k])
    for k in ("cohesion", "tension", "cohesion-residual", "tension-residual"):
        if k in out:
            out[k] = float(out[k]) / factor
    fr = out.get("friction", 0.0)
    if associated:
        out["dilation"] = fr
    elif "dilation" in out:
        out["dilation"] = min(float(out["dilation"]), fr)
    return out


class ContactStrengthTrials:
    """Trials of the rigid-block model ``engine`` with the `mohr` contacts selected by ``mask``
    (a bool array over the contacts; None: all, and the material-table defaults too, so contacts
    made during a trial are reduced as well).

    ``__call__(F)`` puts the model back to the state it had when this object was made, divides
    the strengths by F, cycles until the equilibrium ratio (the mechanical ratio of `model
    solve`) is at most ``ratio`` (stable) or ``steps`` steps are done (unstable), and returns
    whether it was stable. ``finish()`` puts the model back (bit-identical arrays) and gives the
    engine its step hooks (histories, periodic VTK) again; they are not run during trials.
    ``on_unstable(F)`` is called with the model in the state at the end of the first unstable trial.
    """

    def __init__(self, engine, mask=None, associated: bool = False, steps: int = DEFAULT_TRIAL_STEPS,
                 ratio: float = STABLE_RATIO, on_unstable=None):
        self.e = engine
        self.associated = bool(associated)
        self.steps = int(steps)
        self.ratio = float(ratio)
        self.on_unstable = on_unstable
        self.failed_once = False
        self.log: list[tuple[float, bool, int, float]] = []   # (F, stable, steps, ratio)
        engine.ensure_contacts()
        c = engine.contacts
        sel = c["jmodel"] == MODEL_MOHR
        if mask is not None:
            sel &= np.asarray(mask, dtype=bool)
        self.rows = np.flatnonzero(sel)
        self.all_contacts = mask is None
        self.snap = engine._snapshot()
        self.hooks = engine.step_hooks
        engine.step_hooks = []

    def _reset(self) -> None:
        # the engine's own snapshot (the one a failed `model cycle` is put back with); its settings
        # part is copied again so that a trial that changes them in place cannot reach the snapshot
        snap = dict(self.snap)
        snap["mech"] = copy.deepcopy(self.snap["mech"])
        self.e._restore(snap)

    def __call__(self, factor: float) -> bool:
        e = self.e
        self._reset()
        c = e.contacts
        block = c["prop"][self.rows]
        reduce_rows(block, factor, self.associated)
        c["prop"][self.rows] = block
        c["own_props"][self.rows] = 1          # kept through re-detection during the trial
        if self.all_contacts:
            s = e.settings()
            s["props"] = reduce_defaults(s["props"], factor, self.associated)
        done = e.cycle(self.steps, lambda en: en.criteria()["ratio"] <= self.ratio)
        r = e.criteria()["ratio"]
        stable = bool(r <= self.ratio)
        self.log.append((float(factor), stable, int(done), float(r)))
        if not stable and not self.failed_once:
            self.failed_once = True
            if self.on_unstable is not None:
                self.on_unstable(factor)
        return stable

    def finish(self) -> None:
        self._reset()
        self.e.step_hooks = self.hooks


def _trial_from_file(path: str, rows: np.ndarray, all_contacts: bool, associated: bool, steps: int,
                     ratio: float, factor: float) -> tuple[bool, int, float]:
    """One trial on a model read from the state file ``path`` (in this process or a worker process):
    (stable?, steps, final ratio). The same file and factor give the same numbers in any process."""
    from dec3d.io.state import restore_state
    from dec3d.physics.rigid import engine

    model, _ = restore_state(path)
    e = engine(model)
    e.ensure_contacts()
    mask = None
    if not all_contacts:
        mask = np.zeros(e.contacts.n, dtype=bool)
        mask[rows] = True
    t = ContactStrengthTrials(e, mask, associated=associated, steps=steps, ratio=ratio)
    ok = t(factor)
    _, _, done, r = t.log[-1]
    return ok, done, r


class FileTrials:
    """The trials of one round run on copies of the model read from a state file written once
    (``dec3d.io.state.save_state``), by ``workers`` processes (1: in this process, one after the
    other). Every trial, whichever process runs it, starts from the same file, so the answers do
    not depend on the number of workers. ``log`` gets (F, stable, steps, ratio) like
    ``ContactStrengthTrials.log``."""

    def __init__(self, path: str, trials: ContactStrengthTrials, workers: int = 1):
        self.path = str(path)
        self.args = (trials.rows.copy(), trials.all_contacts, trials.associated, trials.steps, trials.ratio)
        self.workers = max(1, int(workers))
        self.log: list[tuple[float, bool, int, float]] = []
        self._pool = None

    def __call__(self, fs: list[float]) -> list[bool]:
        if self.workers > 1 and len(fs) > 1:
            if self._pool is None:
                import multiprocessing
                from concurrent.futures import ProcessPoolExecutor

                from dec3d.config import set_threads

                # spawned, not forked: a process forked after GNU OpenMP ran aborts in its first
                # parallel kernel (``config.LAYER_PRIORITY``); a worker is one thread of work
                self._pool = ProcessPoolExecutor(max_workers=self.workers, initializer=set_threads, initargs=(1,),
                                                 mp_context=multiprocessing.get_context("spawn"))
            futures = [self._pool.submit(_trial_from_file, self.path, *self.args, f) for f in fs]
            out = [fu.result() for fu in futures]
        else:
            out = [_trial_from_file(self.path, *self.args, f) for f in fs]
        for f, (ok, done, r) in zip(fs, out):
            self.log.append((float(f), bool(ok), int(done), float(r)))
        return [ok for ok, _, _ in out]

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
