"""`block zone cmodel assign` and `block zone property`: the constitutive model and the
properties of the zones of deformable blocks.

Zones are selected by their centroid (range elements), or by their group or the group of
their block. Elastic moduli are stored as bulk and shear modulus (``zones.prop`` columns
``ZP_BULK``, ``ZP_SHEAR``); Young's modulus and Poisson's ratio are converted with the
isotropic relations K = E / (3 (1 − 2ν)), G = E / (2 (1 + ν)). Giving only one of young or
poisson keeps the other as it follows from the zone's present bulk and shear modulus
(E = 9KG / (3K + G), ν = (3K − 2G) / (2 (3K + G))), as 3DEC keeps the last given pair.
"""
from __future__ import annotations

import numpy as np

from ..errors import BindError
from ..model.feblocks import set_material
from ..model.zone_mohr import angle_to_tangent
from ..model.zones import (ZMODEL_ELASTIC, ZMODEL_MOHR, ZMODEL_NULL, ZP_BULK, ZP_COHESION, ZP_DENSITY, ZP_SHEAR,
                           ZP_TANDIL, ZP_TANFRIC, ZP_TENSION, zone_stores)
from .registry import command
from .values import ONOFF, Choice, Num, P

_MODELS = {"elastic": ZMODEL_ELASTIC, "null": ZMODEL_NULL, "mohr-coulomb": ZMODEL_MOHR}


def _fe_rows(session, call) -> np.ndarray:
    """FE-block elements in range (``dec3d.model.feblocks``): these commands set them too."""
    m = session.model
    if "feblocks" not in m.stores or not m.store("feblocks").n:
        return np.zeros(0, np.int64)
    return np.flatnonzero(session.range_mask(call, "feblocks"))


def _zones(session, call, what: str, fe_rows=()) -> np.ndarray:
    """Rows of the zones in range; a warning naming file:line when there are none (nor FE elements)."""
    zs = zone_stores(session.model)
    rows = np.flatnonzero(session.range_mask(call, "zone")) if zs.n else np.zeros(0, np.int64)
    if not len(rows) and not len(fe_rows):
        why = "" if zs.n else " (no block is zoned: use `block zone generate` first)"
        session.write(f"warning: {call.location}: `{what}` selected no zone{why}")
    return rows


@command("block zone cmodel assign",
         positional=[P("model", Choice(tuple(_MODELS)), "elastic, mohr-coulomb (abbreviation `mohr-c`), or null "
                       "(the zone carries no stress or mass)", required=True)],
         range="zone",
         doc="Assign the constitutive model of the zones in range.",
         details="`elastic`: isotropic linear elasticity (set bulk and shear, or young and poisson, and density "
                 "with `block zone property`). `mohr-coulomb`: shear yield with a tension cut-off and "
                 "non-associated flow (Itasca's Mohr-Coulomb model; the elastic properties plus cohesion, "
                 "friction, tension and dilation). `null`: the zone takes no part in the mechanics (no stress, no "
                 "force, no mass); its stress is set to zero. Assigning a model clears the zones' plastic state.",
         examples=["block zone cmodel assign elastic", "block zone cmodel assign mohr-c range position-z 0 1",
                   "block zone cmodel assign null range position-z 0 1"])
def block_zone_cmodel_assign(session, call):
    fe = _fe_rows(session, call)
    rows = _zones(session, call, "block zone cmodel assign", fe)
    zs = session.model.store("zones")
    code = _MODELS[call.args["model"]]
    if len(fe) and code == ZMODEL_MOHR:
        raise BindError(f"`block zone cmodel assign mohr-coulomb`: {len(fe)} FE-block element(s) in range; FE "
                        "blocks take elastic or null only (narrow the range to zoned blocks)", call.location)
    if len(fe):
        set_material(session.model, fe, code)
    zs["cmodel"][rows] = code
    zs["state"][rows] = 0
    if code == ZMODEL_NULL:
        zs["stress"][rows] = 0.0
        zs["gstress"][rows] = 0.0


_POS = Num(lo=0, lo_open=True)
_STRENGTH = ("cohesion", "friction", "tension", "dilation")


@command("block zone property",
         keywords=[P("bulk", _POS, "bulk modulus K", units="Pa"),
                   P("shear", _POS, "shear modulus G", units="Pa"),
                   P("young", _POS, "Young's modulus E (with poisson)", units="Pa"),
                   P("poisson", Num(lo=-1, hi=0.5, lo_open=True, hi_open=True), "Poisson's ratio ν, -1 < ν < 0.5"),
                   P("density", _POS, "mass density", units="kg/m³"),
                   P("cohesion", Num(lo=0), "Mohr-Coulomb cohesion c", units="Pa"),
                   P("friction", Num(lo=0, hi=90, hi_open=True), "Mohr-Coulomb friction angle φ", units="degrees"),
                   P("tension", Num(lo=0), "Mohr-Coulomb tensile strength (capped at c/tan φ)", units="Pa"),
                   P("dilation", Num(lo=0, hi=90, hi_open=True), "Mohr-Coulomb dilation angle ψ ≤ φ",
                     units="degrees")],
         range="zone",
         doc="Set the elastic moduli, density and Mohr-Coulomb strength of the zones in range.",
         details="Give either bulk and/or shear, or young and/or poisson (not both kinds in one command); they are "
                 "kept as bulk and shear modulus. Young or poisson alone changes that one and keeps the other as "
                 "the zone's present moduli give it; a zone with no moduli yet needs both. Zone properties are "
                 "checked when cycling starts: an elastic zone without bulk, shear or density stops the run, "
                 "naming its blocks. Mohr-Coulomb zones also take cohesion, friction (degrees), tension and "
                 "dilation (degrees), all 0 unless given; they are checked when cycling starts (dilation "
                 "above friction stops the run; a tension above c/tan φ is warned about and the apex value used).",
         examples=["block zone property bulk 3.9e9 shear 2.8e9 density 2600",
                   "block zone property cohesion 1e6 friction 30 tension 5e5 dilation 0",
                   "block zone property young 1e9 poisson 0.25 density 2000 range position-z 0 1",
                   "block zone property density 2500"])
