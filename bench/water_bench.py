"""Joint-flow speed (issue 29): explicit flow steps on 1e5 pipes (channel-updates per second, one thread)
and the steady direct solve of a 1e4-knot network (a 100 × 100 grid of channels); then the same on a network
built from contacts (``physics.flowgeom``: 100 square contacts of 10 m side in one plane, flow zones of
1 m → about 1e4 knots, 3e4 pipes; and of 0.55 m → 1e5 pipes): the build, the aperture/conductance
update, the explicit steps (with gravity) and the steady solve. Prints figures; no assertions
(tests/rigid/test_jointflow.py, test_flownet.py check the numbers).

    NUMBA_NUM_THREADS=1 python bench/water_bench.py
"""
from __future__ import annotations

import time

import numpy as np

from dec3d.kernels.jointflow import flow_steps, network_steps, stable_dt, zone_update
from dec3d.physics.flowgeom import build_geometry
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
    built(1.0, 200)
    built(0.55, 200)



def contacts_network(size):
    """10 × 10 square contacts of 10 m in the plane z = 0 (each with its four corners twice, as two blocks'
    vertices give them), cut into flow zones of ``size``."""
    pts = []
    for i in range(10):
        for j in range(10):
            c = np.array([[i, j, 0], [i + 1, j, 0], [i + 1, j + 1, 0], [i, j + 1, 0]], float) * 10.0
            pts.append(np.concatenate([c, c[::-1]]))
    pos = np.concatenate(pts)
    counts = np.full(100, 8)
    starts = np.arange(100) * 8
    t0 = time.perf_counter()
    g = build_geometry(starts, counts, np.tile([0.0, 0.0, 1.0], (100, 1)), pos, size, 1e-6)
    return g, len(pos), time.perf_counter() - t0


def built(size, steps):
    g, ns, t_build = contacts_network(size)
    nk, npipe = len(g["pos"]), len(g["pa"])
    zap, c, vol = np.zeros(len(g["zk"])), np.zeros(npipe), np.zeros(nk)
    ones = np.ones(100)
    args = (g["zsub"], g["zw"], g["zcontact"], np.zeros(ns), 1e-4 * ones, 1e-5 * ones, 1e-3 * ones, g["zk"],
            g["zarea"], g["zcot"], g["zpipe"], 1e-3, zap, c, vol)
    zone_update(*args)
    t0 = time.perf_counter()
    zone_update(*args)
    t_up = time.perf_counter() - t0
    x = g["pos"][:, 0]
    fixed = (x < 1e-9) | (x > 100 - 1e-9)
    p = np.where(x < 1e-9, 1e5, 0.0)
    dg = np.zeros(npipe)
    flow = np.zeros(npipe)
    dt = stable_dt(g["pa"], g["pb"], c, vol, 2e9, fixed)
    network_steps(2, dt, g["pa"], g["pb"], c, dg, vol, 2e9, fixed, np.zeros(nk), p, flow)
    t0 = time.perf_counter()
    network_steps(steps, dt, g["pa"], g["pb"], c, dg, vol, 2e9, fixed, np.zeros(nk), p, flow)
    t_steps = time.perf_counter() - t0
    t0 = time.perf_counter()
    steady(nk, g["pa"], g["pb"], c, fixed, np.where(x < 1e-9, 1e5, 0.0))
    t_steady = time.perf_counter() - t0
    print(f"from contacts, zone size {size:g} m: {nk} knots, {npipe} pipes, {len(g['zk'])} zones; build "
          f"{t_build:.2f} s, aperture/conductance update {1e3 * t_up:.2f} ms, {steps} explicit steps "
          f"{npipe * steps / t_steps:.3g} channel-updates/s, steady solve {t_steady:.3f} s")


if __name__ == "__main__":
    main()
