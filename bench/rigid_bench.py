"""Benchmark of the rigid-block cycle: an n x n x n stack of unit cubes on a fixed base.

The scene of the YADE peer benchmark (/work/shared/bench/yade_cubes_bench.py, see
bench/README.md "Peers"): n^3 unit cubes (density 2600 kg/m^3) face to face, resting on
a fixed n x n x 1 base block, gravity -9.81 m/s^2, local damping 0.8, joint model mohr
(kn = ks = 1e9 Pa/m, friction 34.38 deg = YADE's 0.6 rad, no cohesion, no tension) or
elastic (`--jmodel elastic`, same stiffnesses).  5 warm-up steps (they also compile the
numba kernels and make the first contact detection), then S timed steps.

The scene is built and run only through the public command API (`dec3d.Session().command`),
so the script keeps working while the engine behind the commands changes.  The contact and
sub-contact counts are the rows of the model's ``contacts`` and ``subcontacts`` stores.  Each (n, repeat) runs in a fresh
process (peak RSS from resource.getrusage is per process); the median is printed.

    python bench/rigid_bench.py [--n 10 20] [--steps 100] [--repeat 3] [--jmodel mohr|elastic]
                                [--full-detection] [--threads N]
    python bench/rigid_bench.py --quake [--nx 40] [--nz 25] [--steps 200] [--repeat 3] [--threads-list 1 2]

``--quake``: the dynamic earthquake case of bench/quake_bench.py (a masonry wall of about 1000
blocks on a base driven by a synthetic ground-velocity table, dynamic mode, Rayleigh 5 %): simulated
seconds per wall second at the real time step.

``--threads N`` calls numba.set_num_threads(N) in each run; the numba threading layer and the
thread count actually used are printed (a layer of "n/a" means no parallel kernel ran).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time

WARMUP = 5


def deck(n: int, jmodel: str, dynamic: bool = False) -> str:
    """Command lines building the scene (no cycling).  ``dynamic``: every block keeps moving —
    gravity tilted (4, 0, -9.81) m/s², friction 5° (tan 5° < 4/9.81), no damping: the whole
    stack slides and accelerates along x on the base."""
    lines = ["model new", f"block create brick 0 {n} 0 {n} -1 0"]
    for i in range(n):
        for j in range(n):
            for k in range(n):
                lines.append(f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}")
    props = "stiffness-normal 1e9 stiffness-shear 1e9"
    if jmodel == "mohr":
        props += f" friction {5 if dynamic else 34.38} cohesion 0 tension 0"
    lines += [
        "block property density 2600",
        "block fix range position-z -1 0",
        "model gravity 4 0 -9.81" if dynamic else "model gravity 0 0 -9.81",
        "block mechanical damping none" if dynamic else "block mechanical damping local 0.8",
        f"block contact jmodel assign {jmodel}",
        f"block contact material-table default property {props}",
    ]
    return "\n".join(lines) + "\n"


def _counts(session) -> tuple:
    """(contacts, sub-contacts): the rows of the model's contact stores."""
    stores = session.model.stores
    return stores["contacts"].n, stores["subcontacts"].n


def one(n: int, steps: int, jmodel: str, full: bool = False, threads: int | None = None,
        dynamic: bool = False, setup: str = "") -> dict:
    """Build, warm up and time in this process. ``full``: every pair is looked at again at
    every detection (the engine's incremental rule off: the worst case, a model in which
    every block keeps moving)."""
    import io
    import resource
    import tempfile

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if os.path.isdir(os.path.join(root, "dec3d")) and root not in sys.path:
        sys.path.insert(0, root)       # the checkout's dec3d (also when it is not installed)
    import numba

    import dec3d                       # (first: it chooses numba's threading layer)

    if threads:
        numba.set_num_threads(threads)

    if full:
        import dec3d.physics.contacts as contacts

        contacts.QUIET = 0.0

    with tempfile.TemporaryDirectory() as d:
        s = dec3d.Session(out_dir=d, stdout=io.StringIO())
        t0 = time.perf_counter()
        s.command(deck(n, jmodel, dynamic) + setup)
        t1 = time.perf_counter()
        s.command(f"model cycle {WARMUP}")
        t2 = time.perf_counter()
        s.command(f"model cycle {steps}")
        t3 = time.perf_counter()
        nc, nsc = _counts(s)
    rss_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    try:
        layer = numba.threading_layer()
    except ValueError:                 # no parallel kernel has run in this process
        layer = "n/a"
    return dict(threads=numba.get_num_threads(), layer=layer, blocks=n ** 3, contacts=nc, subcontacts=nsc, build_s=t1 - t0, warmup_s=t2 - t1,
                seconds=t3 - t2, peak_rss_mib=rss_kib / 1024.0)


