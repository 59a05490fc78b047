"""`dec3d plot FILE --item ITEM … --out DIR`: the pictures of a run after it, from its files."""
from __future__ import annotations

import sys
from pathlib import Path


def main(args, restore=None) -> int:
    from .items import UnknownItem, item_from_name
    from .render import render
    from .scene import scene_from_files

    try:
        items = [item_from_name(n) for n in (args.item or ["displacement"])]
    except UnknownItem as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    try:
        scene = scene_from_files(args.file, restore)
    except (OSError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out = Path(args.out or ".")
    out.mkdir(parents=True, exist_ok=True)
    stem = Path(args.file).stem
    size = tuple(args.size) if args.size else (800, 600)
    for it in items:
        if it.kind == "chart":
            continue
        name = it.title().replace(" ", "_")
        path = out / f"{stem}_{name}.png"
        _, notices = render(scene, [it], path, title=f"{stem}: {it.title()}", background=args.background, size=size)
        for n in notices:
            print(f"notice: {n}", file=sys.stderr)
        print(path)
    return 0


def add_parser(sub):
    p = sub.add_parser("plot", help="pictures (PNG) of a run from its .pvd/.vtu files or a save, after the run")
    p.add_argument("file", help="a .pvd (its last time is drawn), a .vtu or a .sav")
    p.add_argument("--item", action="append", metavar="ITEM",
                   help="what to draw (repeat for more pictures): blocks, displacement[-x|-y|-z], velocity, "
                        "stress-xx … stress-yz, stress-max, stress-min, stress-mean, von-mises, state, "
                        "normal-stress, shear-stress, slip, opening, pressure, displacement-vector, "
                        "velocity-vector, cable (default: displacement)")
    p.add_argument("--out", help="folder for the pictures (default: the current folder)")
    p.add_argument("--background", default="white")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), help="pixels (default 800 600)")
    return p
