"""`dec3d batch` speed: 16 runs of the wedge deck serially (a pool of 1 process), on a pool of 2
processes, and on a Dask LocalCluster of 2 worker processes.

    python bench/batch_bench.py [--runs 16] [--ncycles 12000] [--repeat 2] [--no-dask]

Each batch starts fresh worker processes (the pool's and, for Dask, the cluster's are started
before the clock and not warmed), so the times include each worker's first-run cost (numba
kernels loaded from the cache). Printed: wall seconds of each batch, the sum of the runs' own wall
times, the speed-up serial / 2 processes, and the overhead per run of each parallel path,
(wall × workers − Σ run wall) / runs: worker-seconds spent outside the runs (start-up, shipping
the deck and the output files, scheduling), per run.
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from dec3d import batch  # noqa: E402

DECK = ROOT / "examples" / "batch" / "wedge.dat"


def _rows(t):
    return t.to_dict("records") if hasattr(t, "to_dict") else t


def once(params, out, **kw):
    """One batch into a fresh folder (nothing skipped): wall, Σ run wall, rows."""
    t0 = time.perf_counter()
    rows = _rows(batch.run(DECK, params, out, progress="off", **kw))
    wall = time.perf_counter() - t0
    assert all(r["status"] == "ok" for r in rows), [r["error"] for r in rows if r["status"] != "ok"]
    return wall, sum(r["wall_s"] for r in rows), rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=16)
    ap.add_argument("--ncycles", type=int, default=12000, help="cycles after the friction drop (the deck's ncycles)")
    ap.add_argument("--no-dask", action="store_true")
    ap.add_argument("--repeat", type=int, default=1,
                    help="rounds of (serial, pool of 2, Dask), interleaved so that a change of the machine's load "
                         "hits every mode; each mode's fastest round counts")
    a = ap.parse_args(argv)
    angles = [round(30.0 + 0.5 * i, 1) for i in range(a.runs)]
    params = {"phi": angles, "ncycles": [a.ncycles]}
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python "
          f"{platform.python_version()}, load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(f"deck: {DECK.relative_to(ROOT)}, {a.runs} runs (phi {angles[0]}..{angles[-1]}), ncycles {a.ncycles}, "
          f"{max(1, a.repeat)} round(s)")
    best: dict[str, tuple] = {}
    start = []

    def keep(mode, res):
        if mode not in best or res[0] < best[mode][0]:
            best[mode] = res
        print(f"  round: {mode:6s} {res[0]:7.2f} s", flush=True)

    with tempfile.TemporaryDirectory() as tmp:
        for k in range(max(1, a.repeat)):
            keep("serial", once(params, Path(tmp) / f"serial-{k}", workers=1))
            keep("pool2", once(params, Path(tmp) / f"pool2-{k}", workers=2))
            if not a.no_dask:
                import logging

                from dask.distributed import Client, LocalCluster

                c0 = time.perf_counter()
                with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=logging.CRITICAL) as cluster, Client(cluster) as client:
                    start.append(time.perf_counter() - c0)
                    keep("dask", once(params, Path(tmp) / f"dask-{k}", client=client))
                    batch._quiet_close(client, None)
    t1, s1, r1 = best["serial"]
    print(f"serial (pool of 1)   wall {t1:7.2f} s   sum of runs {s1:7.2f} s   per run {t1 / a.runs:.3f} s")
    t2, s2, r2 = best["pool2"]
    print(f"pool of 2 processes  wall {t2:7.2f} s   sum of runs {s2:7.2f} s   speed-up {t1 / t2:.2f}x   "
          f"overhead per run {(t2 * 2 - s2) / a.runs:.3f} s")
    assert [r["u.final"] for r in r1] == [r["u.final"] for r in r2]
    if "dask" in best:
        td, sd, rd = best["dask"]
        print(f"dask LocalCluster 2  wall {td:7.2f} s   sum of runs {sd:7.2f} s   speed-up {t1 / td:.2f}x   "
              f"overhead per run {(td * 2 - sd) / a.runs:.3f} s   (cluster start {min(start):.2f} s, not counted)")
        assert [r["u.final"] for r in rd] == [r["u.final"] for r in r1]
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
