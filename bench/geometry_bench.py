"""Time and peak memory to cut a 10 m cube into 8 000 and 64 000 blocks (three joint sets).

Each measurement runs in a fresh child process (numba kernels warmed up there on a small
cut first, so compile time is excluded) and reports:

* wall time of: brick creation + three ``block cut joint-set`` calls (spacing 0.5 m or
  0.25 m; dips 90/90, 90/0, 0/0), including mass properties and store compaction;
* peak resident memory above the process's baseline (Linux VmHWM after resetting it);
* peak memory traced by tracemalloc (numpy allocations made from Python).

Prints the median of several runs; no assertions. Targets (issue 3): ≤ 2 s for 8 000
blocks, ≤ 20 s for 64 000, memory growing linearly with the block count.

    python bench/geometry_bench.py [--runs 5]
"""
from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
import time
import tracemalloc


def _status(key: str) -> int:
    """A VmXXX figure of /proc/self/status in bytes (0 where unavailable)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def _cut(spacing: float):
    from dec3d.geometry.cutting import cut_joint_set
    from dec3d.geometry.polyhedron import brick
    from dec3d.model.blocks import add_blocks
    from dec3d.model.model import Model

    m = Model()
    add_blocks(m, [brick(0, 10, 0, 10, 0, 10)], density=2600.0)
    for dip, dd in ((90, 90), (90, 0), (0, 0)):
        cut_joint_set(m, math.radians(dip), math.radians(dd), origin=(0, 0, 0), spacing=spacing)
    return m


def child(spacing: float) -> None:
    _cut(2.5)                                   # warm-up: compile or load the kernels
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")                       # reset the peak-RSS mark
    except OSError:
        pass
    base = _status("VmRSS")
    t0 = time.perf_counter()
    m = _cut(spacing)
    dt = time.perf_counter() - t0
    rss = _status("VmHWM") - base
    n, vol = m.blocks.n, float(m.blocks["volume"].sum())
    del m
    # a second, untimed run under tracemalloc (it slows numpy allocation down)
    tracemalloc.start()
    _cut(spacing)
    traced = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    print(json.dumps({"blocks": n, "seconds": dt, "rss_peak": rss, "traced_peak": traced,
                      "volume": vol}))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--child", type=float, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child is not None:
        child(args.child)
        return
    print(f"{'blocks':>8} {'time [s] median (min-max)':>28} {'peak RSS [MB]':>14} "
          f"{'numpy peak [MB]':>16} {'B/block':>8}  target")
    for spacing, target in ((0.5, 2.0), (0.25, 20.0)):
        runs = []
        for _ in range(args.runs):
            out = subprocess.run([sys.executable, __file__, "--child", str(spacing)],
                                 check=True, capture_output=True, text=True).stdout
            runs.append(json.loads(out.strip().splitlines()[-1]))
        t = [r["seconds"] for r in runs]
        rss = statistics.median(r["rss_peak"] for r in runs)
        traced = statistics.median(r["traced_peak"] for r in runs)
        n = runs[0]["blocks"]
        print(f"{n:>8} {statistics.median(t):>10.3f} ({min(t):.3f}-{max(t):.3f}){'':>6} "
              f"{rss / 1e6:>14.1f} {traced / 1e6:>16.1f} {traced / n:>8.0f}  <= {target:g} s"
              f"  (volume {runs[0]['volume']:.12f} m^3)")


if __name__ == "__main__":
    main()
