"""Dynamic earthquake benchmark (`rigid_bench.py --quake`): a masonry wall shaken at its base.

Scene: a one-brick-thick wall in running bond, NX bricks of 0.4 x 0.2 x 0.2 m per course (odd
courses NX - 1 bricks and two half bricks at the ends), NZ courses, density 1800 kg/m^3, on a
base block. Joints mohr, kn = 1e9 Pa/m, ks = 0.5e9 Pa/m, friction 35 deg, no cohesion or tension.
Gravity -9.81 m/s^2, `model dynamic active on`, Rayleigh damping 5 % at 5 Hz, no density scaling
(the real time step). ``--rayleigh mass`` (default) keeps the mass-proportional term only, the usual
choice for rigid-block masonry: with the stiffness term (``both``) the stable step of the 3-brick
smoke wall falls from 4e-5 s to 5e-7 s (the step rule of dec3d.physics.dynamic, Δt = Δt₀ (√(1 + λ²) − λ),
λ = β/Δt₀). The base is fixed and then driven along x by `block apply velocity-x 1 table 'quake'`
(``--split-base``: nx brick-long base blocks instead of one, all driven alike): the table is a
recorded-like synthetic ground velocity (``record``), written to a file in the
output folder and read with `table 'quake' import`.

The record: white noise (numpy default_rng(seed)) band-passed to 0.5..10 Hz in the frequency
domain, shaped by an envelope (2 s linear rise, strong phase, exponential decay over the last
half), scaled to a peak ground acceleration ``pga`` [m/s^2], integrated to velocity (trapezoid
rule) and corrected for base-line drift (the mean acceleration that leaves a non-zero final
velocity is taken off, so the velocity ends at zero).

Figure: simulated seconds per wall second = (timed steps x time step) / wall time, after
WARMUP steps (kernel compilation, first detection). Each (threads, repeat) runs in a fresh process;
the median is printed with the load average.

    python bench/rigid_bench.py --quake [--nx 40] [--nz 25] [--steps 200] [--repeat 3]
                                        [--threads-list 1 2]
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

WARMUP = 5
BRICK = (0.4, 0.2, 0.2)          # length (x), thickness (y), height (z) [m]


def record(seed: int = 2026, duration: float = 4.0, dt: float = 0.01, pga: float = 3.0,
           band: tuple = (0.5, 10.0)) -> tuple:
    """(t, acceleration, velocity) of the synthetic ground motion, t from 0 to ``duration``."""
    n = int(round(duration / dt)) + 1
    t = np.arange(n) * dt
    noise = np.random.default_rng(seed).standard_normal(n)
    spec = np.fft.rfft(noise)
    f = np.fft.rfftfreq(n, dt)
    spec[(f < band[0]) | (f > band[1])] = 0.0
    a = np.fft.irfft(spec, n)
    rise = min(2.0, duration / 4)
    env = np.minimum(t / rise, 1.0)
    late = t > duration / 2
    env[late] *= np.exp(-4.0 * (t[late] - duration / 2) / (duration / 2))
    a *= env
    a *= pga / np.abs(a).max()
    v = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * dt)])
    a = a - v[-1] / t[-1]                      # base-line correction: the final velocity is zero
    v = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * dt)])
    return t, a, v


def wall_deck(nx: int, nz: int, form: str = "mass", split_base: bool = False) -> str:
    """Command lines of the wall on its base (no cycling, no time function yet). ``split_base``: the
    base as nx brick-long blocks (all fixed and driven alike) instead of one long block."""
    lx, ty, hz = BRICK
    length = nx * lx
    lines = ["model new"]
    if split_base:
        lines += [f"block create brick {i * lx:.6f} {(i + 1) * lx:.6f} 0 {ty} -0.3 0 group 'base'" for i in range(nx)]
    else:
        lines.append(f"block create brick 0 {length} 0 {ty} -0.3 0 group 'base'")
    for k in range(nz):
        z0, z1 = k * hz, (k + 1) * hz
        if k % 2 == 0:
            xs = [i * lx for i in range(nx + 1)]
        else:
            xs = [0.0] + [(i + 0.5) * lx for i in range(nx)] + [length]
        for a, b in zip(xs[:-1], xs[1:]):
            lines.append(f"block create brick {a:.6f} {b:.6f} 0 {ty} {z0:.6f} {z1:.6f} group 'wall'")
    lines += [
        "block property density 1800",
        "block contact jmodel assign mohr",
        "block contact material-table default property stiffness-normal 1e9 stiffness-shear 0.5e9 "
        "friction 35 cohesion 0 tension 0",
        "block fix range group 'base'",
        "model gravity 0 0 -9.81",
        "model dynamic active on",
        "block mechanical damping rayleigh 0.05 5.0" + ("" if form == "both" else f" {form}"),
    ]
    return "\n".join(lines) + "\n"


def one(nx: int, nz: int, steps: int, threads: int | None = None, form: str = "mass",
        split_base: bool = False) -> dict:
    """Build, warm up and time in this process."""
    import io
    import tempfile

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if os.path.isdir(os.path.join(root, "dec3d")) and root not in sys.path:
        sys.path.insert(0, root)
    import numba

    import dec3d

    if threads:
        numba.set_num_threads(threads)
    t, _, v = record()
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "quake.txt"), "w", encoding="utf-8") as fh:
            fh.write("synthetic ground velocity [m/s]\n")
            fh.writelines(f"{ti:.4f} {vi:.8e}\n" for ti, vi in zip(t, v))
        s = dec3d.Session(out_dir=d, stdout=io.StringIO())
        t0 = time.perf_counter()
        s.command(wall_deck(nx, nz, form, split_base))
        s.command("table 'quake' import 'quake.txt'\n"
                  "block apply velocity-x 1 table 'quake' range group 'base'")
        t1 = time.perf_counter()
        from dec3d.physics.dynamic import dynamic_time

        s.command(f"model cycle {WARMUP}")
        t2 = time.perf_counter()
        start = dynamic_time(s.model)
        s.command(f"model cycle {steps}\n[dt = mech.timestep]")
        t3 = time.perf_counter()
        sim = dynamic_time(s.model)
        b = s.model.blocks
        finite = bool(np.isfinite(b["velocity"][: b.n]).all() and np.isfinite(b["centroid"][: b.n]).all())
        base_vx = float(b["velocity"][0, 0])
        blocks = int(b.n)
        contacts = s.model.stores["contacts"].n
    simulated = sim - start
    return dict(threads=numba.get_num_threads(), blocks=blocks, contacts=contacts, dt=s.variables["dt"],
                build_s=t1 - t0, warmup_s=t2 - t1, seconds=t3 - t2, simulated=simulated,
                dyn_time=sim, finite=finite, base_vx=base_vx)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="dynamic earthquake case of rigid_bench.py")
    ap.add_argument("--quake", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--nx", type=int, default=40, help="bricks per course")
    ap.add_argument("--nz", type=int, default=25, help="courses")
    ap.add_argument("--steps", type=int, default=200, help="timed steps")
    ap.add_argument("--repeat", type=int, default=3, help="runs per thread count (median printed)")
    ap.add_argument("--threads-list", type=int, nargs="+", default=[1, 2], help="numba thread counts")
    ap.add_argument("--rayleigh", choices=("mass", "both", "stiffness"), default="mass",
                    help="Rayleigh terms (default mass: the stiffness term lowers the stable step ~100-fold "
                         "here, dec3d.physics.dynamic.stiffness_timestep)")
    ap.add_argument("--split-base", action="store_true",
                    help="the base as brick-long blocks: the engine's step also counts the fixed base, and "
                         "one long base block lowers it (1.1e-5 s instead of 6.9e-5 s for the 40-brick wall)")
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(one(args.nx, args.nz, args.steps, args.child, args.rayleigh, args.split_base)))
        return 0
    from rigid_bench import machine

    print(f"machine: {machine()}")
    print(f"scene: masonry wall {args.nx} bricks x {args.nz} courses (0.4 x 0.2 x 0.2 m, 1800 kg/m^3) on a "
          f"{'split ' if args.split_base else ''}base driven by a synthetic velocity record; dynamic, "
          f"Rayleigh 5 % at 5 Hz ({args.rayleigh}), real time step; "
          f"{WARMUP} warm-up + {args.steps} timed steps, median of {args.repeat}")
    for th in args.threads_list:
        runs = []
        for _ in range(args.repeat):
            cmd = [sys.executable, os.path.abspath(__file__), "--child", str(th), "--nx", str(args.nx),
                   "--nz", str(args.nz), "--steps", str(args.steps), "--rayleigh", args.rayleigh]
            cmd += ["--split-base"] if args.split_base else []
            out = subprocess.run(cmd, capture_output=True, text=True)
            if out.returncode != 0:
                sys.stderr.write(out.stderr)
                raise SystemExit(f"threads {th}: the run failed (exit {out.returncode})")
            r = json.loads(out.stdout.strip().splitlines()[-1])
            if not r["finite"]:
                raise SystemExit(f"threads {th}: the model state is not finite")
            runs.append(r)
        sec = statistics.median(r["seconds"] for r in runs)
        rate = statistics.median(r["simulated"] / r["seconds"] for r in runs)
        r0 = runs[0]
        print(f"threads {r0['threads']}: blocks {r0['blocks']} contacts {r0['contacts']} dt {r0['dt']:.3e} s "
              f"wall {sec:.3f} s (runs {[round(r['seconds'], 3) for r in runs]}) "
              f"simulated {r0['simulated']:.4e} s; sim s per wall s {rate:.4g}; "
              f"load average {os.getloadavg()[0]:.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    sys.exit(main())
