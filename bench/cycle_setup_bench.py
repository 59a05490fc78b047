"""Per-command set-up cost of `model cycle` on a zoned model: what each `model cycle N` /
`model solve` command pays before (and after) its steps, as decks that cycle a few steps at a
time in FISH loops (excavation stages, histories) pay it at every command.

Scene: bench/zone_bench.py's unit cube of 4-node tetrahedra (elastic, gravity, base held), about
N zones. After warm-up, K commands `model cycle 1` are timed against one `model cycle K`:

    overhead per command = (t(K × `model cycle 1`) − t(`model cycle K`)) / (K − 1)

Then one `model cycle 1` is profiled (cProfile) and its time is broken down by phase: the
engine's snapshot (rollback copy), the zone stepper's set-up (``ZoneStepper.__init__``), the rest
of the run's set-up (``_Run.__init__`` less the stepper), the steps, the run's end.
``--no-cache`` sets DEC3D_NO_STEPPER_CACHE=1 (the zone stepper built anew at every command).

    python bench/cycle_setup_bench.py [--zones 1e5 1e6] [--k 10] [--threads 1] [--no-cache] [--profile]
    python bench/cycle_setup_bench.py --rigid --zones 10 20     # rigid_bench.py's n³ stack of cubes

Each size runs in a fresh process; the machine and /proc/loadavg before and after are printed
(the machine is shared: read the figures with the load).
"""
from __future__ import annotations

import argparse
import cProfile
import io
import json
import os
import pstats
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

#: (phase, function as pstats names it: (file suffix, line-free function name))
PHASES = [
    ("snapshot (rollback copy)", ("physics/rigid.py", "_snapshot")),
    ("zone stepper set-up", ("physics/zones.py", "__init__")),
    ("run set-up (all, incl. stepper)", ("physics/steps.py", "__init__")),
    ("steps (_cycle loop)", ("physics/steps.py", "advance")),
    ("run finish", ("physics/steps.py", "finish")),
    ("command total", ("physics/rigid.py", "cycle")),
]


def _phase_times(prof: cProfile.Profile) -> dict:
    st = pstats.Stats(prof)
    out = {}
    for name, (fsuf, fn) in PHASES:
        tot = 0.0
        for (f, _line, func), (_cc, _nc, _tt, ct, _callers) in st.stats.items():
            if func == fn and f.replace(os.sep, "/").endswith(fsuf):
                tot = max(tot, ct) if fn in ("__init__", "cycle", "finish", "_snapshot") else tot + ct
        out[name] = tot
    return out


def _kept_bytes(model) -> int:
    """Bytes of the copies the engine's zone stepper cache keeps (``physics.zone_cache``)."""
    import numpy as np

    c = getattr(getattr(model, "rigid_engine", None), "_zcache", None)
    if c is None:
        return 0

    def size(x):
        if isinstance(x, np.ndarray):
            return x.nbytes
        if isinstance(x, tuple):
            return sum(size(y) for y in x)
        if hasattr(x, "starts") and hasattr(x, "rows"):
            return x.starts.nbytes + x.rows.nbytes
        return 0
    return int(sum(size(x) for x in c.kept.values()))


def child(zones: float, k: int, threads: int, rigid: bool = False) -> dict:
    sys.path.insert(0, ROOT)
    sys.path.insert(0, HERE)
    import numba

    if threads:
        numba.set_num_threads(threads)
    import dec3d
    from zone_bench import deck, edge_length

    if rigid:                         # rigid_bench.py's stack of n × n × n cubes (n = ``zones``)
        from rigid_bench import deck as rdeck

        def scene(n):
            return rdeck(int(n), "mohr")
        small, size = 2, zones
    else:
        scene, small, size = deck, 0.5, edge_length(zones)
    with tempfile.TemporaryDirectory() as d:
        w = dec3d.Session(out_dir=d, stdout=io.StringIO())
        w.command(scene(small))
        w.command("model cycle 3")
        del w
        s = dec3d.Session(out_dir=d, stdout=io.StringIO())
        s.command(scene(size))
        s.command("model cycle 3")
        s.command("model cycle 1")                   # (a second command: what a cache keeps is made)
        t0 = time.perf_counter()
        for _ in range(k):
            s.command("model cycle 1")
        t1 = time.perf_counter()
        s.command(f"model cycle {k}")
        t2 = time.perf_counter()
        prof = cProfile.Profile()
        prof.enable()
        s.command("model cycle 1")
        prof.disable()
        buf = io.StringIO()
        pstats.Stats(prof, stream=buf).sort_stats("cumulative").print_stats(25)
        nz = s.model.blocks.n if rigid else s.model.store("zones").n
        return dict(zones=nz, kept_b=_kept_bytes(s.model), gridpoints=s.model.vertices.n, threads=numba.get_num_threads(), k=k, t_ones=t1 - t0, t_k=t2 - t1,
                    phases=_phase_times(prof), profile=buf.getvalue())


def loadavg() -> str:
    try:
        with open("/proc/loadavg", encoding="utf-8") as f:
            return f.read().strip()
    except OSError:
        return "n/a"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--zones", type=float, nargs="+", default=[1e5, 1e6])
    ap.add_argument("--k", type=int, default=10, help="commands K")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--no-cache", action="store_true", help="build the zone stepper anew at every command")
    ap.add_argument("--profile", action="store_true", help="print the cProfile listing of one command")
    ap.add_argument("--rigid", action="store_true",
                    help="rigid_bench.py's stack of n x n x n rigid cubes instead (--zones gives n)")
    ap.add_argument("--child", type=float, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child, args.k, args.threads, args.rigid)))
        return 0
    sys.path.insert(0, HERE)
    from rigid_bench import machine

    print(f"machine: {machine()}")
    print(f"loadavg before: {loadavg()}")
    env = dict(os.environ)
    if args.no_cache:
        env["DEC3D_NO_STEPPER_CACHE"] = "1"
    print(f"stepper cache: {'off' if args.no_cache else 'on'}; threads {args.threads}; K = {args.k}")
    for n in args.zones:
        out = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", str(n), "--k", str(args.k),
                              "--threads", str(args.threads)] + (["--rigid"] if args.rigid else []), env=env, capture_output=True, text=True)
        if out.returncode:
            print(out.stderr)
            return 1
        r = json.loads(out.stdout.strip().splitlines()[-1])
        k = r["k"]
        per = (r["t_ones"] - r["t_k"]) / (k - 1)
        print(f"{'blocks' if args.rigid else 'zones'} {r['zones']}: {k} x `model cycle 1` {r['t_ones']:.3f} s, `model cycle {k}` {r['t_k']:.3f} s: "
              f"overhead per command {per * 1e3:.1f} ms (step {r['t_k'] / k * 1e3:.1f} ms); loadavg {loadavg()}")
        if r["kept_b"]:
            print(f"  kept copies of the stepper cache: {r['kept_b'] / r['zones']:.0f} B per zone "
                  f"({r['gridpoints']} gridpoints)")
        print("  one `model cycle 1` under cProfile, by phase (s):")
        for name, t in r["phases"].items():
            print(f"    {name:<34}{t:8.3f}")
        if args.profile:
            print(r["profile"])
    print(f"loadavg after: {loadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
