"""Time per step of an n × n × n stack of unit cubes (``rigid_bench.py``'s scene) without and with
grouted cables: one vertical cable of ``--segments`` elements through each column of the stack, anchored
in the base (issue 28: 1 000 cable segments should add at most 20 % to a 10 000-block rigid step).

    python bench/cable_bench.py --n 10 --segments 10 --steps 200

Prints blocks, cable elements, seconds per step without and with cables, and the ratio. The cable step
runs every step on its own (it cuts the fused rigid kernel's batches to single steps), which is what
this measures. Not run by the tests with a time limit."""
from __future__ import annotations

import argparse
import io
import time


def scene(n: int, cables: bool, segments: int) -> list[str]:
    lines = ["model new", f"block create brick 0 {n} 0 {n} -1 0"]
    for i in range(n):
        for j in range(n):
            for k in range(n):
                lines.append(f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}")
    lines += ["block property density 2600", "block fix range position-z -1 0", "model gravity 0 0 -9.81",
              "block contact jmodel assign mohr",
              "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 34.38"]
    if cables:
        for i in range(n):
            for j in range(n):
                lines.append(f"structure cable create by-line {i + 0.5} {j + 0.5} -0.9 {i + 0.5} {j + 0.5} "
                             f"{n - 0.1} segments {segments}")
        lines.append("structure cable property young 200e9 cross-sectional-area 5e-4 grout-stiffness 1e8 "
                     "grout-cohesion 2e5 density 7800")
    return lines


def timed(n: int, cables: bool, segments: int, steps: int) -> tuple[float, int, int]:
    from dec3d.session import Session

    s = Session(stdout=io.StringIO())
    for line in scene(n, cables, segments):
        s.command(line)
    s.command("model cycle 5")
    t0 = time.perf_counter()
    s.command(f"model cycle {steps}")
    dt = (time.perf_counter() - t0) / steps
    segs = s.model.stores.get("cable_segments")
    return dt, s.model.blocks.n, segs.n if segs is not None else 0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--segments", type=int, default=10)
    ap.add_argument("--steps", type=int, default=200)
    a = ap.parse_args()
    t_plain, nb, _ = timed(a.n, False, a.segments, a.steps)
    t_cab, _, ns = timed(a.n, True, a.segments, a.steps)
    print(f"blocks {nb}  cable elements {ns}  s/step plain {t_plain:.3e}  with cables {t_cab:.3e}  "
          f"ratio {t_cab / t_plain:.3f}")


if __name__ == "__main__":
    main()
