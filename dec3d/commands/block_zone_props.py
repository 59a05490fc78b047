"""`block zone cmodel assign` and `block zone property`: the constitutive model and the
properties of the zones of deformable blocks.

Both come from the zone-model registry (``dec3d.physics.cmodels``): the model names, and the
property keywords with their columns, units and ranges, as each model's host file declares them.
Zones are selected by their centroid (range elements), or by their group or the group of their
block. Elastic moduli are stored as bulk and shear modulus (``zones.prop`` columns ``ZP_BULK``,
``ZP_SHEAR``); Young's modulus and Poisson's ratio are converted with the isotropic relations
K = E / (3 (1 − 2ν)), G = E / (2 (1 + ν)). Giving only one of young or poisson keeps the other as
it follows from the zone's present bulk and shear modulus (E = 9KG / (3K + G),
ν = (3K − 2G) / (2 (3K + G))), as 3DEC keeps the last given pair.

The shared properties (moduli, density, the Mohr-Coulomb strength: columns 0-7) are set on every
zone in range; a model's own properties only on the zones whose model declares them (none: an
error naming the models in range). Table properties (``table-cohesion`` …) name a table that must
exist when the line runs; the model keeps the list of such tables in
``settings.mechanical["zone_tables"]`` (the column holds the entry + 1) and reads their points
when cycling starts.
"""
from __future__ import annotations

import numpy as np

from ..config import MODULUS_LIMIT
from ..errors import BindError, CommandError
from ..model.feblocks import set_material
from ..model.zones import ZMODEL_ELASTIC, ZMODEL_NULL, ZP_BULK, ZP_DENSITY, ZP_SHEAR, zone_stores
from ..physics.cmodels import ALL_PROPS, MODEL_BY_CODE, MODEL_NAMES, P_OWN, ZONE_MODELS, models_with
from .registry import command
from .values import ONOFF, Choice, Num, P, TableId


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


def _model_list() -> str:
    return ", ".join(sorted(ZONE_MODELS))


@command("block zone cmodel assign",
         positional=[P("model", Choice(tuple(MODEL_NAMES)), f"{_model_list()}, or null (the zone carries no stress "
                       "or mass); abbreviations as 3DEC takes them (`mohr-c`)", required=True)],
         range="zone",
         doc="Assign the constitutive model of the zones in range.",
         details="Models: " + "; ".join(f"`{m.name}`: {m.doc}" for m in sorted(ZONE_MODELS.values(),
                                                                                   key=lambda m: m.code))
                 + ". `null`: the zone takes no part in the mechanics (no stress, no force, no mass); its stress is "
                 "set to zero. Assigning a model keeps the zones' stresses (null excepted) and their shared properties "
                 "(moduli, density, cohesion, friction, tension, dilation), clears their plastic state and "
                 "history, and sets the new model's own properties to their defaults on zones that had another "
                 "model. FE-block elements in range take elastic or null only.",
         examples=["block zone cmodel assign elastic", "block zone cmodel assign mohr-c range position-z 0 1",
                   "block zone cmodel assign strain-softening", "block zone cmodel assign null range position-z 0 1"])
def block_zone_cmodel_assign(session, call):
    fe = _fe_rows(session, call)
    rows = _zones(session, call, "block zone cmodel assign", fe)
    zs = session.model.store("zones")
    code = MODEL_NAMES[call.args["model"]]
    if len(fe) and code not in (ZMODEL_ELASTIC, ZMODEL_NULL):
        raise BindError(f"`block zone cmodel assign {call.args['model']}`: {len(fe)} FE-block element(s) in range; "
                        "FE blocks take elastic or null only (narrow the range to zoned blocks)", call.location)
    if len(fe):
        set_material(session.model, fe, code)
    if code != ZMODEL_NULL:
        changed = rows[zs["cmodel"][rows] != code]
        if len(changed):
            own = zs["prop"][changed]
            MODEL_BY_CODE[code].assign_row(own)
            zs["prop"][changed] = own
    zs["cmodel"][rows] = code
    zs["state"][rows] = 0
    zs["hist"][rows] = 0.0
    if "ghist" in zs:                       # (a model with 10-node zones: ``model.zones.ho_fields``)
        zs["ghist"][rows] = 0.0
    if code == ZMODEL_NULL:
        zs["stress"][rows] = 0.0
        if "gstress" in zs:
            zs["gstress"][rows] = 0.0


def _value_type(p):
    if p.kind == "table":
        return TableId()
    if p.kind == "angle":
        return Num(lo=p.lo, hi=p.hi, lo_open=p.lo_open, hi_open=p.hi_open)
    return Num(lo=p.lo, hi=p.hi, lo_open=p.lo_open, hi_open=p.hi_open)


def _owners(name: str) -> str:
    return ", ".join(m.name for m in models_with(name))


def _keyword(p):
    units = "degrees" if p.kind == "angle" else p.units
    who = "" if p.column < P_OWN else f" ({_owners(p.name)})"
    what = "table id or name" if p.kind == "table" else p.doc
    doc = p.doc + (f": {what}" if p.kind == "table" else "") + who
    return P(p.name, _value_type(p), doc, units=units)


_ELASTIC_KEYS = ("bulk", "shear", "young", "poisson", "density")
_PROPS = [n for n in ALL_PROPS if n not in _ELASTIC_KEYS]