def base_reaction(session, base: int = 0) -> float:
    """Vertical force the sub-contacts on block ``base`` carry [N] (the base reaction)."""
    import numpy as np

    c = session.model.stores["contacts"].to_arrays()
    sc = session.model.stores["subcontacts"].to_arrays()
    on_base = (c["a"] == base) | (c["b"] == base)
    rows = on_base[sc["contact"]]
    return float(abs(np.sum(sc["fn"][rows] * c["normal"][sc["contact"][rows], 2])))


def at_equilibrium(session, rtol: float = 1e-3, vtol: float = 1e-5) -> tuple:
    """(done, reaction error, largest speed): the base reaction within ``rtol`` of the
    weight of the free blocks and every free block slower than ``vtol`` m/s."""
    import numpy as np

    b = session.model.blocks
    free = b["fixity"] == 0
    weight = float(b["mass"][free].sum()) * 9.81
    err = abs(base_reaction(session) - weight) / weight
    vmax = float(np.sqrt((b["velocity"][free] ** 2).sum(axis=1)).max())
    return err <= rtol and vmax < vtol, err, vmax


def equilibrium(n: int, jmodel: str = "mohr", cap: int = 100000,
                solve: str | None = None) -> dict:
    """Wall time and steps from the first cycle until ``at_equilibrium`` (checked after every
    batch of one run, at most the update interval apart; the check is inside the timed wall).  Kernels are compiled first on a
    one-cube scene so the figure is the warm time.  ``solve``: extra command lines (damping
    etc.) given after the scene."""
    import io
    import tempfile

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if os.path.isdir(os.path.join(root, "dec3d")) and root not in sys.path:
        sys.path.insert(0, root)
    import dec3d

    with tempfile.TemporaryDirectory() as d:
        w = dec3d.Session(out_dir=d, stdout=io.StringIO())
        w.command(deck(1, jmodel))
        w.command("model cycle 3")
        s = dec3d.Session(out_dir=d, stdout=io.StringIO())
        s.command(deck(n, jmodel) + (solve or ""))
        from dec3d.physics.rigid import engine

        # one run, as `model solve` makes it, checked after every batch of steps (at most the
        # update interval apart); the check is inside the timed wall
        en = engine(s.model)
        t0 = time.perf_counter()
        c0 = time.process_time()
        en.cycle(cap, stop=lambda _: at_equilibrium(s)[0])
        wall = time.perf_counter() - t0
        cpu = time.process_time() - c0
        steps = s.model.step
        done, err, vmax = at_equilibrium(s)
    return dict(blocks=n ** 3, steps=steps, seconds=wall, cpu_seconds=cpu, reached=done, reaction_error=err,
                max_speed=vmax)


def machine() -> str:
    cpu = platform.processor() or "?"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, {platform.system()} {platform.release()}"


def run_children(cmd: list, repeat: int, what: str) -> list:
    """Run ``cmd`` (a bench script in ``--child`` mode) ``repeat`` times, each a fresh process,
    and return the JSON dicts each printed on its last line; stop with the child's stderr when a
    run fails (``what`` names the size in the message)."""
    runs = []
    for _ in range(repeat):
        out = subprocess.run(cmd, capture_output=True, text=True)
        if out.returncode != 0:
            sys.stderr.write(out.stderr)
            raise SystemExit(f"{what}: the run failed (exit {out.returncode})")
        runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
    return runs


def _fmt(x) -> str:
    return "n/a" if x is None else str(x)