def block_zone_property(session, call):
    a = call.args
    keys = [k for k in ("bulk", "shear", "young", "poisson", "density") + _STRENGTH if a[k] is not None]
    if not keys:
        raise BindError("`block zone property` needs bulk, shear, young, poisson, density, cohesion, friction, "
                        "tension or dilation", call.location)
    kg = a["bulk"] is not None or a["shear"] is not None
    ev = a["young"] is not None or a["poisson"] is not None
    if kg and ev:
        where = call.locations.get("young" if a["young"] is not None else "poisson", call.location)
        raise BindError("`block zone property`: give bulk/shear or young/poisson, not both pairs in one command",
                        where)
    fe = _fe_rows(session, call)
    if len(fe):
        try:
            set_material(session.model, fe, None, a["young"], a["poisson"], a["bulk"], a["shear"], a["density"])
        except ValueError as exc:
            given = "young" if a["young"] is not None else "poisson"
            raise BindError(f"`block zone property {given}` needs the other too: {exc}",
                            call.locations.get(given, call.location)) from None
    rows = _zones(session, call, "block zone property", fe)
    zs = session.model.store("zones")
    prop = zs["prop"]
    if ev and len(rows):
        K, G = prop[rows, ZP_BULK], prop[rows, ZP_SHEAR]
        have = (K > 0) & (G > 0)
        if (a["young"] is None or a["poisson"] is None) and not have.all():
            given, other = ("young", "poisson") if a["young"] is not None else ("poisson", "young")
            z = int(zs["id"][rows[~have][0]])
            raise BindError(f"`block zone property {given}` needs {other} too: {int((~have).sum())} zone(s) in "
                            f"range have no elastic moduli yet (the first is zone {z})",
                            call.locations.get(given, call.location))
        with np.errstate(divide="ignore", invalid="ignore"):
            E = a["young"] if a["young"] is not None else 9.0 * K * G / (3.0 * K + G)
            nu = a["poisson"] if a["poisson"] is not None else (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G))
        E = np.broadcast_to(np.asarray(E, float), rows.shape)
        nu = np.broadcast_to(np.asarray(nu, float), rows.shape)
        prop[rows, ZP_BULK] = E / (3.0 * (1.0 - 2.0 * nu))
        prop[rows, ZP_SHEAR] = E / (2.0 * (1.0 + nu))
    if a["bulk"] is not None:
        prop[rows, ZP_BULK] = a["bulk"]
    if a["shear"] is not None:
        prop[rows, ZP_SHEAR] = a["shear"]
    if a["density"] is not None:
        prop[rows, ZP_DENSITY] = a["density"]
    if a["cohesion"] is not None:
        prop[rows, ZP_COHESION] = a["cohesion"]
    if a["tension"] is not None:
        prop[rows, ZP_TENSION] = a["tension"]
    for key, col in (("friction", ZP_TANFRIC), ("dilation", ZP_TANDIL)):
        if a[key] is not None:
            try:
                prop[rows, col] = angle_to_tangent(a[key])
            except ValueError as e:
                raise BindError(f"`block zone property {key}`: {e}", call.locations.get(key, call.location)) from None


@command("block zone nodal-mixed-discretization",
         positional=[P("mode", ONOFF, "on (the default): NMD averaging for tetrahedral zones; off: none",
                       required=True)],
         doc="Switch nodal mixed discretization (NMD) of the 4-node tetrahedral zones on or off.",
         details="NMD (3DEC theory text, \"Nodal Mixed Discretization for a Tetrahedral Grid\"): the volumetric "
                 "strain increment of each tetrahedron is replaced by the average over the zones around its "
                 "gridpoints, and so is the plastic mean-stress correction, the constitutive model untouched; it "
                 "reduces the locking of constant-strain tetrahedra in plastic flow. On by default; zones of "
                 "hexahedral mixed-discretization sets use their own averaging either way. The command name is "
                 "dec3d's (no 3DEC command for this switch was found); the setting is saved with the model.",
         examples=["block zone nodal-mixed-discretization off", "block zone nodal-mixed-discretization on"])
def block_zone_nmd(session, call):
    session.model.settings.mechanical["nmd"] = bool(call.args["mode"])
