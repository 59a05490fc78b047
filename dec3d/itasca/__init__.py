"""An ``itasca``-compatible Python API on dec3d: the scripts 3DEC users write run on dec3d.

    import dec3d.itasca as it          # or `import itasca as it` (docs/python.md)
    it.command('''
    model new
    block create brick 0 1 0 1 0 1
    ''')
    it.cycle(100)
    for b in it.block.list():
        print(b.id(), b.pos())

Functions act on the *current* ``dec3d.Model`` (``it.current()``; made on first use; ``it.bind(m)`` or
``with m.bound():`` chooses another), so several models can live in one interpreter. Names follow
Itasca's Python documentation (``itasca.command``, ``itasca.cycle``, ``itasca.block``, ``itasca.blockarray``
...); where 3DEC's are not documented, FLAC3D's pattern is used and the docstring says so. Side-by-side
table: docs/python.md.
"""
from __future__ import annotations

import numpy as np

from ._bind import CallbackError, ItascaError, Model, StaleError, bind, current
from .callbacks import remove_callback, set_callback
from . import fish  # noqa: E402
from . import blockarray, contactarray, gridpointarray, zonearray  # noqa: E402
from . import block  # noqa: E402
from . import structure  # noqa: E402


def command(text: str) -> None:
    """Run 3DEC commands (one line, or several in a triple-quoted string; `...`/`&` continuations as in
    decks). A failing command raises ``ItascaError`` with dec3d's file:line:column report."""
    current().command(text)


def cycle(n: int) -> None:
    """Take ``n`` mechanical steps (`model cycle n`)."""
    current().cycle(n)


def timestep() -> float:
    """The time step of the last cycle [s] (0 before the model has cycled)."""
    from ._objects import fish_call

    return float(fish_call(current(), "mech.timestep"))


def mech_age() -> float:
    """The model's mechanical time [s]."""
    return float(current().session.model.time)


def step() -> int:
    """The model's step count."""
    return int(current().session.model.step)


def gravity() -> np.ndarray:
    """Gravity [m/s²], shape (3,)."""
    return np.array(current().session.model.settings.gravity, dtype=float)


def set_gravity(g) -> None:
    """Set gravity [m/s²] (three finite numbers; as `model gravity gx gy gz`)."""
    from ._objects import vec3

    a = vec3(g, "set_gravity")
    current().command("model gravity " + " ".join(repr(float(c)) for c in a))


def threads() -> int:
    """Threads the parallel kernels use."""
    from ..config import threads as t

    return t()


def set_threads(n: int) -> int:
    """Use ``n`` threads in the parallel kernels (1 … the machine's); ValueError otherwise."""
    from ..config import set_threads as st

    return st(n)


def deterministic() -> bool:
    """Always True: every dec3d kernel gives bit-identical results whatever the thread count."""
    return True


def set_deterministic(on: bool = True) -> None:
    """Accepted for Itasca compatibility; dec3d is always deterministic, so nothing changes."""


def dim() -> int:
    """The model's dimension (3)."""
    return 3


def version() -> str:
    """dec3d's version."""
    import sys

    return sys.modules["dec3d"].__version__


__all__ = ["command", "cycle", "timestep", "mech_age", "step", "gravity", "set_gravity", "threads", "set_threads",
           "deterministic", "set_deterministic", "dim", "version", "fish", "set_callback", "remove_callback",
           "block", "blockarray", "contactarray", "gridpointarray", "zonearray", "structure", "Model", "bind",
           "current", "ItascaError", "StaleError", "CallbackError"]