def main() -> int:
    if "--quake" in sys.argv[1:]:      # the dynamic earthquake case: bench/quake_bench.py
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import quake_bench

        return quake_bench.main(sys.argv[1:])
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[10, 20], help="cubes per side")
    ap.add_argument("--steps", type=int, default=100, help="timed steps S")
    ap.add_argument("--repeat", type=int, default=3, help="runs per n (median printed)")
    ap.add_argument("--jmodel", choices=("mohr", "elastic"), default="mohr")
    ap.add_argument("--full-detection", action="store_true",
                    help="look at every pair at every detection (no incremental skipping): the worst case")
    ap.add_argument("--threads", type=int, default=None,
                    help="numba threads per run (numba.set_num_threads); default: numba's own")
    ap.add_argument("--equilibrium", action="store_true",
                    help="time to equilibrium (base reaction within 0.1 %% of the weight, "
                         "largest speed < 1e-5 m/s) instead of per-step speed")
    ap.add_argument("--dynamic", action="store_true",
                    help="every block keeps moving (the stack slides on the base; with "
                         "--full-detection: detection at every step)")
    ap.add_argument("--setup", default="",
                    help="extra command lines after the scene, separated by ';' "
                         "(e.g. 'block mechanical mass-scale body; block mechanical damping global')")
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    setup = "".join(line.strip() + "\n" for line in args.setup.split(";") if line.strip())
    if args.equilibrium:
        import importlib

        root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        if os.path.isdir(os.path.join(root, "dec3d")) and root not in sys.path:
            sys.path.insert(0, root)
        importlib.import_module("dec3d")          # (first: it chooses numba's threading layer)
        import numba

        if args.threads:
            numba.set_num_threads(args.threads)
        print(f"machine: {machine()}; threads {numba.get_num_threads()}")
        print(f"setup: {args.setup or '(scene as is: local damping 0.8, default density scaling: by body, masses raised)'}; "
              f"load average before: {os.getloadavg()[0]:.2f}")
        for n in args.n:
            runs = [equilibrium(n, args.jmodel, solve=setup) for _ in range(args.repeat)]
            t = statistics.median(r['seconds'] for r in runs)
            print(f"n {n}: steps {runs[0]['steps']} reached {runs[0]['reached']} "
                  f"reaction err {runs[0]['reaction_error']:.2e} vmax {runs[0]['max_speed']:.2e} "
                  f"wall median {t:.2f} s (runs {[round(r['seconds'], 2) for r in runs]}), "
                  f"{1e3 * t / max(1, runs[0]['steps']):.3f} ms/step; CPU median "
                  f"{statistics.median(r['cpu_seconds'] for r in runs):.2f} s (all threads); "
                  f"load average {os.getloadavg()[0]:.2f}",
                  flush=True)
        return 0
    if args.child:
        print(json.dumps(one(args.child, args.steps, args.jmodel, args.full_detection,
                             args.threads, args.dynamic, setup)))
        return 0
    print(f"machine: {machine()}")
    print(f"scene: n^3 unit cubes on a fixed base, jmodel {args.jmodel}, kn = ks = 1e9 Pa/m, "
          f"{WARMUP} warm-up + {args.steps} timed steps, median of {args.repeat}"
          + (", full detection" if args.full_detection else "")
          + (", dynamic (sliding, no damping)" if args.dynamic else "")
          + (f", setup: {args.setup}" if setup else ""))
    print(f"{'n':>3} {'blocks':>7} {'contacts':>8} {'subcont':>8} {'build s':>8} {'warmup s':>8} "
          f"{'seconds':>8} {'min..max':>15} {'blk-cyc/s':>10} {'subc-upd/s':>11} {'peak MiB':>9}")
    for n in args.n:
        runs = run_children([sys.executable, os.path.abspath(__file__), "--child", str(n),
                             "--steps", str(args.steps), "--jmodel", args.jmodel]
                            + (["--full-detection"] if args.full_detection else [])
                            + (["--threads", str(args.threads)] if args.threads else [])
                            + (["--dynamic"] if args.dynamic else [])
                            + (["--setup", args.setup] if setup else []),
                            args.repeat, f"n = {n}")
        sec = [r["seconds"] for r in runs]
        t = statistics.median(sec)
        r0 = runs[0]
        print(f"    threads {r0['threads']}, threading layer {r0['layer']}", flush=True)
        bcs = r0["blocks"] * args.steps / t if t > 0 else float("inf")
        scu = "n/a" if r0["subcontacts"] is None else f"{r0['subcontacts'] * args.steps / t:.3g}"
        print(f"{n:>3} {r0['blocks']:>7} {_fmt(r0['contacts']):>8} {_fmt(r0['subcontacts']):>8} "
              f"{statistics.median(r['build_s'] for r in runs):>8.2f} "
              f"{statistics.median(r['warmup_s'] for r in runs):>8.2f} {t:>8.3f} "
              f"{min(sec):>7.3f}..{max(sec):<7.3f} {bcs:>10.4g} {scu:>11} "
              f"{statistics.median(r['peak_rss_mib'] for r in runs):>9.0f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
