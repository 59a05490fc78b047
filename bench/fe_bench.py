"""Element-cycles/s of the 20-node brick step (kernels/feblock.py) for regular meshes of about
1e3, 1e4 and 1e5 elements, 2x2x2 and 3x3x3 integration, 1 and 2 threads, with the memory per
element of the arrays the step touches.

    python bench/fe_bench.py [--n 1000 10000 100000] [--steps 20] [--threads 1 2] [--hourglass 0.1]

The mesh is a block of nx x ny x nz unit elements (nodes shared, as `feblock generate` makes),
random velocities; one warm-up step (numba compilation) then S timed steps of
``feb_step_parallel`` (the element pass on the threads, fixed-order node sums: the result is the
same for any thread count). 2x2x2 without hourglass control, as the engine runs a mesh that holds
its zero-energy modes; ``--hourglass 0.1`` times the control (rows of elements, ``kernels.feblock_hg``). element-cycles/s = elements x S / seconds (best of 3).
"""
import argparse
import os
import platform
import time

import numba
import numpy as np

from dec3d.kernels.feblock import YNODE, feb_node_lists, feb_step_parallel
from dec3d.kernels.feblock_hg import HOURGLASS


def mesh(ne_target: int):
    n = max(1, round(ne_target ** (1 / 3)))
    nx, ny, nz = n, n, max(1, round(ne_target / (n * n)))
    key, pts, elems = {}, [], []
    yi = YNODE.astype(int)
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                ids = []
                for y in yi:
                    q = (2 * i + 1 + y[0], 2 * j + 1 + y[1], 2 * k + 1 + y[2])
                    if q not in key:
                        key[q] = len(pts)
                        pts.append(q)
                    ids.append(key[q])
                elems.append(ids)
    return np.array(pts, float) / 2, np.array(elems, np.int64)


def run(ne_target, steps, nq, threads, hg):
    pos, nodes = mesh(ne_target)
    ne, nv = len(nodes), len(pos)
    rows = np.arange(ne, dtype=np.int64)
    vel = np.random.default_rng(0).normal(scale=1e-3, size=pos.shape)
    K, G = np.full(ne, 1e9), np.full(ne, 6e8)
    gs, st, f = np.zeros((ne, 27, 6)), np.zeros((ne, 6)), np.zeros((nv, 3))
    fe, ok = np.empty((ne, 20, 3)), np.empty(ne, np.bool_)
    nstart, nent = feb_node_lists(nv, nodes, rows)
    numba.set_num_threads(threads)
    feb_step_parallel(pos, vel, nodes, rows, K, G, 1e-4, gs, st, f, nq, fe, ok, nstart, nent, hg)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for _ in range(steps):
            feb_step_parallel(pos, vel, nodes, rows, K, G, 1e-4, gs, st, f, nq, fe, ok, nstart, nent, hg)
        best = min(best, time.perf_counter() - t0)
    per_elem = (nodes.nbytes + gs.nbytes + st.nbytes + K.nbytes + G.nbytes + fe.nbytes + ok.nbytes
                + nent.nbytes + (pos.nbytes + vel.nbytes + f.nbytes + nstart.nbytes)) / ne
    return ne, nv, best, ne * steps / best, per_elem


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[1000, 10000, 100000])
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--hourglass", type=float, default=0.0,
                    help="hourglass control eps_h of the 2x2x2 elements (default 0: the engine gives none to a "
                         f"mesh two or more elements across, as this one; {HOURGLASS:g} to time the control)")
    a = ap.parse_args(argv)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, "
          f"numba {numba.__version__}, max threads {numba.config.NUMBA_NUM_THREADS}, "
          f"2x2x2 hourglass control {a.hourglass:g}")
    print(f"{'elements':>9} {'nodes':>8} {'gauss':>6} {'threads':>7} {'seconds':>9} {'elem-cyc/s':>11} "
          f"{'bytes/elem':>10}")
    for n in a.n:
        for nq in (2, 3):
            for th in a.threads:
                th = min(th, numba.config.NUMBA_NUM_THREADS)
                ne, nv, sec, rate, mem = run(n, a.steps, nq, th, a.hourglass)
                print(f"{ne:>9} {nv:>8} {nq}x{nq}x{nq:<2} {th:>7} {sec:>9.4f} {rate:>11.4g} {mem:>10.0f}",
                      flush=True)


if __name__ == "__main__":
    main()
