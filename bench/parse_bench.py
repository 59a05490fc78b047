"""Parse-and-bind throughput of the command language (issue 2 target: >= 20 000 lines/s).

    python bench/parse_bench.py [--repeat 5] [--decks mixed brick polyhedron] [--no-shared]

1. the largest shared deck (`../shared/decks`, 48 KB): every line parsed and bound on
   its own, as `dec3d check` does (most of its commands are not implemented yet, which
   binding reports per line);
2. a generated 100 000-line deck of implemented commands, with comments, continuation
   lines, abbreviations and inline expressions, through `Session.load_text` (the path
   `dec3d run` takes before running anything).
   With ``--decks`` (issue 33) also, or instead, the 8 000-line `block create brick` and
   `block create polyhedron` decks of ``geometry_bench.py`` (a line of 72 numbers), parse and
   bind only (nothing is built).
Prints lines per second, median of the runs. Nothing is asserted: this is a benchmark.
"""
from __future__ import annotations

import argparse
import os
import platform
import random
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from dec3d.check import check_text  # noqa: E402
from dec3d.session import Session  # noqa: E402

sys.path.insert(0, str(ROOT / "bench"))
from geometry_bench import create_deck  # noqa: E402

_TEMPLATES = [
    "model gravity 0 0 {neg}  ; gravity",
    "model grav ({a},{b},{neg})",
    "model large-strain {onoff}",
    "model title 'stage {i}'",
    "[x{k} = {a} * 2.5 + math.sqrt({b})]",
    "model gravity 0 0 [-x{k}]",
    "model config dyn",
    "model gravity 0 0 ...\n    {neg}",
    "program echo {onoff}",
    "; a comment line {i}",
]


def generated_deck(n_lines: int, seed: int = 1) -> str:
    rng = random.Random(seed)
    out, count, defined = [], 0, set()
    while count < n_lines:
        t = rng.choice(_TEMPLATES)
        k = rng.randrange(50)
        if "[-x{k}]" in t and k not in defined:
            continue
        if "[x{k} =" in t:
            defined.add(k)
        line = t.format(neg=-rng.uniform(1, 10), a=rng.uniform(0, 1), b=rng.uniform(1, 2),
                        onoff=rng.choice(["on", "off"]), i=count, k=k)
        out.append(line)
        count += line.count("\n") + 1
    return "\n".join(out) + "\n"


def time_it(fn, repeat, cpu=None):
    """Median wall time of `repeat` runs (and their CPU times appended to `cpu`)."""
    times = []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        times.append(time.perf_counter() - t0)
        if cpu is not None:
            cpu.append(time.process_time() - c0)
    return statistics.median(times), times


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--lines", type=int, default=100_000)
    ap.add_argument("--decks", nargs="+", default=["mixed"], choices=["mixed", "brick", "polyhedron"],
                    help="generated decks: mixed commands (--lines of them), 8 000 brick or polyhedron lines")
    ap.add_argument("--no-shared", action="store_true", help="skip the largest shared deck")
    args = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}")
    if not args.no_shared:
        shared_deck(args.repeat)
    for kind in args.decks:
        gen = generated_deck(args.lines) if kind == "mixed" else create_deck(kind)
        n = gen.count("\n")
        Session(out_dir="/tmp").load_text(create_deck(kind, 2) if kind != "mixed" else "\n".join(gen.splitlines()[:50]) + "\n", "warm.dat")

        def load():
            Session(out_dir="/tmp").load_text(gen, "generated.dat")

        cpu: list[float] = []
        med, times = time_it(load, args.repeat, cpu)
        mc = statistics.median(cpu)
        print(f"generated deck {kind} ({n:,} lines, {len(gen) / 1e6:.1f} MB): {med:.3f} s, {n / med:,.0f} lines/s "
              f"(runs: {', '.join(f'{t:.3f}' for t in times)} s); CPU {mc:.3f} s, {n / mc:,.0f} lines/s per CPU s; "
              "target >= 100,000 lines/s")


def shared_deck(repeat: int) -> None:
    shared = Path(os.environ.get("DEC3D_SHARED", ROOT.parent / "shared")) / "decks"
    largest = max(shared.rglob("*.dat"), key=lambda p: p.stat().st_size if "legacy" not in str(p) else 0)
    text = largest.read_text(encoding="utf-8", errors="replace")
    n_big = text.count("\n")
    check_text(text, largest.name)          # warm-up: grammar load
    med, _ = time_it(lambda: check_text(text, largest.name), repeat)
    print(f"largest shared deck {largest.name} ({len(text) / 1024:.0f} KB, {n_big} lines): "
          f"{med * 1e3:.1f} ms, {n_big / med:,.0f} lines/s")


if __name__ == "__main__":
    main()
