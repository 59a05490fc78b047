"""A small masonry arch as 3DEC command text, the way public Python drivers (compas_3dec, SAFEGO) write
their models: voussoirs as `block create prism` lines, then groups, joint properties, gravity, supports.

A segmental ring (intrados radius 1 m, extrados 1.4 m, 0.5 m deep) from 20° to 160°, cut into ``n``
voussoirs; the first and last are fixed (the abutments), the ones between carry their weight to them.
"""
from __future__ import annotations

import math


def arch_commands(n: int = 7, r1: float = 1.0, r2: float = 1.4, depth: float = 0.5, a0: float = 20.0,
                  a1: float = 160.0, density: float = 2000.0) -> str:
    lines = ["model new", "model large-strain off"]
    for i in range(n):
        a = math.radians(a0 + (a1 - a0) * i / n)
        b = math.radians(a0 + (a1 - a0) * (i + 1) / n)
        quad = [(r1 * math.cos(a), r1 * math.sin(a)), (r2 * math.cos(a), r2 * math.sin(a)),
                (r2 * math.cos(b), r2 * math.sin(b)), (r1 * math.cos(b), r1 * math.sin(b))]
        f1 = " ".join(f"{x:.12g} 0 {z:.12g}" for x, z in quad)
        f2 = " ".join(f"{x:.12g} {depth:g} {z:.12g}" for x, z in quad)
        group = "abutment" if i in (0, n - 1) else "voussoir"
        lines.append(f"block create prism face-1 {f1} face-2 {f2} group '{group}'")
    lines += [
        f"block property density {density:g}",
        "block contact jmodel assign mohr",
        "block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 40",
        "model gravity 0 0 -9.81",
        "block fix range group 'abutment'",
        "block mechanical damping local 0.8",
    ]
    return "\n".join(lines) + "\n"
