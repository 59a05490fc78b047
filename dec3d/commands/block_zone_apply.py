"""`block zone apply` and `block zone apply-remove`: conditions on the volume of zones.

The keywords are those of Itasca's `zone apply` page (FLAC3D 7, in the 3DEC 7 documentation set:
docs.itascacg.com/3dec700/flac3d/zone/doc/manual/zone_manual/zone_commands/cmd_zone.apply.html): `force`,
`force-x|-y|-z` (a body force per unit volume), `source` (a heat source per unit volume, thermal option) and
`well` (a fluid source). 3DEC 7 lists a `block zone apply` command; its own page was not found in the
reference material, so dec3d takes FLAC3D's keywords. The body force is stored per zone (``zones.fbody``,
``dec3d.model.zones``) and loads the gridpoints every step (``dec3d.physics.zone_loads``); `source` and `well`
need physics dec3d lacks and are refused where they are written.
"""
from __future__ import annotations

import numpy as np

from ..errors import BindError, NotSupportedError
from ..model.zones import body_force_field, zone_stores
from .registry import command
from .values import FLAG, Num, Nums, P

_AX = ("x", "y", "z")
_FORCE = ("force", "force_x", "force_y", "force_z")
#: keyword -> why dec3d refuses it
_LACKING = {"source": "a heat source needs thermal analysis, which dec3d does not have (`model configure "
                      "thermal`, `block zone thermal` are not supported)",
            "well": "a fluid source in zones needs fluid flow through the zones; dec3d flows water through the "
                    "joints only (`block fluid`, `flowknot`), its zones carry no pore pressure"}


def _check(call):
    a = call.args
    for k, why in _LACKING.items():
        if a[k] is not None:
            raise NotSupportedError(f"`block zone apply {k}` is not supported: {why}",
                                    call.locations.get(k, call.location))
    given = [k for k in _FORCE if a[k] is not None]
    if not given:
        raise BindError("`block zone apply` needs force <fx fy fz> or force-x|-y|-z <f> (a body force per unit "
                        "volume)", call.location)
    if a["force"] is not None and len(given) > 1:
        k = next(k for k in given if k != "force")
        raise BindError("give the body force as `force <fx fy fz>` or as components, not both "
                        f"(`{k.replace('_', '-')}`)", call.locations.get(k, call.location))


def _rows(session, call, what: str) -> np.ndarray:
    """Rows of the zones in range; a warning naming file:line when there are none."""
    m = session.model
    zs = zone_stores(m)
    rows = np.flatnonzero(session.range_mask(call, "zone"))
    if not len(rows) and (call.range is None or zs.n == 0):     # (an empty range has warned already)
        session.write(f"warning: {call.location}: `{what}` selected no zone"
                      + (" (there are no zones: `block zone generate` makes them)" if zs.n == 0 else ""))
    return rows


@command("block zone apply",
         keywords=[P("force", Nums(3, 3), "fx fy fz: the body force per unit volume", units="N/m³"),
                   *[P(f"force-{a}", Num(), f"the {a} component of the body force per unit volume", units="N/m³")
                     for a in _AX],
                   P("source", Num(), "heat source per unit volume (thermal option: not in dec3d)", units="W/m³"),
                   P("well", Num(), "fluid source per unit volume (fluid flow in zones: not in dec3d)")],
         range="zone", check=_check,
         doc="Apply a body force per unit volume to the zones in range (located by centroid).",
         details="`force fx fy fz` sets all three components, `force-x|-y|-z f` one; a zone's new value "
                 "replaces the one it had (Itasca: conditions that conflict with existing ones overwrite them). "
                 "Every step the force loads the zone's gridpoints: f V / 4 to each corner of a 4-node zone of "
                 "volume V (the split of its lumped mass, so `force 0 0 [-rho*g]` loads as gravity does), the "
                 "consistent loads f ∫N dV to the nodes of a 10-node zone; null zones take none. The volume is "
                 "that of the zone's reference geometry (where its lumped mass was worked out). The loads count "
                 "in the applied forces of the equilibrium ratio and in the `body` work of `model energy`. They "
                 "stay with the zones (saved and restored with the model) until `block zone apply-remove`; "
                 "zones made again by `block zone generate` start without. `source` (heat) and `well` (fluid) "
                 "need thermal analysis or fluid flow in zones, which dec3d does not have: they are refused where "
                 "they are written. Itasca's value modifiers (time and space variation) are not supported. (The keywords "
                 "are those of Itasca's `zone apply` page of FLAC3D 7, part of the 3DEC 7 documentation set; "
                 "3DEC's own `block zone apply` page was not at hand.)",
         examples=["block zone apply force 0 0 -2e4",
                   "block zone apply force-z -1e4 range group 'fill'",
                   "block zone apply force-x 5e3 range position-z 0 2"])
def block_zone_apply(session, call):
    a = call.args
    for k in _FORCE:
        if a[k] is not None and not np.isfinite(np.asarray(a[k], float)).all():
            raise BindError(f"`{k.replace('_', '-')}` must be finite", call.locations.get(k, call.location))
    rows = _rows(session, call, "block zone apply")
    if not len(rows):
        return
    fb = body_force_field(session.model)
    if a["force"] is not None:
        fb[rows] = np.asarray(a["force"], float)
    for i, ax in enumerate(_AX):
        if a[f"force_{ax}"] is not None:
            fb[rows, i] = float(a[f"force_{ax}"])


@command("block zone apply-remove",
         keywords=[P("force", FLAG, "the whole body force", bare=True),
                   *[P(f"force-{a}", FLAG, f"the {a} component of the body force", bare=True) for a in _AX]],
         range="zone",
         doc="Remove the body forces of `block zone apply` from the zones in range (all of it without a keyword).",
         details="`force-x|-y|-z` removes one component and keeps the others. (FLAC3D's `zone apply` page names "
                 "`zone apply-remove` as the way to remove its conditions; its keywords here follow dec3d's other "
                 "apply-remove commands.)",
         examples=["block zone apply-remove", "block zone apply-remove force-z range group 'fill'"])
def block_zone_apply_remove(session, call):
    a = call.args
    rows = _rows(session, call, "block zone apply-remove")
    if not len(rows) or "fbody" not in session.model.store("zones"):
        return
    fb = session.model.store("zones")["fbody"]
    comps = [i for i, ax in enumerate(_AX) if a[f"force_{ax}"]]
    if a["force"] or not comps:
        comps = [0, 1, 2]
    for i in comps:
        fb[rows, i] = 0.0
