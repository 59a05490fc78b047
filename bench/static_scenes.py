"""Steps and wall time to a static answer (`model solve ratio …`) on small static scenes, per
density-scaling and damping setting: the table "model solve ratio 1e-5 on other static scenes"
of bench/README.md.

    python bench/static_scenes.py [--ratio 1e-5] [--scenes wall,column20,...] [--setups default,...]

Scenes: the masonry-wall example's settling (examples/rigid/masonry_wall.dat up to its
`model solve`), a column of twenty 0.5 × 0.5 × 1 m blocks, the R2-style wedge at φ = 40°, a
10 × 10 × 5 m block on a 40° slope at φ = 45° (gravity tilted), a stack of ten 1 m cubes with the
elastic joint model (R5-style), a 0.1 m cube on a 1 m cube, three 1 m cubes with the top two
joined. Each run is `model solve ratio <ratio> cycles 20000` in a fresh session; a row prints the
steps taken, whether it converged, the wall and CPU seconds and the first three free blocks' final
centroid z (the static answers agree across settings to about 1e-7 m; a frictional slide is
path-dependent). Kernels are compiled first on a small scene, so times are warm.
"""
from __future__ import annotations

import argparse
import io
import json
import os
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _lines(cmds: list) -> str:
    return "\n".join(cmds) + "\n"


def column(n: int, w: float = 0.5) -> str:
    """n blocks w × w × 1 m stacked on a fixed base, Coulomb joints (φ 35°)."""
    cmds = ["model new", f"block create brick 0 {w} 0 {w} -1 0"]
    cmds += [f"block create brick 0 {w} 0 {w} {k} {k + 1}" for k in range(n)]
    cmds += ["block property density 2500", "model gravity 0 0 -9.81", "block fix range position-z -1 0",
             "block contact jmodel assign mohr",
             "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 35"]
    return _lines(cmds)


def _wall() -> str:
    text = open(os.path.join(ROOT, "examples", "rigid", "masonry_wall.dat"), encoding="utf-8").read()
    head = text.split("model solve")[0]
    return _lines([ln for ln in head.splitlines() if not ln.strip().startswith("model title")])


SCENES = {
    "wall": _wall,
    "column20": lambda: column(20),
    "wedge": lambda: _lines([
        "model new", "block create brick -5 5 -5 5 -5 5",
        "block cut joint-set dip 40 dip-direction 130 origin 0 0 0",
        "block cut joint-set dip 60 dip-direction 220 origin 0 0 0",
        "block property density 2000", "model gravity 0 0 -10", "block contact jmodel assign mohr",
        "block contact material-table default property stiffness-normal 10e6 stiffness-shear 10e6 friction 40",
        "block fix range id-list 1 2 3"]),
    "incline": lambda: _lines([
        "model new", "block create brick -5 40 -5 15 -2 0", "block create brick 0 10 0 10 0 5",
        "block property density 2000", "model gravity 6.4279 0 -7.6604", "block contact jmodel assign mohr",
        "block contact material-table default property stiffness-normal 10e6 stiffness-shear 10e6 friction 45",
        "block fix range position-z -2 0"]),
    "R5": lambda: _lines(
        ["model new"] + [f"block create brick 0 1 0 1 {k} {k + 1}" for k in range(10)] +
        ["block property density 2500", "model gravity 0 0 -10", "block contact jmodel assign elastic",
         "block contact material-table default property stiffness-normal 10e9 stiffness-shear 10e9",
         "block fix range position-z 0 1"]),
    "mix": lambda: _lines([
        "model new", "block create brick -1 2 -1 2 -1 0", "block create brick 0 1 0 1 0 1",
        "block create brick 0.45 0.55 0.45 0.55 1 1.1", "block property density 2000", "model gravity 0 0 -10",
        "block contact jmodel assign mohr",
        "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 35",
        "block fix range position-z -1 0"]),
    "join3": lambda: column(3, 1.0).replace("block contact jmodel",
                                            "block join range position-z 1 3\nblock contact jmodel"),
}

SETUPS = {
    "eq87": "block mechanical mass-scale on",
    "default": "",
    "default-combined": "block mechanical damping combined",
    "default-global": "block mechanical damping global",
    "body-local": "block mechanical mass-scale body",
    "body-combined": "block mechanical mass-scale body\nblock mechanical damping combined",
    "body-global": "block mechanical mass-scale body\nblock mechanical damping global",
}


def run(scene: str, setup: str, ratio: float) -> dict:
    """One `model solve` of ``scene`` with ``setup`` in a fresh session."""
    import numpy as np

    import dec3d

    with tempfile.TemporaryDirectory() as d:
        out = io.StringIO()
        s = dec3d.Session(out_dir=d, stdout=out)
        s.command(SCENES[scene]() + SETUPS[setup] + "\n")
        t0 = time.perf_counter()
        c0 = time.process_time()
        s.command(f"model solve ratio {ratio} cycles 20000")
        wall = time.perf_counter() - t0
        cpu = time.process_time() - c0
        b = s.model.blocks
        free = b["fixity"] == 0
        last = [ln for ln in out.getvalue().splitlines() if ln.startswith("model solve")][-1]
        return dict(scene=scene, setup=setup, steps=int(s.model.step), converged=last.startswith("model solve: converged"),
                    wall=round(wall, 4), cpu=round(cpu, 4),
                    z=[round(float(x), 7) for x in b["centroid"][free][:, 2][:3]])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ratio", type=float, default=1e-5)
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated, from: " + ", ".join(SCENES))
    ap.add_argument("--setups", default=",".join(SETUPS), help="comma-separated, from: " + ", ".join(SETUPS))
    ap.add_argument("--json", action="store_true", help="one JSON object per run instead of the table")
    a = ap.parse_args(argv)
    if ROOT not in sys.path:
        sys.path.insert(0, ROOT)
    scenes, setups = a.scenes.split(","), a.setups.split(",")
    for name in scenes + setups:
        if name not in SCENES and name not in SETUPS:
            ap.error(f"unknown scene or setup {name!r}")
    run("mix", "eq87", 1e-3)                # (compiles the kernels: the times below are warm)
    rows = {}
    for sc in scenes:
        for st in setups:
            r = run(sc, st, a.ratio)
            rows[sc, st] = r
            if a.json:
                print(json.dumps(r), flush=True)
    if not a.json:
        print(f"steps of `model solve ratio {a.ratio} cycles 20000` ('!': not converged)")
        print(f"{'scene':>10} " + " ".join(f"{st:>16}" for st in setups))
        for sc in scenes:
            cells = [f"{rows[sc, st]['steps']}{'' if rows[sc, st]['converged'] else '!'}" for st in setups]
            print(f"{sc:>10} " + " ".join(f"{c:>16}" for c in cells))


if __name__ == "__main__":
    main()
