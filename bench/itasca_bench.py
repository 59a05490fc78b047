"""dec3d.itasca: the cost of the Python API on an n × n × n stack of unit cubes (as rigid_bench.py).

Prints, per size: building the stack through it.command (one multi-line string), reading every block's
centroid through the objects (it.block.list() + Block.pos()) and through it.blockarray.pos() (a view),
every contact's normal force through the objects and through it.contactarray.force_norm(), and the cost
per step of a Python callback at position 0 (cycle with and without it).

    python bench/itasca_bench.py --n 6 10 --steps 200
"""
from __future__ import annotations

import argparse
import time


def stack(n: int) -> str:
    lines = ["model new", f"block create brick 0 {n} 0 {n} -1 0"]
    lines += [f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}"
              for k in range(n) for j in range(n) for i in range(n)]
    lines += ["block property density 2600", "block contact jmodel assign mohr",
              "block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 34.38",
              "model gravity 0 0 -9.81", "block mechanical damping local 0.8", "block fix range position-z -1 0"]
    return "\n".join(lines)


def best(fn, repeat=3):
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return min(out)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, nargs="+", default=[6, 10])
    ap.add_argument("--steps", type=int, default=200)
    a = ap.parse_args(argv)
    import dec3d
    import dec3d.itasca as it

    for n in a.n:
        m = dec3d.Model()
        with m.bound():
            t = time.perf_counter()
            it.command(stack(n))
            build = time.perf_counter() - t
            it.cycle(10)                                  # contacts detected, kernels warm
            nb, nc = it.block.count(), it.block.contact.count()
            obj = best(lambda: [b.pos() for b in it.block.list()])
            arr = best(lambda: it.blockarray.pos().copy())
            cobj = best(lambda: [c.force_norm() for c in it.block.contact.list()])
            carr = best(lambda: it.contactarray.force_norm())
            plain = best(lambda: it.cycle(a.steps), 1) / a.steps
            calls = [0]

            def cb():
                calls[0] += 1
            it.set_callback(cb, 0)
            withcb = best(lambda: it.cycle(a.steps), 1) / a.steps
            it.remove_callback(cb)
        print(f"n={n}: {nb} blocks, {nc} contacts; build by it.command {build:.2f} s")
        print(f"  centroids: objects {obj * 1e3:.2f} ms ({obj / nb * 1e6:.2f} µs/block), blockarray {arr * 1e3:.3f} ms")
        print(f"  contact normal forces: objects {cobj * 1e3:.2f} ms ({cobj / max(nc, 1) * 1e6:.2f} µs/contact), "
              f"contactarray {carr * 1e3:.3f} ms")
        print(f"  cycle: {plain * 1e3:.3f} ms/step, with a Python callback at position 0 {withcb * 1e3:.3f} ms/step")


if __name__ == "__main__":
    main()
