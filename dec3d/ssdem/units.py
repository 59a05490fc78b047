"""Unit systems accepted on input; everything inside is SI (N, m, Pa).

A unit system is a (force, length) pair; stresses are force/length^2, unit weights
and spring constants force/length^3.  Reports are written back in the input's units.
"""
from __future__ import annotations

SYSTEMS = {
    "N-m": (1.0, 1.0),
    "kN-m": (1000.0, 1.0),
    "lb-ft": (4.4482216152605, 0.3048),
}


def factors(name: str) -> dict[str, float]:
    """Multipliers from the named system to SI for each kind of quantity."""
    f, l = SYSTEMS[name]
    return {"length": l, "force": f / l, "stress": f / l ** 2, "unit_weight": f / l ** 3,
            "stiffness": f / l ** 3, "moment": f, "angle": 1.0, "none": 1.0}


def labels(name: str) -> dict[str, str]:
    force, length = name.split("-")
    return {"length": length, "force": f"{force}/{length}", "stress": f"{force}/{length}^2",
            "unit_weight": f"{force}/{length}^3", "stiffness": f"{force}/{length}^3",
            "moment": f"{force}*{length}/{length}"}
