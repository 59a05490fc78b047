"""Time per step of an n × n × n stack of unit cubes (``rigid_bench.py``'s scene) without and with
grouted cables: one vertical cable of ``--segments`` elements through each column of the stack, anchored
in the base (issue 28: 1 000 cable segments should add at most 20 % to a 10 000-block rigid step).
``--kind hybrid`` makes them hybrid bolts (a dowel at every joint a bolt crosses: n per column),
``--kind beam`` beams linked to the blocks they lie in (3-D Euler-Bernoulli, 6 DOF per node).

    python bench/cable_bench.py --n 10 --segments 10 --steps 200 [--kind cable|hybrid|beam]

Prints blocks, cable elements, seconds per step without and with cables, and the ratio. The cable step
runs every step on its own (it cuts the fused rigid kernel's batches to single steps), which is what
this measures. Not run by the tests with a time limit."""
from __future__ import annotations

import argparse
import io
import time


def scene(n: int, cables: bool, segments: int, kind: str = "cable") -> list[str]:
    lines = ["model new", f"block create brick 0 {n} 0 {n} -1 0"]
    for i in range(n):
        for j in range(n):
            for k in range(n):
                lines.append(f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}")
    lines += ["block property density 2600", "block fix range position-z -1 0", "model gravity 0 0 -9.81",
              "block contact jmodel assign mohr",
              "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 34.38"]
    if cables:
        word = {"cable": "cable", "hybrid": "hybrid", "beam": "beam"}[kind]
        for i in range(n):
            for j in range(n):
                lines.append(f"structure {word} create by-line {i + 0.5} {j + 0.5} -0.9 {i + 0.5} {j + 0.5} "
                             f"{n - 0.1} segments {segments}")
        if kind == "beam":
            lines.append("structure beam property young 200e9 poisson 0.3 cross-sectional-area 5e-4 moi-y 2e-8 "
                         "moi-z 2e-8 moi-polar 4e-8 density 7800")
        else:
            lines.append(f"structure {word} property young 200e9 cross-sectional-area 5e-4 grout-stiffness 1e8 "
                         "grout-cohesion 2e5 density 7800")
        if kind == "hybrid":
            lines.append("structure hybrid property dowel-stiffness 5e7 dowel-yield 1e5")
    return lines


def timed(n: int, cables: bool, segments: int, steps: int, kind: str = "cable") -> tuple[float, int, int]:
    from dec3d.session import Session

    s = Session(stdout=io.StringIO())
    for line in scene(n, cables, segments, kind):
        s.command(line)
    s.command("model cycle 5")
    t0 = time.perf_counter()
    s.command(f"model cycle {steps}")
    dt = (time.perf_counter() - t0) / steps
    segs = s.model.stores.get("beam_elements" if kind == "beam" else "cable_segments")
    return dt, s.model.blocks.n, segs.n if segs is not None else 0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--segments", type=int, default=10)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--kind", choices=("cable", "hybrid", "beam"), default="cable")
    a = ap.parse_args()
    t_plain, nb, _ = timed(a.n, False, a.segments, a.steps)
    t_cab, _, ns = timed(a.n, True, a.segments, a.steps, a.kind)
    print(f"blocks {nb}  {a.kind} elements {ns}  s/step plain {t_plain:.3e}  with {a.kind}s {t_cab:.3e}  "
          f"ratio {t_cab / t_plain:.3f}")


if __name__ == "__main__":
    main()
