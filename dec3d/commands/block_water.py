"""Pore pressure in the joints: `block water …` (a water table) and `block contact apply
pore-pressure` (3DEC's words; physics ``dec3d.physics.water``).

Contact stresses are effective stresses, as in 3DEC: the pressure acts on the two faces of every
sub-contact as a force of its own, so the joint laws see σn′ = σn − p.
"""
from __future__ import annotations

import numpy as np

from ..errors import BindError, CommandError
from ..physics import water as _water
from ..physics.rigid import engine
from .registry import command
from .values import FLAG, POINT, VEC3, Num, P


def _check_water(call):
    a = call.args
    if (a["normal"] is not None or a["origin"] is not None) and not a["plane"]:
        key = "normal" if a["normal"] is not None else "origin"
        raise BindError(f"`{key}` belongs to `block water plane`", call.locations.get(key, call.location))
    given = [k for k in ("density", "plane", "clear", "list") if a[k] not in (None, False)]
    if not given:
        raise BindError("`block water` needs one of density, plane, clear, list", call.location)
    if a["plane"] and (a["normal"] is None or a["origin"] is None):
        raise BindError("`block water plane` needs `normal nx ny nz` and `origin x y z`",
                        call.locations.get("plane", call.location))


@command("block water",
         keywords=[P("density", Num(lo=0), "fluid density ρw", units="kg/m³"),
                   P("plane", FLAG, "define the water table as a plane (with `normal` and `origin`)", bare=True),
                   P("normal", VEC3, "normal of the water-table plane"),
                   P("origin", POINT, "a point on the water-table plane", units="m"),
                   P("clear", FLAG, "delete the water table (the pressures go)", bare=True),
                   P("list", FLAG, "print the water-table definition", bare=True)],
         check=_check_water,
         doc="A pore-pressure field in the joints from a water table: p = ρw |g| h below the table, 0 above.",
         details="h is the distance from a sub-contact's point up to the table along gravity (the pressure "
                 "gradient follows the gravity vector, as in 3DEC), so `model gravity` and `block water density` "
                 "must be given for pressures to arise; a later change of either is taken up at the next cycle. "
                 "The pressure acts on both faces of every sub-contact as a force p·A along the contact normal; "
                 "the forces the joint models keep are effective (σn′ = σn − p), as 3DEC's contact stresses are. "
                 "Pressures given with `block contact apply pore-pressure` are added. The table applies to the "
                 "joints only (zone pore pressures are not modelled). `clear` deletes the table.",
         examples=["block water density 1000", "block water plane normal 0.17 0 0.98 origin 50 50 90",
                   "block water clear"])
def block_water(session, call):
    a = call.args
    m = session.model
    w = _water.water_settings(m)
    if a["list"]:
        session.write(_water.describe(m))
    changed = False
    if a["density"] is not None:
        w["density"] = float(a["density"])
        changed = True
    if a["clear"]:
        w["plane"] = None
        changed = True
    if a["plane"] and not np.linalg.norm(np.asarray(a["normal"], float)) > 0.0:
        raise CommandError("the water table's normal is the zero vector", call.locations.get("normal", call.location))
    if a["plane"]:
        w["plane"] = [float(x) for x in a["normal"]] + [float(x) for x in a["origin"]]
        changed = True
    if changed and m.blocks.n > 1:
        eng = engine(m)
        eng.ensure_contacts()
        _water.refresh(eng)


def _check_apply(call):
    if call.args["pore_pressure"] is None:
        raise BindError("`block contact apply` needs `pore-pressure <p>`", call.location)


@command("block contact apply",
         keywords=[P("pore-pressure", Num(), "pore pressure added to the sub-contacts in range", units="Pa")],
         range="contact", check=_check_apply,
         doc="Add a fluid pressure to the joint sub-contacts of the contacts in range (rigid or zoned blocks).",
         details="Each command adds its value to what the contacts had (3DEC: apply the negative value to remove "
                 "it); the pressure stays until changed or the contact is deleted, and it is added to the water "
                 "table's (`block water`). Positive pressures push the blocks apart: a force p·A along the "
                 "contact normal on both faces of each sub-contact, while the joint model works on the effective "
                 "normal stress σn′ = σn − p. Without a range every contact takes it.",
         examples=["block contact apply pore-pressure 1e5", "block contact apply pore-pressure 2e5 range group 'crack'"])
def contact_apply(session, call):
    m = session.model
    if m.blocks.n < 2:
        raise CommandError("`block contact apply`: there are no contacts (fewer than two blocks)", call.location)
    eng = engine(m)
    eng.ensure_contacts()
    mask = session.range_mask(call, "contact")
    if not mask.any():
        raise CommandError("`block contact apply`: no contact in range", call.location)
    p = float(call.args["pore_pressure"])
    cs = eng.contacts
    cs["pp_apply"][mask] += p
    w = _water.water_settings(m)
    w["applied"] = int(w.get("applied", 0)) + 1
    _water.refresh(eng)
