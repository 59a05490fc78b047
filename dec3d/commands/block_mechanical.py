"""`block mechanical damping`, `block fix|free`, `block initialize`: motion settings and conditions."""
from __future__ import annotations

import numpy as np

from ..physics.rigid import engine, mech
from .registry import command
from .values import FLAG, Choice, Num, Nums, P


_DAMPING_NOT_YET = ("global", "combined", "rayleigh", "maxwell")


def _check_damping(call):
    from ..errors import NotSupportedError

    if call.args["mode"] in _DAMPING_NOT_YET:
        raise NotSupportedError(f"`block mechanical damping {call.args['mode']}` is not supported yet",
                                call.locations.get("mode", call.location), hint="implemented: local [α], none")
    if len(call.args["alpha"]) > 1:
        from ..errors import BindError

        raise BindError("local damping takes one coefficient", call.locations.get("alpha", call.location))


@command("block mechanical damping",
         positional=[P("mode", Choice(("local", "global", "combined", "none", "rayleigh", "maxwell")),
                       "damping form", required=True),
                     P("alpha", Nums(0, 6), "local damping coefficient α (rayleigh and maxwell take more values)",
                       default=())],
         check=_check_damping,
         doc="Set the mechanical damping (default: local, α = 0.8).",
         details="`none` switches damping off. `global` (adaptive), `combined`, `rayleigh` and `maxwell` are "
                 "known and not supported yet.",
         examples=["block mechanical damping local 0.8", "block mechanical damping none"])
def damping(session, call):
    alpha = call.args["alpha"][0] if call.args["alpha"] else 0.8
    if not 0.0 <= alpha:
        from ..errors import BindError

        raise BindError("the damping coefficient must be ≥ 0", call.locations.get("alpha", call.location))
    s = mech(session.model)
    s["damping"] = call.args["mode"]
    if call.args["mode"] == "local":
        s["alpha"] = float(alpha)


_BITS = {"velocity": 0b000111, "velocity-x": 1, "velocity-y": 2, "velocity-z": 4,
         "rotation": 0b111000, "rotation-x": 8, "rotation-y": 16, "rotation-z": 32}
_FIXKW = [P(k, FLAG, f"the {k} component(s)", bare=True) for k in _BITS]


def _bits(call):
    bits = 0
    for k, v in _BITS.items():
        if call.args[k.replace("-", "_")]:
            bits |= v
    return bits or 0b111111


@command("block fix", keywords=_FIXKW, range="block",
         doc="Fix velocity and/or rotation components of the blocks in range (all six when none is named).",
         examples=["block fix", "block fix velocity-z rotation range position-z -1 0"])
def block_fix(session, call):
    mask = session.range_mask(call, "block")
    b = session.model.blocks
    engine(session.model)
    bits = _bits(call)
    b["fixity"][mask] |= np.uint8(bits)
    for i in range(3):
        if bits & (1 << i):
            b["velocity"][mask, i] = 0.0
        if bits & (8 << i):
            b["spin"][mask, i] = 0.0


@command("block free", keywords=_FIXKW, range="block",
         doc="Free velocity and/or rotation components of the blocks in range (all six when none is named).",
         examples=["block free", "block free rotation"])
def block_free(session, call):
    mask = session.range_mask(call, "block")
    b = session.model.blocks
    b["fixity"][mask] &= np.uint8(~_bits(call) & 0xFF)


@command("block initialize", keywords=[P(k, Num(), f"initial {k}", units="m/s" if k.startswith("v") else "rad/s")
                                       for k in ("velocity-x", "velocity-y", "velocity-z",
                                                 "rvelocity-x", "rvelocity-y", "rvelocity-z")], range="block",
         doc="Set the velocity or angular velocity of the blocks in range.",
         examples=["block initialize velocity-z -1", "block initialize rvelocity-z 2"])
def block_initialize(session, call):
    mask = session.range_mask(call, "block")
    b = session.model.blocks
    for i, ax in enumerate("xyz"):
        if call.args[f"velocity_{ax}"] is not None:
            b["velocity"][mask, i] = call.args[f"velocity_{ax}"]
        if call.args[f"rvelocity_{ax}"] is not None:
            b["spin"][mask, i] = call.args[f"rvelocity_{ax}"]


@command("block mechanical timestep", positional=[P("dt", Num(lo=0), "fixed time step; 0 returns to Eq. (87)",
                                                    required=True, units="s")],
         doc="Force the time step (0: automatic, Eq. 87 with frac 0.1).",
         examples=["block mechanical timestep 1e-4", "block mechanical timestep 0"])
def timestep(session, call):
    mech(session.model)["timestep"] = float(call.args["dt"]) or None