@command("block zone property",
         keywords=[_keyword(ALL_PROPS["bulk"]), _keyword(ALL_PROPS["shear"]),
                   P("young", Num(lo=0, lo_open=True, hi=MODULUS_LIMIT), "Young's modulus E (with poisson)", units="Pa"),
                   P("poisson", Num(lo=-1, hi=0.5, lo_open=True, hi_open=True), "Poisson's ratio ν, -1 < ν < 0.5"),
                   _keyword(ALL_PROPS["density"])] + [_keyword(ALL_PROPS[n]) for n in _PROPS],
         range="zone",
         doc="Set the elastic moduli, density and the constitutive-model properties of the zones in range.",
         details="Give either bulk and/or shear, or young and/or poisson (not both kinds in one command); they are "
                 "kept as bulk and shear modulus. Young or poisson alone changes that one and keeps the other as "
                 "the zone's present moduli give it; a zone with no moduli yet needs both. The moduli, density "
                 "and the Mohr-Coulomb strength (cohesion, friction, tension, dilation; angles in degrees) are "
                 "kept on every zone in range whatever its model; every other property is a model's own and is "
                 "set on the zones in range whose model has it (an error when none has). Properties are checked "
                 "again when cycling starts, model by model (a zone lacking a required property, or Mohr-Coulomb "
                 "dilation above friction, stops the run naming its zones). Table properties (`table-cohesion` …) "
                 "name a table made before with `table`.",
         examples=["block zone property bulk 3.9e9 shear 2.8e9 density 2600",
                   "block zone property cohesion 1e6 friction 30 tension 5e5 dilation 0",
                   "block zone property young 1e9 poisson 0.25 density 2000 range position-z 0 1",
                   "block zone property cohesion 1e6 friction 30 tension 1e7 table-cohesion 'coh'"])
def block_zone_property(session, call):
    a = {k.replace("_", "-"): v for k, v in call.args.items()}        # the keywords' own names
    loc = {k.replace("_", "-"): v for k, v in call.locations.items()}
    keys = [k for k in ("bulk", "shear", "young", "poisson", "density", *_PROPS) if a.get(k) is not None]
    if not keys:
        raise BindError("`block zone property` needs a property: " + ", ".join(("young", "poisson", *ALL_PROPS)),
                        call.location)
    kg = a["bulk"] is not None or a["shear"] is not None
    ev = a["young"] is not None or a["poisson"] is not None
    if kg and ev:
        where = loc.get("young" if a["young"] is not None else "poisson", call.location)
        raise BindError("`block zone property`: give bulk/shear or young/poisson, not both pairs in one command",
                        where)
    if a["density"] is not None:
        from .block_edit import density_warning
        density_warning(session, call, float(a["density"]))
    fe = _fe_rows(session, call)
    if len(fe):
        try:
            set_material(session.model, fe, None, a["young"], a["poisson"], a["bulk"], a["shear"], a["density"])
        except ValueError as exc:
            given = "young" if a["young"] is not None else "poisson"
            raise BindError(f"`block zone property {given}` needs the other too: {exc}",
                            loc.get(given, call.location)) from None
    rows = _zones(session, call, "block zone property", fe)
    zs = session.model.store("zones")
    prop = zs["prop"]
    # the model's own properties first: refused (nothing changed) when no zone in range has them
    own = [k for k in _PROPS if a.get(k) is not None and ALL_PROPS[k].column >= P_OWN]
    cm = zs["cmodel"][rows]
    writes = []
    for k in own:
        where = loc.get(k, call.location)
        hit = False
        for m in models_with(k):
            sel = rows[cm == m.code]
            if len(sel):
                writes.append((sel, m.props[k], a[k], where))
                hit = True
        if not hit and len(rows):
            have = ", ".join(f"{MODEL_BY_CODE[int(c)].name if int(c) else 'null'} {int((cm == c).sum())}"
                             for c in np.unique(cm))
            raise BindError(f"`block zone property {k}`: no zone in range has a model with this property (it belongs "
                            f"to {_owners(k)}; the zones in range are {have}): assign the model first", where)
    if ev and len(rows):
        K, G = prop[rows, ZP_BULK], prop[rows, ZP_SHEAR]
        have = (K > 0) & (G > 0)
        if (a["young"] is None or a["poisson"] is None) and not have.all():
            given, other = ("young", "poisson") if a["young"] is not None else ("poisson", "young")
            z = int(zs["id"][rows[~have][0]])
            raise BindError(f"`block zone property {given}` needs {other} too: {int((~have).sum())} zone(s) in "
                            f"range have no elastic moduli yet (the first is zone {z})",
                            loc.get(given, call.location))
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
    for k in _PROPS:
        if a.get(k) is not None and ALL_PROPS[k].column < P_OWN:
            writes.append((rows, ALL_PROPS[k], a[k], loc.get(k, call.location)))
    for sel, p, value, where in writes:
        prop[sel, p.column] = _column_value(session, p, value, where)


def _column_value(session, p, value, where) -> float:
    """The column value of a user value: tangent of an angle, table entry + 1 of a table id."""
    if p.kind != "table":
        return p.to_column(value)
    from ..fish.table_intrinsics import table_key

    from .fish_cmds import attach_fish

    key = table_key(value)
    if key not in session.fish_rt.tables:
        raise CommandError(f"`{p.name}`: there is no table {value!r} (make it with `table {value!r} add …` "
                           "before this line)", where)
    attach_fish(session)           # (the model reads the tables through the FISH run time when it cycles)
    ids = session.model.settings.mechanical.setdefault("zone_tables", [])
    if key not in ids:
        ids.append(key)
    return float(ids.index(key) + 1)


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
