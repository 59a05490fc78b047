"""Factor of safety by strength reduction (`model factor-of-safety`).

Method (Itasca, FLAC3D/3DEC manual, "Strength Reduction Procedure in FLAC3D and 3DEC" and
"Computational Methods for Factor of Safety Calculation of Slopes", docs.itascacg.com; the
bracketing of Dawson, Roth & Drescher 1999, Géotechnique 49(6)): every trial factor F divides the
joint strengths, c/F, tan φ/F (and the tensile strength T/F; each joint model's host says how, its
``reduce`` in ``dec3d.physics.jmodels``); each trial is solved from the same
initial state and is *stable* when it reaches equilibrium, *unstable* otherwise; the bracket
[stable F, unstable F] is halved until it is narrower than the resolution.

Zones are reduced together with the joints, as FLAC3D and 3DEC do (same page: the method "is applied
automatically" to the Mohr-Coulomb, ubiquitous-joint and Hoek-Brown zone strengths, and to the joint
cohesion and friction of `block contact property`): every zone whose constitutive model declares a
``reduce`` in the registry (``dec3d.physics.cmodels``; e.g. `mohr-coulomb`: c/F, tan φ/F, σt/F) gets
its property row from that ``reduce`` for the trial, and the strength-reduction column ``P_SRF`` set
to F (the factor a kernel applies to strengths it reads from tables).

This module holds the bracketing logic (``bracket_fos``, independent of the engine: a trial is any
callable F -> bool) and the trial on a model (``StrengthTrials``): reduce the contacts' and
the zones' strengths, cycle, judge, put the model back exactly.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field

import numpy as np

from dec3d.kernels.zmodels._common import P_SRF
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


def reducible_zones(model) -> np.ndarray:
    """Rows of the ``zones`` store whose constitutive model declares a strength ``reduce`` in the
    registry (``dec3d.physics.cmodels.MODEL_BY_CODE``); empty without zones."""
    from dec3d.model.zones import has_zones
    from dec3d.physics.cmodels import MODEL_BY_CODE

    if not has_zones(model):
        return np.zeros(0, dtype=np.int64)
    codes = model.store("zones")["cmodel"]
    ok = np.zeros(len(codes), dtype=bool)
    for code in np.unique(codes):
        m = MODEL_BY_CODE.get(int(code))
        if m is not None and m.reduce is not None:
            ok |= codes == code
    return np.flatnonzero(ok)


def reduce_zone_rows(prop: np.ndarray, cmodel: np.ndarray, factor: float) -> np.ndarray:
    """The property rows ``prop`` (k, ncols) of zones of models ``cmodel`` (k,) with their strengths
    divided by ``factor``: each model's own ``reduce(rows, F)`` (a new array; ``prop`` is not
    changed), then the strength-reduction column ``P_SRF`` = F where the rows have it (the factor
    a kernel divides the strengths it reads from tables by). Rows of a model without ``reduce``
    are returned as they are."""
    from dec3d.physics.cmodels import MODEL_BY_CODE

    out = np.array(prop, dtype=np.float64, copy=True)
    for code in np.unique(cmodel):
        m = MODEL_BY_CODE.get(int(code))
        if m is None or m.reduce is None:
            continue
        sel = np.flatnonzero(cmodel == code)
        rows = np.asarray(m.reduce(out[sel].copy(), float(factor)), dtype=np.float64)
        if rows.shape != (len(sel), out.shape[1]):
            raise FosError(f"zone model '{m.name}': its strength reduction gave rows of shape {rows.shape}, "
                           f"expected {(len(sel), out.shape[1])}")
        if out.shape[1] > P_SRF:
            rows[:, P_SRF] = float(factor)
        out[sel] = rows
    return out


def _store_snapshot(store) -> dict:
    return {k: store[k].copy() for k in store.fields}


def _store_restore(store, snap: dict) -> None:
    for k, a in snap.items():
        store.full(k)[: len(a)] = a


class StrengthTrials:
    """Trials of the model of ``engine`` with the strengths of the `mohr` contacts selected by
    ``mask`` (a bool array over the contacts; None: all, and the material-table defaults too, so
    contacts made during a trial are reduced as well) and of every zone whose model declares a
    ``reduce`` (``reducible_zones``) divided by the trial factor.

    ``__call__(F)`` puts the model back to the state it had when this object was made, divides
    the strengths by F, cycles until the equilibrium ratio (the mechanical ratio of `model
    solve`) is at most ``ratio`` (stable) or ``steps`` steps are done (unstable), and returns
    whether it was stable. ``finish()`` puts the model back (bit-identical arrays) and gives the
    engine its step hooks (histories, periodic VTK) again; they are not run during trials.
    ``on_unstable(F)`` is called with the model in the state at the end of the first unstable trial.

    The model is put back with the engine's own snapshot (the one a failed ``cycle`` is put back
    with: blocks, vertex motion, contacts, settings, time) and, because a trial may change any zone
    or gridpoint field (stress, Gauss-point stress, plastic state, history, the reduced properties;
    positions, velocities, displacements, reference positions), a copy of *every* field of the
    ``zones`` and ``vertices`` stores.
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
        m = engine.model
        c = engine.contacts
        from dec3d.physics.jmodels import MODEL_BY_CODE

        # the contacts whose joint model says how its strengths are reduced (its host's ``reduce``)
        self.jmodels = {code: m for code, m in MODEL_BY_CODE.items() if m.reduce is not None}
        sel = np.isin(c["jmodel"], np.array(sorted(self.jmodels), dtype=np.int64))
        if mask is not None:
            sel &= np.asarray(mask, dtype=bool)
        self.rows = np.flatnonzero(sel)
        self.all_contacts = mask is None
        #: rows of the zones whose strengths are reduced
        self.zone_rows = reducible_zones(m)
        self.snap = engine._snapshot()
        self.zsnap = _store_snapshot(m.store("zones")) if "zones" in m.stores else None
        self.vsnap = _store_snapshot(m.vertices)
        self.hooks = engine.step_hooks
        engine.step_hooks = []

    @property
    def empty(self) -> bool:
        """Nothing to reduce: no contact with a reducible joint model selected and no zone with a
        reducible model."""
        return self.rows.size == 0 and self.zone_rows.size == 0

    def _reset(self) -> None:
        # the engine's own snapshot (the one a failed `model cycle` is put back with); its settings
        # part is copied again so that a trial that changes them in place cannot reach the snapshot
        snap = dict(self.snap)
        snap["mech"] = copy.deepcopy(self.snap["mech"])
        self.e._restore(snap)
        m = self.e.model
        if self.zsnap is not None:
            _store_restore(m.store("zones"), self.zsnap)
        _store_restore(m.vertices, self.vsnap)

    def __call__(self, factor: float) -> bool:
        e = self.e
        self._reset()
        c = e.contacts
        if self.rows.size:
            codes = c["jmodel"][self.rows]
            for code in np.unique(codes):
                rows = self.rows[codes == code]
                block = c["prop"][rows]
                self.jmodels[int(code)].reduce(block, factor, self.associated)
                c["prop"][rows] = block
            c["own_props"][self.rows] = 1          # kept through re-detection during the trial
        if self.all_contacts:
            s = e.settings()
            s["props"] = reduce_defaults(s["props"], factor, self.associated)
        if self.zone_rows.size:
            zs = e.model.store("zones")
            r = self.zone_rows
            zs["prop"][r] = reduce_zone_rows(zs["prop"][r], zs["cmodel"][r], factor)
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


#: the name of the joints-only days (kept for callers)
ContactStrengthTrials = StrengthTrials


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
    t = StrengthTrials(e, mask, associated=associated, steps=steps, ratio=ratio)
    ok = t(factor)
    _, _, done, r = t.log[-1]
    return ok, done, r


class FileTrials:
    """The trials of one round run on copies of the model read from a state file written once
    (``dec3d.io.state.save_state``), by ``workers`` processes (1: in this process, one after the
    other). Every trial, whichever process runs it, starts from the same file, so the answers do
    not depend on the number of workers. ``log`` gets (F, stable, steps, ratio) like
    ``StrengthTrials.log``."""

    def __init__(self, path: str, trials: StrengthTrials, workers: int = 1):
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
