"""DFN speed: generate 1e5 disk fractures; cut a 50 m block by 2000 fractures; peak memory.

    python bench/dfn_bench.py [--generate 100000] [--cut 2000] [--dmin 3] [--dmax 24]

Printed: seconds to generate (by count, and by a P32 target with exact clipping), seconds to cut
and the blocks made, seconds per fracture of the cut, the total volume error of the cut (relative),
and the peak resident memory of the process (ru_maxrss). Targets (issue 30): generation ≤ 2 s,
cut to ≥ 1e4 blocks ≤ 60 s on one core.
"""
from __future__ import annotations

import argparse
import os
import platform
import resource
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from dec3d.geometry import dfn_gen  # noqa: E402
from dec3d.geometry.dfn_cut import cut_dfn  # noqa: E402
from dec3d.model.fractures import ensure_face_fields  # noqa: E402
from dec3d.session import Session  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--generate", type=int, default=100_000)
    ap.add_argument("--cut", type=int, default=2000)
    ap.add_argument("--dmin", type=float, default=3.0)
    ap.add_argument("--dmax", type=float, default=24.0)
    a = ap.parse_args()
    print(f"python {platform.python_version()}, {platform.machine()}, {os.cpu_count()} cpus "
          f"(load {os.getloadavg()[0]:.2f}), NUMBA_NUM_THREADS={os.environ['NUMBA_NUM_THREADS']}")
    t = dfn_gen.default_template()
    t["orientation"] = {"kind": "uniform"}
    t["size"] = {"kind": "power-law", "exponent": 3.0}
    t["size_limits"] = [a.dmin, a.dmax]
    box = [0, 50, 0, 50, 0, 50]
    t0 = time.perf_counter()
    c, n, r = dfn_gen.generate(t, box, 1, count=a.generate)
    print(f"generate {len(r)} fractures by count: {time.perf_counter() - t0:.3f} s")
    t1 = dict(t, size_limits=[1.0, 20.0], size={"kind": "power-law", "exponent": 3.5})
    t0 = time.perf_counter()
    c1, _, _ = dfn_gen.generate(t1, box, 1, p32=2.0)
    print(f"generate P32 = 2 in a 50 m box (exact clipping): {len(c1)} fractures, {time.perf_counter() - t0:.3f} s")

    s = Session()
    s.command("model new")
    s.command("block create brick 0 50 0 50 0 50")
    ensure_face_fields(s.model)
    # warm the cutting kernel (numba compiles or loads its cache) before the clock
    cut_dfn(s.model, np.array([[25, 25, 25.0]]), np.array([[0, 0, 1.0]]), np.array([100.0]), [0], 0)
    s.command("model new")
    s.command("block create brick 0 50 0 50 0 50")
    ensure_face_fields(s.model)
    v0 = float(s.model.blocks["volume"].sum())
    c, n, r = dfn_gen.generate(t, box, 2, count=a.cut)
    t0 = time.perf_counter()
    made, used, skipped = cut_dfn(s.model, c, n, r, np.arange(1, len(r) + 1), 1)
    dt = time.perf_counter() - t0
    v = s.model.blocks["volume"]
    print(f"cut a 50 m block by {len(r)} fractures ({used} cut): {s.model.blocks.n} blocks in {dt:.2f} s "
          f"({1e3 * dt / len(r):.2f} ms per fracture, {skipped} sliver cuts skipped); volume error {abs(v.sum() - v0) / v0:.2e}, "
          f"smallest block {v.min():.3g} m³")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak memory {peak:.0f} MB")


if __name__ == "__main__":
    main()
