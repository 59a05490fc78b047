"""FISH interpreter speed: a loop of simple arithmetic and assignments, in statements per second.

The function below runs N passes of a counted loop whose body holds four statements
(two float updates, an integer update, a comparison-driven `if`), so each pass counts
5 statements (the four plus the loop step). Prints the best of a few runs; no
assertions. Target (issue 13): >= 2e6 statements/s on the project machine.

    python bench/fish_bench.py [--n 400000] [--runs 3]
"""
from __future__ import annotations

import argparse
import io
import time
from pathlib import Path
import sys

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

DECK = """
fish define bench(n)
  local s = 0.0
  local x = 1.0
  local k = 0
  loop local i (1, n)
    s = s + x
    x = x * 1.000001
    k = k + 1
    if k > 1000 then
      k = 0
    endif
  endloop
  bench = s
end
"""
PER_PASS = 5


def main(argv=None) -> int:
    from dec3d.session import Session

    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=400_000)
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args(argv)
    s = Session(stdout=io.StringIO())
    s.command(DECK)
    fn = s.fish_rt.functions["bench"]
    best = float("inf")
    for _ in range(args.runs):
        t0 = time.perf_counter()
        fn.invoke((args.n,), None)
        best = min(best, time.perf_counter() - t0)
    rate = args.n * PER_PASS / best
    print(f"FISH loop: {args.n} passes x {PER_PASS} statements in {best:.3f} s (best of {args.runs}): "
          f"{rate / 1e6:.2f}e6 statements/s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
