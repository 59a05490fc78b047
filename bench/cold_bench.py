"""Cold start: wall time of the first `dec3d run` of a deck on an empty numba cache, and the compile
CPU of each kernel in the deck's process (issue 9, "Cold start").

Each run gets a fresh NUMBA_CACHE_DIR and runs the deck in a child process, which records numba's
"numba:compile" events (CPU seconds per kernel, those of the kernels it compiled inside excluded);
a second run on the now warm cache gives the warm wall time. The CPU total counts the warm-up
process too (a child of the deck's process, waited for).

    python bench/cold_bench.py [--deck examples/rigid/masonry_wall.dat] [--repeat 3] [--no-warmup]
                               [--kernels]

The machine may be shared: the compile CPU is the robust figure; compare wall times back to back.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def child(deck: str, out: str, report: str) -> int:
    """Run the deck (as `dec3d run`) recording the exclusive compile CPU of each kernel."""
    from numba.core import event as ev

    stack, rec = [], {}

    class Compiles(ev.Listener):
        def on_start(self, event):
            stack.append([time.process_time(), 0.0])

        def on_end(self, event):
            c0, inner = stack.pop()
            dt = time.process_time() - c0
            if stack:
                stack[-1][1] += dt
            f = event.data["dispatcher"].py_func
            key = f"{f.__module__}.{f.__name__}"
            rec[key] = rec.get(key, 0.0) + dt - inner

    ev.register("numba:compile", Compiles())
    from dec3d.cli import main

    rc = main(["run", deck, "--out", out, "--quiet"])
    Path(report).write_text(json.dumps({"rc": rc, "kernels": rec, "cpu": time.process_time()}))
    return rc


def one(deck: str, warmup: bool) -> dict:
    with tempfile.TemporaryDirectory(prefix="dec3d-cold-") as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "cache"), DEC3D_WARMUP="1" if warmup else "0",
                   PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
        report = str(Path(tmp) / "report.json")
        cmd = [sys.executable, __file__, "--child", deck, str(Path(tmp) / "out"), report]
        walls, cpus = [], []
        for _ in range(2):                      # cold, then warm
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            walls.append(time.perf_counter() - t0)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpus.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
            if len(walls) == 1:
                rec = json.loads(Path(report).read_text())
        return dict(cold_wall=walls[0], warm_wall=walls[1], cold_cpu=cpus[0], main_cpu=rec["cpu"],
                    compile=sum(rec["kernels"].values()), kernels=rec["kernels"])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--deck", default=str(ROOT / "examples" / "rigid" / "masonry_wall.dat"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-warmup", action="store_true", help="DEC3D_WARMUP=0: no second process")
    ap.add_argument("--kernels", action="store_true", help="print the compile CPU of each kernel (median)")
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        sys.exit(child(*a.child))
    runs = [one(a.deck, not a.no_warmup) for _ in range(a.repeat)]
    med = {k: statistics.median(r[k] for r in runs) for k in ("cold_wall", "warm_wall", "cold_cpu", "main_cpu",
                                                                "compile")}
    print(f"{Path(a.deck).name}: cold {med['cold_wall']:.1f} s wall, warm {med['warm_wall']:.2f} s wall; "
          f"cold CPU {med['cold_cpu']:.1f} s (all processes), deck's process {med['main_cpu']:.1f} s, of which "
          f"compiling {med['compile']:.1f} s (median of {a.repeat}, warm-up {'off' if a.no_warmup else 'on'})")
    if a.kernels:
        names = sorted({k for r in runs for k in r["kernels"]},
                       key=lambda k: -statistics.median(r["kernels"].get(k, 0.0) for r in runs))
        for k in names:
            print(f"  {statistics.median(r['kernels'].get(k, 0.0) for r in runs):6.2f} s  {k}")


if __name__ == "__main__":
    main()
