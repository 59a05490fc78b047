"""`block gridpoint fix` / `block gridpoint free`: hold gridpoint velocity components where they are.

FLAC3D's pattern (`zone gridpoint fix velocity-x`), which 3DEC decks also use: a fixed component
keeps its present velocity (zero after `block gridpoint initialize velocity 0 0 0`), or the value
given. It is the same condition as `block gridpoint apply velocity…` (one store of held components),
so `free` undoes either.
"""
from __future__ import annotations

import numpy as np

from ..errors import BindError
from ..physics.dynamic import remove_timefns
from .block_gridpoint import _gridpoints
from .registry import command
from .values import FLAG, Nums, P

_AX = ("x", "y", "z")
_KEYS = ("velocity", "velocity_x", "velocity_y", "velocity_z")


def _components(call) -> list[int]:
    a = call.args
    if not any(a[k] is not None and a[k] is not False for k in _KEYS):
        return [0, 1, 2]
    comps = set()
    if a["velocity"] is not None and a["velocity"] is not False:
        comps.update((0, 1, 2))
    for i, ax in enumerate(_AX):
        if a[f"velocity_{ax}"] is not None and a[f"velocity_{ax}"] is not False:
            comps.add(i)
    return sorted(comps)


@command("block gridpoint fix",
         keywords=[P("velocity", Nums(1, 3, counts=(1, 3)), "all three components (optionally the values held)",
                     units="m/s", bare=()),
                   *[P(f"velocity-{a}", Nums(1, 1), f"the {a} component (optionally the value held)", units="m/s",
                     bare=())
                     for a in _AX]],
         range="gridpoint",
         doc="Hold velocity components of the gridpoints in range (all three when no keyword is given) at "
             "their present value, or at the value given.",
         details="The held components are the ones `block gridpoint apply velocity…` sets: `block gridpoint "
                 "free` or `block gridpoint apply-remove velocity` release them. A held component ignores "
                 "forces; its displacement grows by the held velocity times the time step.",
         examples=["block gridpoint fix range position-z 0", "block gridpoint fix velocity-z range group 'base'",
                   "block gridpoint fix velocity-x 0 range position-x 0",
                   "block gridpoint fix velocity 0 0 0 range group 'foundation'"])
def block_gridpoint_fix(session, call):
    a = call.args
    rows = _gridpoints(session, call, "block gridpoint fix")
    m = session.model
    v = m.vertices
    given = {}
    if a["velocity"] is not None and len(a["velocity"]):
        vals = np.asarray(a["velocity"], float).reshape(-1)
        for i in range(3):
            given[i] = float(vals[i] if vals.size == 3 else vals[0])
    for i, ax in enumerate(_AX):
        val = a[f"velocity_{ax}"]
        if val is not None and len(val):
            given[i] = float(np.asarray(val, float).reshape(-1)[0])
    for i, x in given.items():
        if not np.isfinite(x):
            raise BindError("a held velocity must be finite", call.location)
    for i in _components(call):
        remove_timefns(m, "gridpoint", rows, {("velocity", i)})
        v["vapp"][rows, i] = given[i] if i in given else v["velocity"][rows, i]
        v["apply_fix"][rows] |= np.uint8(1 << i)


@command("block gridpoint free",
         keywords=[P("velocity", FLAG, "all three components", bare=True),
                   *[P(f"velocity-{a}", FLAG, f"the {a} component", bare=True) for a in _AX]],
         range="gridpoint",
         doc="Release held velocity components of the gridpoints in range (all three when no keyword is given).",
         examples=["block gridpoint free range position-z 0", "block gridpoint free velocity-x range group 'side'"])
def block_gridpoint_free(session, call):
    rows = _gridpoints(session, call, "block gridpoint free")
    m = session.model
    v = m.vertices
    for i in _components(call):
        remove_timefns(m, "gridpoint", rows, {("velocity", i)})
        v["apply_fix"][rows] &= np.uint8(~(1 << i) & 0xFF)
        v["vapp"][rows, i] = 0.0
