"""Benchmark of `dec3d ssdem`: time per load step and peak memory for 1e3, 1e4, 1e5 blocks.

A 10 m high, 45 degree slope on a 10 m deep foundation, meshed as a grid whose block
size gives the wanted block count; soft enough (c' = 12 kPa, phi' = 20 deg) that
interfaces near the toe yield, so the secant iterations are exercised.  Each size
runs in a fresh process (peak RSS from resource.getrusage is per process), several
times; the median is printed.  Targets on the 2-core reference machine: <= 0.5 s,
<= 3 s and <= 40 s per load step, memory growing linearly with the block count.

    python bench/ssdem_bench.py [--repeat 3] [--sizes 1000 10000 100000] [--steps 5]
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

TEMPLATE = """
title = "bench"
units = "kN-m"
[profile]
points = [[-20.0, 0.0], [0.0, 0.0], [10.0, 10.0], [40.0, 10.0]]
[[layer]]
c = 12.0
phi = 20.0
gamma = 18.0
kn = 3.5e5
ks = 1.0e5
tension_cutoff = false
[mesh]
size = {size}
bottom = -10.0
[analysis]
steps = {steps}
"""
AREA = 60.0 * 10.0 + 0.5 * 10.0 * 10.0 + 30.0 * 10.0   # section area, m^2


def one(n_target: int, steps: int) -> dict:
    """Run in this process; return timings and peak memory."""
    import resource
    import tempfile
    from pathlib import Path

    from dec3d.ssdem import solve
    from dec3d.ssdem.readers import read
    size = (AREA / n_target) ** 0.5
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "bench.toml"
        f.write_text(TEMPLATE.format(size=f"{size:.6f}", steps=steps))
        t0 = time.perf_counter()
        prob = read(f)
        t1 = time.perf_counter()
        st = solve.run(prob)
        t2 = time.perf_counter()
    rss_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return dict(blocks=prob.blocks.n, dofs=int((~prob.blocks.fix).sum()), interfaces=prob.interfaces.m,
                mesh_s=t1 - t0, per_step_s=(t2 - t1) / steps,
                iterations=[r.iterations for r in st.steps], factorizations=st.factorizations,
                yielded=st.steps[-1].n_yielded, peak_rss_mib=rss_kib / 1024.0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000])
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        print(json.dumps(one(args.child, args.steps)))
        return 0
    print(f"{'blocks':>8} {'DOFs':>8} {'mesh s':>7} {'s/step':>8} {'min..max':>15} {'peak MiB':>9} {'MiB/kblock':>10}  iterations")
    for n in args.sizes:
        runs = []
        for _ in range(args.repeat):
            out = subprocess.run([sys.executable, __file__, "--child", str(n), "--steps", str(args.steps)],
                                 capture_output=True, text=True, check=True)
            runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
        per = [r["per_step_s"] for r in runs]
        mem = statistics.median(r["peak_rss_mib"] for r in runs)
        r0 = runs[0]
        print(f"{r0['blocks']:>8} {r0['dofs']:>8} {statistics.median(r['mesh_s'] for r in runs):>7.2f} "
              f"{statistics.median(per):>8.3f} {min(per):>7.3f}..{max(per):<7.3f} {mem:>9.0f} "
              f"{1000 * mem / r0['blocks']:>10.1f}  {r0['iterations']} ({r0['yielded']} yielded)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
