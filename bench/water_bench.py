"""Joint-flow speed (issue 29): explicit flow steps on 1e5 pipes (channel-updates per second, one thread)
and the steady direct solve of a 1e4-knot network (a 100 × 100 grid of channels). Prints figures; no
assertions (tests/rigid/test_jointflow.py checks the numbers).

    NUMBA_NUM_THREADS=1 python bench/water_bench.py
"""
from __future__ import annotations

import time

import numpy as np

from dec3d.kernels.jointflow import flow_steps, stable_dt
from dec3d.physics.jointflow import conductance, steady


def grid(n):
    """An n × n grid of knots joined by channels of random aperture: (nk, pa, pb, c, vol, fixed, p)."""
    rng = np.random.default_rng(1)
    idx = np.arange(n * n).reshape(n, n)
    pa = np.concatenate((idx[:, :-1].ravel(), idx[:-1, :].ravel()))
    pb = np.concatenate((idx[:, 1:].ravel(), idx[1:, :].ravel()))
    c = conductance(rng.uniform(5e-5, 3e-4, len(pa)), 1.0, 1.0, 1e-3)
    vol = np.full(n * n, 1e-4)
    fixed = np.zeros(n * n, bool)
    fixed[idx[:, 0]] = True
    fixed[idx[:, -1]] = True
    p = np.where(np.arange(n * n) % n == 0, 1e5, 0.0)
    return n * n, pa, pb, c, vol, fixed, p


def main():
    nk, pa, pb, c, vol, fixed, p = grid(224)          # 2 × 224 × 223 = 99 904 pipes
    flow = np.zeros(len(pa))
    q_in = np.zeros(nk)
    dt = stable_dt(pa, pb, c, vol, 2e9, fixed)
    flow_steps(2, dt, pa, pb, c, vol, 2e9, fixed, q_in, p, flow)          # compile
    steps = 200
    t0 = time.perf_counter()
    flow_steps(steps, dt, pa, pb, c, vol, 2e9, fixed, q_in, p, flow)
    s = time.perf_counter() - t0
    print(f"explicit flow: {len(pa)} pipes, {steps} steps in {s:.3f} s: {len(pa) * steps / s:.3g} channel-updates/s")
    nk, pa, pb, c, vol, fixed, p = grid(100)
    t0 = time.perf_counter()
    steady(nk, pa, pb, c, fixed, p)
    print(f"steady solve: {nk} knots, {len(pa)} pipes in {time.perf_counter() - t0:.3f} s")


if __name__ == "__main__":
    main()
