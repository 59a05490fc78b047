"""Time and peak memory to cut a 10 m cube into 8 000 and 64 000 blocks (three joint sets).

Each measurement runs in a fresh child process (numba kernels warmed up there on a small
cut first, so compile time is excluded) and reports:

* wall time of: brick creation + three ``block cut joint-set`` calls (spacing 0.5 m or
  0.25 m; dips 90/90, 90/0, 0/0), including mass properties and store compaction;
* peak resident memory above the process's baseline (Linux VmHWM after resetting it);
* peak memory traced by tracemalloc (numpy allocations made from Python).

Prints the median of several runs; no assertions. Targets (issue 3): ≤ 2 s for 8 000
blocks, ≤ 20 s for 64 000, memory growing linearly with the block count.

Then (issue 33) decks of 8 000 `block create brick` lines and of 8 000 `block create polyhedron`
lines (a sheared hexahedron each, six faces of four corners written out: 72 numbers a line, as
masonry decks exported from CAD are) run through a session: parse + bind (``Session.load_text``)
and running (building the blocks) timed apart, in a child process after a warm-up deck.
Target: ≥ 5 000 blocks/s (8 000 bricks in under 2 s).

    python bench/geometry_bench.py [--runs 5] [--decks-only]
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


def create_deck(kind: str, n_side: int = 20) -> str:
    """n_side³ `block create` lines: unit bricks, or sheared hexahedra given face by face."""
    lines = ["model new"]
    quads = ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5))
    for k in range(n_side):
        for j in range(n_side):
            for i in range(n_side):
                if kind == "brick":
                    lines.append(f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}")
                    continue
                c = [(i + a + 0.2 * (k + c_), j + b, k + c_) for c_ in (0, 1) for b in (0, 1) for a in (0, 1)]
                faces = " ".join("face " + " ".join(f"{x:g},{y:g},{z:g}" for x, y, z in (c[q] for q in quad))
                                 for quad in quads)
                lines.append(f"block create polyhedron {faces} group 'course_{k}'")
    return "\n".join(lines) + "\n"


def deck_child(kind: str) -> None:
    import io

    from dec3d.session import Session

    warm = Session(out_dir="/tmp", stdout=io.StringIO())
    warm.run_items(warm.load_text(create_deck(kind, 3), "warm.dat"))
    text = create_deck(kind)
    s = Session(out_dir="/tmp", stdout=io.StringIO())
    t0 = time.perf_counter()
    items = s.load_text(text, "deck.dat")
    t1 = time.perf_counter()
    s.run_items(items)
    t2 = time.perf_counter()
    print(json.dumps({"lines": text.count("\n"), "blocks": s.model.blocks.n, "load": t1 - t0, "run": t2 - t1}))


def decks(runs: int) -> None:
    print(f"{'deck':>28} {'lines':>6} {'parse+bind s':>13} {'lines/s':>9} {'build s':>8} {'blocks/s':>9}  target")
    for kind in ("brick", "polyhedron"):
        rs = []
        for _ in range(runs):
            out = subprocess.run([sys.executable, __file__, "--deck-child", kind],
                                 check=True, capture_output=True, text=True).stdout
            rs.append(json.loads(out.strip().splitlines()[-1]))
        load = statistics.median(r["load"] for r in rs)
        run = statistics.median(r["run"] for r in rs)
        print(f"{'8 000 block create ' + kind:>28} {rs[0]['lines']:>6} {load:>13.3f} {rs[0]['lines'] / load:>9,.0f} "
              f"{run:>8.3f} {rs[0]['blocks'] / run:>9,.0f}  >= 5 000 blocks/s, >= 100 000 lines/s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--decks-only", action="store_true", help="only the `block create` decks")
    ap.add_argument("--child", type=float, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--deck-child", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child is not None:
        child(args.child)
        return
    if args.deck_child is not None:
        deck_child(args.deck_child)
        return
    if args.decks_only:
        decks(args.runs)
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
    decks(args.runs)


if __name__ == "__main__":
    main()
