"""What the joint-model and zone-model registries (``physics/jmodels.py``, ``physics/cmodels.py``)
share: a model property as its host file declares it, and the degree ↔ tangent conversions of
angle properties."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from dec3d.config import STIFFNESS_LIMIT


def tan_deg(v: float) -> float:
    return math.tan(math.radians(v))


def atan_deg(v: float) -> float:
    return math.degrees(math.atan(v))


@dataclass(frozen=True)
class ModelProp:
    """One property keyword of a model: its kernel column and how a user value becomes one."""
    name: str
    column: int
    doc: str
    units: str | None = None
    to_column: Callable[[float], float] = float
    from_column: Callable[[float], float] = float
    #: column value when nothing set it
    default: float = 0.0
    #: valid user values [lo, hi] (``lo_open``/``hi_open`` exclude the ends); None: unbounded
    lo: float | None = 0.0
    hi: float | None = None
    hi_open: bool = False
    lo_open: bool = False

    def __post_init__(self):
        if self.units == "Pa/m" and self.hi is None:
            # a stiffness: bounded above by what any deck can mean (dec3d.config.STIFFNESS_LIMIT)
            object.__setattr__(self, "hi", STIFFNESS_LIMIT)
