"""Cost of one sub-contact update of each joint model's law, against `mohr` (issue 27: each new law
≤ 1.5× mohr's cost per update).

Every model found in dec3d/kernels/joints runs the same loading path on N sub-contacts (each its own
contact row): a closure, then shearing back and forth at a normal displacement that also cycles, so
that every law passes through its elastic, yielding (slip, softening, damage) and opening branches.
The loop is a numba kernel calling the dispatch chain (``joints.joint_law``) the cycle compiles in,
so a law's cost here is its cost in the cycle, minus the kinematics around it. Timed: the median of
``--repeat`` runs of ``--steps`` updates of all N sub-contacts, after one warm-up run (compile).

Property rows: each model's defaults (``JointModel.row``), columns 0, 1 (the stiffnesses) 1e10, and for a required
property a representative value by its units (degrees 30, Pa 1e6, m 1e-3, others 1).

    python bench/joint_law_bench.py [--n 20000] [--steps 200] [--repeat 5]
"""
from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np
from numba import njit

from dec3d.kernels.joints import NJHIST, NPROP, joint_law
from dec3d.physics.jmodels import JOINT_MODELS

_TYPICAL = {"deg": 30.0, "Pa": 1e6, "m": 1e-3}


def rows_for(name: str, n: int) -> np.ndarray:
    m = JOINT_MODELS[name]
    # columns 0, 1 are every model's stiffnesses (whatever its keywords for them: cyjm's kn-initial)
    vals = {p.name: 1e10 for p in m.props.values() if p.column in (0, 1)}
    for p in m.props.values():
        if p.required and p.name not in vals:
            v = _TYPICAL.get(p.units, 1.0)
            if p.hi is not None and v >= p.hi:
                v = 0.5 * (p.hi + (p.lo or 0.0))
            vals[p.name] = v
    return np.tile(m.row(vals), (n, 1))


@njit   # (not cached: its cache would not know when a joint model's file changes)
def _run(model, p, h, steps, area, un, udil, fs, us, state, fn_out):
    n = p.shape[0]
    for k in range(steps):
        # normal: close 2e-5 m over the first tenth, then cycle ±5e-6 m; shear: ±2e-4 m cycles
        ph = 2.0 * math.pi * k / 50.0
        dun = -2e-5 / (steps // 10 + 1) if k < steps // 10 else 5e-6 * (math.sin(ph + 0.13) - math.sin(ph - 0.0))
        dus = 2e-4 * (math.sin(ph + 0.13) - math.sin(ph))
        for s in range(n):
            jit = 1.0 + 1e-3 * (s % 7)
            fn, f0, f1, f2, u, ud, u0, u1, u2, st = joint_law(
                model, p, s, h, s, area, dun * jit, dus * jit, 0.3 * dus, 0.0, un[s], udil[s], fs[s, 0], fs[s, 1],
                fs[s, 2], us[s, 0], us[s, 1], us[s, 2], state[s])
            un[s] = u
            udil[s] = ud
            fs[s, 0] = f0
            fs[s, 1] = f1
            fs[s, 2] = f2
            us[s, 0] = u0
            us[s, 1] = u1
            us[s, 2] = u2
            state[s] = st
            fn_out[s] = fn


def one(name: str, n: int, steps: int) -> float:
    """Seconds per sub-contact update of model ``name``."""
    code = JOINT_MODELS[name].code
    p = rows_for(name, n)
    h = np.zeros((n, NJHIST))
    un, udil, fn = np.zeros(n), np.zeros(n), np.zeros(n)
    fs, us = np.zeros((n, 3)), np.zeros((n, 3))
    state = np.zeros(n, np.int64)
    t0 = time.perf_counter()
    _run(code, p, h, steps, 0.01, un, udil, fs, us, state, fn)
    dt = time.perf_counter() - t0
    if not (np.isfinite(fn).all() and np.isfinite(h).all()):
        raise SystemExit(f"{name}: a non-finite force or history")
    return dt / (n * steps)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20000, help="sub-contacts")
    ap.add_argument("--steps", type=int, default=200, help="updates of every sub-contact per run")
    ap.add_argument("--repeat", type=int, default=5, help="timed runs (median printed)")
    a = ap.parse_args(argv)
    assert NPROP >= 2
    names = sorted(JOINT_MODELS, key=lambda k: JOINT_MODELS[k].code)
    for name in names:                      # warm-up: compiles the chain once for every code
        one(name, 16, 4)
    res = {}
    for name in names:
        res[name] = statistics.median(one(name, a.n, a.steps) for _ in range(a.repeat))
    base = res.get("mohr")
    print(f"{'model':24s} {'ns/update':>10s} {'× mohr':>8s}")
    for name in names:
        ratio = res[name] / base if base else float("nan")
        print(f"{name:24s} {res[name] * 1e9:10.2f} {ratio:8.2f}")


if __name__ == "__main__":
    main()
